// The height-field terrain's traversal (core/terrain/height_field.h) against brute force over the
// triangles its grid implies: closest and any hit, ray for ray, for rays from above, grazing along ridges,
// from below, axis-aligned, vertical and from outside the footprint.
#include <QTest>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "core/base/error.h"
#include "core/terrain/height_field.h"

using namespace sylva;

namespace {

struct BruteHit {
    bool got = false;
    float t = 0.0f;
    uint32_t prim = kNoHit;
};

// Every triangle, written out from the documented layout (not from the traversal's code).
struct Triangles {
    std::vector<glm::vec3> v0, e1, e2;
};

Triangles explicitTriangles(const HeightField& h)
{
    Triangles t;
    auto p = [&](uint32_t i, uint32_t j) { return glm::vec3(float(i) * h.layout.dx, h.heights[size_t(j) * h.layout.nx + i], float(j) * h.layout.dz); };
    for (uint32_t j = 0; j + 1 < h.layout.nz; ++j)
        for (uint32_t i = 0; i + 1 < h.layout.nx; ++i) {
            const glm::vec3 a = p(i, j), b = p(i + 1, j), c = p(i, j + 1), d = p(i + 1, j + 1);
            t.v0.push_back(a), t.e1.push_back(d - a), t.e2.push_back(b - a);   // 2c:     (p00, p11, p10)
            t.v0.push_back(a), t.e1.push_back(c - a), t.e2.push_back(d - a);   // 2c + 1: (p00, p01, p11)
        }
    return t;
}

BruteHit brute(const Triangles& tris, const Ray& r)
{
    BruteHit b;
    float tmax = r.tmax;
    for (size_t k = 0; k < tris.v0.size(); ++k) {
        float t, u, v;
        if (intersectTriangle(r.org, r.dir, tris.v0[k], tris.e1[k], tris.e2[k], r.tmin, tmax, t, u, v)) {
            tmax = t;
            b = BruteHit{true, t, uint32_t(k)};
        }
    }
    return b;
}

HeightField ridgeTerrain(uint32_t nx, uint32_t nz, float dx, float dz, uint32_t seed, uint32_t block = kHeightBlock)
{
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> noise(-0.4f, 0.4f);
    std::vector<float> hts(size_t(nx) * nz);
    for (uint32_t j = 0; j < nz; ++j)
        for (uint32_t i = 0; i < nx; ++i) {
            const float x = float(i) * dx, z = float(j) * dz;
            const float ridge = 12.0f * std::exp(-std::fabs(x - 0.4f * z - 20.0f) * 0.5f);   // a sharp crest
            hts[size_t(j) * nx + i] = 3.0f * std::sin(x * 0.21f) * std::cos(z * 0.17f) + ridge + noise(rng);
        }
    return buildHeightField(std::move(hts), nx, nz, dx, dz, block);
}

} // namespace

class TestHeightField : public QObject {
    Q_OBJECT

private Q_SLOTS:
    void pyramidBoundsEverySample_data()
    {
        QTest::addColumn<uint32_t>("block");
        QTest::addColumn<uint32_t>("levels");
        QTest::newRow("block 8") << 8u << 4u;    // 60 x 44 cells: blocks 8 x 6, 4 x 3, 2 x 2, 1 x 1
        QTest::newRow("block 32") << 32u << 2u;   // 2 x 2, 1 x 1
        QTest::newRow("block 1") << 1u << 7u;     // 60 x 44, 30 x 22, 15 x 11, 8 x 6, 4 x 3, 2 x 2, 1 x 1
    }
    void pyramidBoundsEverySample()
    {
        QFETCH(uint32_t, block);
        QFETCH(uint32_t, levels);
        const HeightField h = ridgeTerrain(61, 45, 1.5f, 0.75f, 1, block);
        QCOMPARE(h.layout.block, block);
        QCOMPARE(h.layout.levels, levels);
        const glm::vec2 top = h.ranges[h.layout.levelOffset[h.layout.levels - 1]];
        float lo = INFINITY, hi = -INFINITY;
        for (float v : h.heights) lo = std::min(lo, v), hi = std::max(hi, v);
        QCOMPARE(top.x, lo);
        QCOMPARE(top.y, hi);
        // Every level-0 block's range holds exactly its samples' (edges shared with the neighbours).
        const HeightFieldLayout& L = h.layout;
        for (uint32_t bj = 0; bj < L.levelDepth[0]; ++bj)
            for (uint32_t bi = 0; bi < L.levelWidth[0]; ++bi) {
                float blo = INFINITY, bhi = -INFINITY;
                for (uint32_t j = bj * block; j <= std::min(L.nz - 1, (bj + 1) * block); ++j)
                    for (uint32_t i = bi * block; i <= std::min(L.nx - 1, (bi + 1) * block); ++i) blo = std::min(blo, h.at(i, j)), bhi = std::max(bhi, h.at(i, j));
                QCOMPARE(h.ranges[L.levelOffset[0] + bj * L.levelWidth[0] + bi], glm::vec2(blo, bhi));
            }
    }

    // The default block and a small one (a deep pyramid over the same terrain), 100k rays each.
    void hitsEqualBruteForce_data()
    {
        QTest::addColumn<uint32_t>("block");
        QTest::newRow("default block") << kHeightBlock;
        QTest::newRow("block 4") << 4u;
    }
    void hitsEqualBruteForce()
    {
        QFETCH(uint32_t, block);
        const HeightField h = ridgeTerrain(61, 45, 1.5f, 0.75f, 2, block);
        const HeightFieldView v = h.view();
        const Triangles tris = explicitTriangles(h);
        const float sx = 60 * 1.5f, sz = 44 * 0.75f;
        std::mt19937 rng(5);
        std::uniform_real_distribution<float> u01(0.0f, 1.0f);
        auto unit = [&] {
            for (;;) {
                const glm::vec3 d(2 * u01(rng) - 1, 2 * u01(rng) - 1, 2 * u01(rng) - 1);
                const float l = glm::length(d);
                if (l > 0.05f && l <= 1.0f) return d / l;
            }
        };
        const int n = 100000;
        int hits = 0, bad = 0, badAny = 0;
        for (int k = 0; k < n; ++k) {
            Ray r{};
            r.tmin = 0.0f;
            r.tmax = k % 7 == 0 ? 5.0f + 60.0f * u01(rng) : INFINITY;
            const int kind = k % 6;
            if (kind == 0) {   // from above, anywhere
                r.org = glm::vec3(sx * u01(rng), 16.0f + 20.0f * u01(rng), sz * u01(rng));
                r.dir = unit();
            } else if (kind == 1) {   // grazing along the ridge, just above or below the crest
                const float z = sz * u01(rng);
                r.org = glm::vec3(20.0f + 0.4f * z + 2.0f * (u01(rng) - 0.5f), 8.0f + 8.0f * u01(rng), z);
                r.dir = glm::normalize(glm::vec3(0.4f, 0.05f * (u01(rng) - 0.5f), 1.0f) * (u01(rng) < 0.5f ? 1.0f : -1.0f));
            } else if (kind == 2) {   // from below the terrain, upward or sideways
                r.org = glm::vec3(sx * u01(rng), -8.0f * u01(rng) - 4.0f, sz * u01(rng));
                r.dir = unit();
                r.dir.y = std::fabs(r.dir.y);
            } else if (kind == 3) {   // axis-aligned in x or z, or vertical
                r.org = glm::vec3(sx * u01(rng), 20.0f * u01(rng) - 2.0f, sz * u01(rng));
                const int axis = int(rng() % 3);
                const float s = u01(rng) < 0.5f ? 1.0f : -1.0f;
                r.dir = axis == 0 ? glm::vec3(s, 0.0f, 0.0f) : axis == 1 ? glm::vec3(0.0f, s, 0.0f) : glm::vec3(0.0f, 0.0f, s);
                if (axis != 1) r.dir.y = -0.1f * u01(rng);
            } else if (kind == 4) {   // from outside the footprint toward it
                r.org = glm::vec3(-30.0f + (sx + 60.0f) * u01(rng), 30.0f * u01(rng), u01(rng) < 0.5f ? -20.0f : sz + 20.0f);
                r.dir = glm::normalize(glm::vec3(sx * u01(rng), 4.0f * u01(rng), sz * u01(rng)) - r.org);
            } else {   // straight down onto sample positions and cell edges exactly (vertices shared by 6 triangles)
                const uint32_t i = rng() % 61, j = rng() % 45;
                const bool edge = u01(rng) < 0.5f;
                r.org = glm::vec3(float(i) * 1.5f + (edge && i < 60 ? 0.75f : 0.0f), 30.0f, float(j) * 0.75f);
                r.dir = glm::vec3(0.0f, -1.0f, 0.0f);
            }
            const BruteHit want = brute(tris, r);
            float tmax = r.tmax, uu = 0.0f, vv = 0.0f;
            uint32_t prim = kNoHit;
            const bool got = intersectHeightField<false>(v, r, tmax, prim, uu, vv);
            hits += want.got;
            if (got != want.got) {
                ++bad;
                if (bad <= 5) qWarning("ray %d (kind %d): traversal %s (t %g prim %u), brute force %s (t %g); org %g %g %g dir %g %g %g tmax %g", k, kind, got ? "hit" : "missed", double(tmax), prim, want.got ? "hit" : "missed", double(want.t), double(r.org.x), double(r.org.y), double(r.org.z), double(r.dir.x), double(r.dir.y), double(r.dir.z), double(r.tmax));
            } else if (got && !(std::fabs(tmax - want.t) <= 1e-5f * std::max(1.0f, want.t) && (prim == want.prim || std::fabs(tmax - want.t) <= 1e-6f * std::max(1.0f, want.t)))) {
                ++bad;
                if (bad <= 5) qWarning("ray %d (kind %d): t %g prim %u, brute force t %g prim %u", k, kind, double(tmax), prim, double(want.t), want.prim);
            }
            float tAny = r.tmax;
            uint32_t pAny = kNoHit;
            const bool any = intersectHeightField<true>(v, r, tAny, pAny, uu, vv);
            if (any != want.got) ++badAny;
            if (kind == 5 && !got && std::isinf(r.tmax)) ++bad;   // a vertical ray over the footprint cannot miss
        }
        qInfo("%d of %d rays hit the terrain", hits, n);
        QVERIFY(hits > n / 3 && hits < n);   // the sample has both
        QCOMPARE(bad, 0);
        QCOMPARE(badAny, 0);
    }

    void normalPointsUpAndIsPerpendicular()
    {
        const HeightField h = ridgeTerrain(17, 9, 2.0f, 1.0f, 3);
        const HeightFieldView v = h.view();
        const Triangles tris = explicitTriangles(h);
        for (uint32_t k = 0; k < tris.v0.size(); ++k) {
            const glm::vec3 n = heightFieldNormal(v, k);
            QVERIFY(n.y > 0.0f);
            QVERIFY(std::fabs(glm::length(n) - 1.0f) < 1e-5f);
            QVERIFY(std::fabs(glm::dot(n, glm::normalize(tris.e1[k]))) < 1e-5f);
            QVERIFY(std::fabs(glm::dot(n, glm::normalize(tris.e2[k]))) < 1e-5f);
        }
    }

    // surfaceHeight (instances standing on the terrain) is where a vertical ray meets the triangles.
    void surfaceHeightMeetsVerticalRays()
    {
        const HeightField h = ridgeTerrain(61, 45, 1.5f, 0.75f, 4);
        const HeightFieldView v = h.view();
        std::mt19937 rng(9);
        std::uniform_real_distribution<double> ux(0.0, 90.0), uz(0.0, 33.0);
        for (int k = 0; k < 20000; ++k) {
            const double x = k == 0 ? 90.0 : ux(rng), z = k == 0 ? 33.0 : uz(rng);   // the far corner too
            Ray r{glm::vec3(float(x), 100.0f, float(z)), 0.0f, glm::vec3(0.0f, -1.0f, 0.0f), INFINITY};
            float t = INFINITY, uu, vv;
            uint32_t prim;
            QVERIFY(intersectHeightField<false>(v, r, t, prim, uu, vv));
            const double y = surfaceHeight(h, x, z);
            QVERIFY2(std::fabs((100.0 - double(t)) - y) < 1e-4, qPrintable(QString("%1 %2: %3 vs %4").arg(x).arg(z).arg(100.0 - t).arg(y)));
        }
        QVERIFY(std::isnan(surfaceHeight(h, -0.01, 3.0)));
        QVERIFY(std::isnan(surfaceHeight(h, 3.0, 33.01)));
    }

    void badInputThrows()
    {
        QVERIFY_THROWS_EXCEPTION(Error, buildHeightField(std::vector<float>(3, 0.0f), 3, 1, 1.0f, 1.0f));
        QVERIFY_THROWS_EXCEPTION(Error, buildHeightField(std::vector<float>(5, 0.0f), 2, 2, 1.0f, 1.0f));
        QVERIFY_THROWS_EXCEPTION(Error, buildHeightField(std::vector<float>(4, 0.0f), 2, 2, 0.0f, 1.0f));
        QVERIFY_THROWS_EXCEPTION(Error, buildHeightField(std::vector<float>(4, 0.0f), 2, 2, 1.0f, -2.0f));
        QVERIFY_THROWS_EXCEPTION(Error, buildHeightField(std::vector<float>(4, 0.0f), 2, 2, 1.0f, 1.0f, 0));
        QVERIFY_THROWS_EXCEPTION(Error, buildHeightField(std::vector<float>(4, 0.0f), 2, 2, 1.0f, 1.0f, kMaxHeightBlock + 1));
        std::vector<float> nan(4, 0.0f);
        nan[2] = std::nanf("");
        QVERIFY_THROWS_EXCEPTION(Error, buildHeightField(nan, 2, 2, 1.0f, 1.0f));
        std::vector<float> inf(4, 0.0f);
        inf[1] = -INFINITY;
        QVERIFY_THROWS_EXCEPTION(Error, buildHeightField(inf, 2, 2, 1.0f, 1.0f));
    }
};

QTEST_APPLESS_MAIN(TestHeightField)
#include "tst_height_field.moc"
