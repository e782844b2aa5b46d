// The renderer's sample generators (core/render/sampling.h) against their defining properties, counted by brute
// force: the scrambled Sobol' points of one pixel and dimension form (0,m,2)-nets in base 2 (every 2^m
// consecutive samples from 0 put exactly one point in each elementary interval of every shape: 2^a x 2^(m-a)
// cells), the one-dimensional sequence is stratified the same way, the scrambling differs between seeds and
// stays uniform over them (means and a chi-square over cells), and cosineHemisphere draws cos / pi.
#include <QTest>

#include <cmath>
#include <set>
#include <vector>

#include "core/render/sampling.h"

using namespace sylva;

class TestSampling : public QObject {
    Q_OBJECT

private Q_SLOTS:
    void sobolPointsAreNets()
    {
        for (uint32_t seed : {0u, 1u, 0x12345u, 0xDEADBEEFu})
            for (int m = 0; m <= 8; ++m) {
                const int n = 1 << m;
                std::vector<glm::vec2> pts;
                for (int i = 0; i < n; ++i) pts.push_back(lds::sample2(uint32_t(i), seed));
                for (int a = 0; a <= m; ++a) {
                    const int nx = 1 << a, ny = 1 << (m - a);
                    std::vector<int> count(size_t(n), 0);
                    for (const glm::vec2& p : pts) {
                        QVERIFY(p.x >= 0.0f && p.x < 1.0f && p.y >= 0.0f && p.y < 1.0f);
                        ++count[size_t(int(p.y * float(ny)) * nx + int(p.x * float(nx)))];
                    }
                    for (int c : count) QVERIFY2(c == 1, qPrintable(QString("seed %1, %2 points, cells %3 x %4").arg(seed).arg(n).arg(nx).arg(ny)));
                }
                std::vector<int> cells(size_t(n), 0);
                for (int i = 0; i < n; ++i) ++cells[size_t(lds::sample1(uint32_t(i), seed) * float(n))];
                for (int c : cells) QCOMPARE(c, 1);
            }
    }

    // Different seeds, different points; over many seeds each point is uniform on the square.
    void scramblingIsUniformOverSeeds()
    {
        std::set<std::pair<float, float>> firsts;
        const int seeds = 4096, cells = 8;
        for (int index : {0, 1, 5}) {
            std::vector<int> count(size_t(cells * cells), 0);
            double mx = 0.0, my = 0.0;
            for (int s = 0; s < seeds; ++s) {
                const glm::vec2 p = lds::sample2(uint32_t(index), lds::mix(uint32_t(s), 7u));
                if (index == 0) firsts.insert({p.x, p.y});
                mx += p.x;
                my += p.y;
                ++count[size_t(int(p.y * cells) * cells + int(p.x * cells))];
            }
            mx /= seeds;
            my /= seeds;
            // chi-square with 63 degrees of freedom: its 99.9th percentile is about 103
            const double e = double(seeds) / double(cells * cells);
            double chi2 = 0.0;
            for (int c : count) chi2 += (c - e) * (c - e) / e;
            qInfo("index %d: mean (%.4f, %.4f), chi-square %.1f over %d cells", index, mx, my, chi2, cells * cells);
            QVERIFY(std::fabs(mx - 0.5) < 0.02 && std::fabs(my - 0.5) < 0.02);
            QVERIFY(chi2 < 103.0);
        }
        QVERIFY(firsts.size() > size_t(seeds) * 99 / 100);
    }

    // cos / pi about n: E[cos] = 2/3, E[cos^2] = 1/2, never below the surface, whatever n.
    void cosineHemisphereDrawsCosine()
    {
        for (const glm::vec3 n : {glm::vec3(0, 1, 0), glm::vec3(0, 0, -1), glm::normalize(glm::vec3(0.3f, -0.5f, 0.8f))}) {
            double c1 = 0.0, c2 = 0.0;
            const int count = 1 << 14;
            for (int i = 0; i < count; ++i) {
                const glm::vec2 u = lds::sample2(uint32_t(i), 99u);
                const glm::vec3 d = cosineHemisphere(n, u.x, u.y);
                QVERIFY(std::fabs(glm::length(d) - 1.0f) < 1e-5f);
                const double c = double(glm::dot(d, n));
                QVERIFY(c >= -1e-6);
                c1 += c;
                c2 += c * c;
            }
            c1 /= count;
            c2 /= count;
            qInfo("E[cos] %.5f (2/3), E[cos^2] %.5f (1/2)", c1, c2);
            QVERIFY(std::fabs(c1 - 2.0 / 3.0) < 1e-3);
            QVERIFY(std::fabs(c2 - 0.5) < 1e-3);
        }
    }
};

QTEST_GUILESS_MAIN(TestSampling)
#include "tst_sampling.moc"
