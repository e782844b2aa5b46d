// Monte Carlo reference: known answers (empty grid, Beer-Lambert, single scattering by quadrature),
// determinism, 1/sqrt(N) error, the g = 1 limit, and the LB model measured against it on a small cloud.
#include <QTest>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <functional>
#include <random>

#include <tbb/task_arena.h>

#include "core/base/error.h"
#include "core/base/progress.h"
#include "core/grid/grid.h"
#include "core/lb/lattice.h"
#include "core/lb/lb_params.h"
#include "core/lb/lb_solver.h"
#include "core/reference/mc_reference.h"

using namespace sylva;

namespace {

constexpr double kPi = 3.14159265358979323846;

DensityGrid uniformGrid(glm::ivec3 dims, float rho)
{
    DensityGrid g;
    g.geometry.dims = dims;
    g.density.assign(g.geometry.nodeCount(), rho);
    g.woodFraction.assign(g.geometry.nodeCount(), 0.0f);
    return g;
}

DensityGrid randomGrid(glm::ivec3 dims, uint32_t seed, double woodShare)
{
    DensityGrid g = uniformGrid(dims, 0.0f);
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    for (size_t n = 0; n < g.density.size(); ++n) {
        g.density[n] = u(rng) < 0.4f ? 0.0f : u(rng);
        g.woodFraction[n] = u(rng) < woodShare ? 1.0f : 0.0f;
    }
    return g;
}

// A layer of nodes j0..j1 (all i, k) at density rho: its cells fill y in [j0 - 0.5, j1 + 0.5].
DensityGrid slabGrid(glm::ivec3 dims, int j0, int j1, float rho, float wood)
{
    DensityGrid g = uniformGrid(dims, 0.0f);
    for (int i = 0; i < dims.x; ++i)
        for (int j = j0; j <= j1; ++j)
            for (int k = 0; k < dims.z; ++k) {
                g.density[g.geometry.index(i, j, k)] = rho;
                g.woodFraction[g.geometry.index(i, j, k)] = wood;
            }
    return g;
}

// Gauss-Legendre nodes and weights on [a, b] (Newton on the Legendre recurrence).
void gaussLegendre(int n, double a, double b, std::vector<double>& x, std::vector<double>& w)
{
    x.assign(size_t(n), 0.0);
    w.assign(size_t(n), 0.0);
    for (int i = 0; i < n; ++i) {
        double z = std::cos(kPi * (i + 0.75) / (n + 0.5)), dp = 1.0;
        for (int it = 0; it < 100; ++it) {
            double p0 = 1.0, p1 = z;
            for (int k = 2; k <= n; ++k) {
                const double p2 = ((2.0 * k - 1.0) * z * p1 - (k - 1.0) * p0) / k;
                p0 = p1;
                p1 = p2;
            }
            dp = n * (z * p1 - p0) / (z * z - 1.0);
            const double dz = p1 / dp;
            z -= dz;
            if (std::fabs(dz) < 1e-15) break;
        }
        x[size_t(i)] = 0.5 * (a + b) + 0.5 * (b - a) * z;
        w[size_t(i)] = (b - a) / ((1.0 - z * z) * dp * dp);
    }
}

// Domain of the reference: the union of node-centred cells, [-0.5, N-0.5] per axis.
double boxExit(glm::dvec3 p, glm::dvec3 dir, glm::ivec3 dims)
{
    double t = 1e300;
    for (int a = 0; a < 3; ++a) {
        if (dir[a] > 0) t = std::min(t, (dims[a] - 0.5 - p[a]) / dir[a]);
        if (dir[a] < 0) t = std::min(t, (-0.5 - p[a]) / dir[a]);
    }
    return t;
}

// The part [sa, sb] of the ray p + s*dir, s in [0, sMax], where y lies in [y0, y1]; false when empty.
bool layerInterval(glm::dvec3 p, glm::dvec3 dir, double sMax, double y0, double y1, double& sa, double& sb)
{
    double lo = 0.0, hi = sMax;
    if (dir.y == 0.0) {
        if (p.y < y0 || p.y > y1) return false;
    } else {
        double s0 = (y0 - p.y) / dir.y, s1 = (y1 - p.y) / dir.y;
        if (s0 > s1) std::swap(s0, s1);
        lo = std::max(lo, s0);
        hi = std::min(hi, s1);
    }
    sa = lo;
    sb = hi;
    return hi > lo;
}

// Incident beams as the LB boundary condition defines them (computed here from the lattice, not by the solver).
std::vector<std::pair<glm::dvec3, double>> latticeBeams(glm::dvec3 sun)
{
    const glm::dvec3 d = -glm::normalize(sun);
    std::vector<std::pair<glm::dvec3, double>> beams;
    for (int m = 1; m < lb::kDirections; ++m) {
        const glm::dvec3 n = glm::normalize(glm::dvec3(lb::kC[m][0], lb::kC[m][1], lb::kC[m][2]));
        if (glm::dot(n, d) > 0) beams.emplace_back(n, glm::dot(n, d));
    }
    return beams;
}

// Average of f over the cell of node (i,j,k) by an n^3 Gauss-Legendre rule.
double cellAverage(glm::ivec3 node, int n, const std::function<double(glm::dvec3)>& f)
{
    std::vector<double> x, w;
    gaussLegendre(n, -0.5, 0.5, x, w);
    double s = 0.0;
    for (int a = 0; a < n; ++a)
        for (int b = 0; b < n; ++b)
            for (int c = 0; c < n; ++c)
                s += w[size_t(a)] * w[size_t(b)] * w[size_t(c)] *
                     f(glm::dvec3(node) + glm::dvec3(x[size_t(a)], x[size_t(b)], x[size_t(c)]));
    return s;
}

struct ZStats {
    double maxAbs = 0.0, meanSq = 0.0, beyond3 = 0.0;
    size_t count = 0;
};

// z = (estimate - exact) / standard error over the given values.
ZStats zStats(const std::vector<double>& estimate, const std::vector<double>& exact, const std::vector<double>& se)
{
    ZStats z;
    for (size_t i = 0; i < estimate.size(); ++i) {
        const double v = (estimate[i] - exact[i]) / se[i];
        z.maxAbs = std::max(z.maxAbs, std::fabs(v));
        z.meanSq += v * v;
        z.beyond3 += std::fabs(v) > 3.0;
        ++z.count;
    }
    z.meanSq /= double(z.count);
    z.beyond3 /= double(z.count);
    return z;
}

// Every value within the confidence interval: no |z| beyond 4.5, at most 1% beyond 3 (0.27% expected),
// and the mean of z^2 near 1 (which also checks that the standard errors are right, not just small).
#define CHECK_Z(z)                                                                                                          \
    do {                                                                                                                    \
        qInfo("  %zu values: max |z| %.2f, mean z^2 %.3f, share beyond 3 sigma %.4f", (z).count, (z).maxAbs, (z).meanSq, \
              (z).beyond3);                                                                                                 \
        QVERIFY2((z).maxAbs < 4.5, "a value lies beyond 4.5 standard errors");                                              \
        QVERIFY2((z).beyond3 <= 0.01, "more than 1% of the values lie beyond 3 standard errors");                           \
        QVERIFY2((z).meanSq > 0.75 && (z).meanSq < 1.3, "mean z^2 is not near 1: biased, or wrong standard errors");      \
    } while (0)

lb::LbParams params(lb::ChannelParams r, lb::ChannelParams g, lb::ChannelParams b, bool zeroF0, glm::vec3 sun)
{
    lb::LbParams p;
    p.channels = {r, g, b};
    p.zeroF0 = zeroF0;
    p.sun = sun;
    return p;
}

ReferenceResult normalizedReference(const DensityGrid& d, const lb::LbParams& p, const ReferenceSettings& s)
{
    ReferenceResult r = solveReference(d, p, s);
    normalizeToUnobstructed(r.mean, p, &r.standardError);
    qInfo("  %llu paths x %d channel solves in %.2f s (%.2f real collisions per path)", (unsigned long long)r.paths,
          r.channelSolves, r.seconds, r.collisionsPerPath);
    return r;
}

} // namespace

class TestReference : public QObject {
    Q_OBJECT
private Q_SLOTS:
    void emptyGridIsOneEverywhere_data()
    {
        QTest::addColumn<int>("incidence");
        QTest::addColumn<float>("sunX");
        QTest::addColumn<float>("sunY");
        QTest::addColumn<float>("sunZ");
        QTest::newRow("lattice beams, oblique sun") << int(Incidence::LatticeBeams) << 0.3f << 1.0f << 0.2f;
        QTest::newRow("lattice beams, sun on a diagonal") << int(Incidence::LatticeBeams) << -1.0f << 1.0f << 0.0f;
        QTest::newRow("collimated, oblique sun") << int(Incidence::Collimated) << 0.3f << 1.0f << 0.2f;
    }
    void emptyGridIsOneEverywhere()
    {
        QFETCH(int, incidence);
        QFETCH(float, sunX);
        QFETCH(float, sunY);
        QFETCH(float, sunZ);
        const DensityGrid d = uniformGrid({11, 9, 13}, 0.0f);
        lb::LbParams p = lb::paramsFromPreset(*lb::findPreset("leaf"));
        p.sun = {sunX, sunY, sunZ};
        p.intensity = {1.0f, 2.5f, 0.5f};
        ReferenceSettings s;
        s.paths = 60000;
        s.incidence = Incidence(incidence);
        const ReferenceResult r = normalizedReference(d, p, s);
        std::vector<double> est, exact, se;
        for (size_t i = 0; i < r.mean.rgb.size(); ++i) {
            QVERIFY2(r.standardError[i] > 0.0f, "a cell no path crossed");
            est.push_back(r.mean.rgb[i]);
            exact.push_back(1.0);
            se.push_back(r.standardError[i]);
        }
        const ZStats z = zStats(est, exact, se);
        CHECK_Z(z);
        // The LB side of the normalization: an empty grid converges to the boundary total, i.e. 1.
        p.steps = 40;
        LightingGrid lbOut = lb::solveLighting(d, p);
        normalizeToUnobstructed(lbOut, p);
        for (float v : lbOut.rgb) QVERIFY2(std::fabs(v - 1.0f) < 1e-5f, qPrintable(QString("LB empty grid: %1").arg(v)));
    }

    void absorbingSlabFollowsBeerLambert_data()
    {
        QTest::addColumn<int>("incidence");
        QTest::addColumn<float>("sunX");
        QTest::addColumn<float>("sunY");
        QTest::addColumn<float>("sunZ");
        QTest::newRow("lattice beams, oblique sun") << int(Incidence::LatticeBeams) << 0.3f << 1.0f << 0.2f;
        QTest::newRow("lattice beams, zenith sun") << int(Incidence::LatticeBeams) << 0.0f << 1.0f << 0.0f;
        QTest::newRow("collimated, oblique sun") << int(Incidence::Collimated) << 0.3f << 1.0f << 0.2f;
    }
    void absorbingSlabFollowsBeerLambert()
    {
        // A layer of density 0.7 over the full width, purely absorbing (plants: absorbed light leaves).
        // Each beam m of fluence w_m is attenuated by exp(-sigma_a rho L_m), L_m the length of the way back
        // from the point along -n_m inside the layer (thickness / cos(theta) away from the sides).
        QFETCH(int, incidence);
        QFETCH(float, sunX);
        QFETCH(float, sunY);
        QFETCH(float, sunZ);
        const glm::ivec3 dims{15, 12, 15};
        const int j0 = 3, j1 = 7;
        const float rho = 0.7f;
        const DensityGrid d = slabGrid(dims, j0, j1, rho, 0.0f);
        const lb::LbParams p = params({0.1f, 0.0f, 0.0f}, {0.3f, 0.0f, 0.0f}, {0.6f, 0.0f, 0.0f}, true, {sunX, sunY, sunZ});
        ReferenceSettings s;
        s.paths = 600000;
        s.incidence = Incidence(incidence);
        const ReferenceResult r = normalizedReference(d, p, s);

        std::vector<std::pair<glm::dvec3, double>> beams;
        if (s.incidence == Incidence::LatticeBeams) {
            beams = latticeBeams(glm::dvec3(p.sun));
        } else {
            beams.emplace_back(-glm::normalize(glm::dvec3(p.sun)), 1.0);
        }
        double total = 0.0;
        for (const auto& b : beams) total += b.second;
        std::vector<double> est, exact, se;
        double deepest = 1.0;
        for (int i = 0; i < dims.x; ++i)
            for (int j = 0; j < dims.y; ++j)
                for (int k = 0; k < dims.z; ++k)
                    for (int c = 0; c < 3; ++c) {
                        const double mu = double(p.channels[size_t(c)].sigmaA) * double(rho);
                        const double v = cellAverage({i, j, k}, 4, [&](glm::dvec3 q) {
                            double f = 0.0;
                            for (const auto& [dir, weight] : beams) {
                                double sa, sb;
                                const double len = layerInterval(q, -dir, boxExit(q, -dir, dims), j0 - 0.5, j1 + 0.5, sa, sb) ? sb - sa : 0.0;
                                f += weight * std::exp(-mu * len);
                            }
                            return f / total;
                        });
                        deepest = std::min(deepest, v);
                        est.push_back(r.mean.at(i, j, k, c));
                        exact.push_back(v);
                        se.push_back(r.standardError[d.geometry.index(i, j, k) * 3 + size_t(c)]);
                    }
        qInfo("  transmitted fluence down to %.4f of the incident", deepest);
        const ZStats z = zStats(est, exact, se);
        CHECK_Z(z);
    }

    void singleScatteringMatchesQuadrature_data()
    {
        QTest::addColumn<bool>("brown");
        QTest::newRow("green, g = 0.6 / -0.4 / 0") << false;
        QTest::newRow("brown (g = -1)") << true;
    }
    void singleScatteringMatchesQuadrature()
    {
        // A thin, low-albedo layer (optical depth 0.75, albedo 0.4) lit by a collimated zenith sun; paths
        // stop at their second real collision (maxBounces = 1), so the answer is the uncollided plus the
        // singly scattered fluence:
        //   phi1(p) = int_{4pi} dw p_HG(w0 . w) int_{layer} sigma_s exp(-mu depth(q)) exp(-mu |p q|_layer) ds,
        // q = p - s w. The inner integral is closed-form; the outer one is Gauss-Legendre in w_y times the
        // trapezoid rule in azimuth. Brown nodes scatter straight back (g = -1): phi1 is the w = +y term alone.
        QFETCH(bool, brown);
        const glm::ivec3 dims{21, 11, 21};
        const int j0 = 4, j1 = 6;
        const double y0 = j0 - 0.5, y1 = j1 + 0.5;
        const DensityGrid d = slabGrid(dims, j0, j1, 1.0f, brown ? 1.0f : 0.0f);
        const float sa = 0.15f, ss = 0.1f;
        const lb::LbParams p = brown ? params({sa, ss, 0.3f}, {sa, ss, 0.3f}, {sa, ss, 0.3f}, true, {0, 1, 0})
                                     : params({sa, ss, 0.6f}, {sa, ss, -0.4f}, {sa, ss, 0.0f}, true, {0, 1, 0});
        ReferenceSettings s;
        s.paths = brown ? 4000000 : 2000000;
        s.maxBounces = 1;
        s.incidence = Incidence::Collimated;
        const ReferenceResult r = normalizedReference(d, p, s);

        const double mu = double(sa) + double(ss), sigmaS = ss;
        // Singly scattered light arriving at p travelling along w.
        auto inner = [&](glm::dvec3 q, glm::dvec3 w) {
            double a, b;
            if (!layerInterval(q, -w, boxExit(q, -w, dims), y0, y1, a, b)) return 0.0;
            // source at s: sigma_s exp(-mu (y1 - q_y + s w_y)) exp(-mu (s - a))
            const double k = mu * (1.0 + w.y);
            const double len = b - a;
            const double integral = k * len < 1e-9 ? len : std::exp(-k * a) * -std::expm1(-k * len) / k;
            return sigmaS * std::exp(-mu * (y1 - q.y) + mu * a) * integral;
        };
        std::vector<double> muX, muW, muX2, muW2, phiX;
        gaussLegendre(48, -1.0, 0.0, muX, muW);
        gaussLegendre(48, 0.0, 1.0, muX2, muW2);
        muX.insert(muX.end(), muX2.begin(), muX2.end());
        muW.insert(muW.end(), muW2.begin(), muW2.end());
        const int nPhi = 48;
        std::vector<double> yX, yW;
        gaussLegendre(3, -0.5, 0.5, yX, yW);

        std::vector<double> est, exact, se;
        std::vector<double> scatterShare;
        for (int i = 7; i <= 13; ++i)
            for (int k = 7; k <= 13; ++k)
                for (int j = 0; j < dims.y; ++j) {
                    double expect[3] = {0, 0, 0}, scattered[3] = {0, 0, 0};
                    for (size_t t = 0; t < yX.size(); ++t) {
                        const glm::dvec3 q(i, j + yX[t], k);
                        const double direct = std::exp(-mu * std::clamp(y1 - std::max(q.y, y0), 0.0, y1 - y0));
                        double phi1[3] = {0, 0, 0};
                        if (brown) {
                            const double up = inner(q, {0, 1, 0});
                            for (double& v : phi1) v = up;
                        } else {
                            for (size_t m = 0; m < muX.size(); ++m) {
                                const double wy = muX[m], sinT = std::sqrt(std::max(0.0, 1.0 - wy * wy));
                                double ring = 0.0;
                                for (int a = 0; a < nPhi; ++a) {
                                    const double ph = 2.0 * kPi * (a + 0.5) / nPhi;
                                    ring += inner(q, {sinT * std::cos(ph), wy, sinT * std::sin(ph)});
                                }
                                ring *= 2.0 * kPi / nPhi * muW[m];
                                for (int c = 0; c < 3; ++c) {
                                    const double g = p.channels[size_t(c)].g, cosT = -wy;   // w0 = -y
                                    phi1[c] += ring * (1.0 - g * g) / (4.0 * kPi * std::pow(1.0 + g * g - 2.0 * g * cosT, 1.5));
                                }
                            }
                        }
                        for (int c = 0; c < 3; ++c) {
                            expect[c] += yW[t] * (direct + phi1[c]);
                            scattered[c] += yW[t] * phi1[c];
                        }
                    }
                    for (int c = 0; c < 3; ++c) {
                        est.push_back(r.mean.at(i, j, k, c));
                        exact.push_back(expect[c]);
                        se.push_back(r.standardError[d.geometry.index(i, j, k) * 3 + size_t(c)]);
                        scatterShare.push_back(scattered[c] / expect[c]);
                    }
                }
        qInfo("  singly scattered share of the fluence up to %.3f", *std::max_element(scatterShare.begin(), scatterShare.end()));
        const ZStats z = zStats(est, exact, se);
        CHECK_Z(z);
        // The scattered part alone, averaged over the 7x7 block at each height and channel: within 4 sigma.
        for (int j = 0; j < dims.y; ++j)
            for (int c = 0; c < 3; ++c) {
                double diff = 0.0, var = 0.0, scat = 0.0;
                for (size_t col = 0; col < 49; ++col) {
                    const size_t at = (col * size_t(dims.y) + size_t(j)) * 3 + size_t(c);
                    diff += est[at] - exact[at];
                    var += se[at] * se[at];
                    scat += scatterShare[at] * exact[at];
                }
                QVERIFY2(std::fabs(diff) < 4.0 * std::sqrt(var),
                         qPrintable(QString("height %1 channel %2: block mean off by %3 (sigma %4, scattered part %5)")
                                        .arg(j).arg(c).arg(diff / 49).arg(std::sqrt(var) / 49).arg(scat / 49)));
            }
    }

    void forwardDeltaScatteringIsPassThrough()
    {
        // g = 1 with nothing absorbed: every collision keeps the direction, so any medium equals an empty grid.
        const DensityGrid d = randomGrid({10, 9, 11}, 3, 0.0);
        const lb::LbParams p = params({0.0f, 1.0f, 1.0f}, {0.0f, 0.6f, 1.0f}, {0.0f, 1.0f, 1.0f}, false, {0.3f, 1.0f, -0.2f});
        ReferenceSettings s;
        s.paths = 50000;
        const ReferenceResult r = normalizedReference(d, p, s);
        QVERIFY(r.collisionsPerPath > 1.0);
        std::vector<double> est(r.mean.rgb.begin(), r.mean.rgb.end()), exact(est.size(), 1.0),
            se(r.standardError.begin(), r.standardError.end());
        const ZStats z = zStats(est, exact, se);
        CHECK_Z(z);
    }

    void sameSeedSameBitsAtAnyThreadCount()
    {
        const DensityGrid d = randomGrid({12, 10, 11}, 7, 0.2);
        lb::LbParams p = lb::paramsFromPreset(*lb::findPreset("leaf"));
        p.sun = {0.3f, 1.0f, 0.2f};
        ReferenceSettings s;
        s.paths = 20000;
        s.seed = 42;
        const ReferenceResult a = solveReference(d, p, s);
        for (int threads : {1, 2}) {
            tbb::task_arena arena(threads);
            ReferenceResult b;
            arena.execute([&] { b = solveReference(d, p, s); });
            QVERIFY2(std::memcmp(a.mean.rgb.data(), b.mean.rgb.data(), a.mean.rgb.size() * sizeof(float)) == 0,
                     qPrintable(QString("mean differs with %1 threads").arg(threads)));
            QVERIFY(std::memcmp(a.standardError.data(), b.standardError.data(), a.standardError.size() * sizeof(float)) == 0);
            QCOMPARE(a.collisionsPerPath, b.collisionsPerPath);
        }
        s.seed = 43;
        const ReferenceResult c = solveReference(d, p, s);
        QVERIFY(std::memcmp(a.mean.rgb.data(), c.mean.rgb.data(), a.mean.rgb.size() * sizeof(float)) != 0);
    }

    void standardErrorShrinksAsOneOverSqrtPaths()
    {
        const DensityGrid d = randomGrid({10, 10, 10}, 11, 0.2);
        lb::LbParams p = lb::paramsFromPreset(*lb::findPreset("dogrose"));
        p.sun = {-0.4f, 1.0f, 0.3f};
        ReferenceSettings s;
        s.paths = 15000;
        const ReferenceResult a = solveReference(d, p, s);
        s.paths = 60000;
        s.seed = 2;
        const ReferenceResult b = solveReference(d, p, s);
        std::vector<double> ratio;
        for (size_t i = 0; i < a.standardError.size(); ++i)
            if (a.standardError[i] > 0.0f && b.standardError[i] > 0.0f) ratio.push_back(double(a.standardError[i]) / double(b.standardError[i]));
        QVERIFY(ratio.size() > a.standardError.size() * 9 / 10);
        std::nth_element(ratio.begin(), ratio.begin() + long(ratio.size() / 2), ratio.end());
        const double median = ratio[ratio.size() / 2];
        qInfo("  4x the paths: standard error falls by %.3f (median over %zu values; 2 expected)", median, ratio.size());
        QVERIFY(median > 1.85 && median < 2.15);
        // And the two estimates agree within their combined errors.
        std::vector<double> ea(a.mean.rgb.begin(), a.mean.rgb.end()), eb(b.mean.rgb.begin(), b.mean.rgb.end()), se;
        for (size_t i = 0; i < a.standardError.size(); ++i)
            se.push_back(std::hypot(double(a.standardError[i]), double(b.standardError[i])) + 1e-30);
        const ZStats z = zStats(ea, eb, se);
        CHECK_Z(z);
    }

    void lbAgainstReferenceOnACloud()
    {
        // What the reference is for: the LB model's error on a small dense cloud (no threshold beyond sanity).
        const int n = 20;
        DensityGrid d = uniformGrid({n, n, n}, 0.0f);
        for (int i = 1; i < n - 1; ++i)
            for (int j = 1; j < n - 1; ++j)
                for (int k = 1; k < n - 1; ++k) {
                    const glm::dvec3 r = (glm::dvec3(i, j, k) - glm::dvec3(9.5)) / glm::dvec3(5.0, 3.5, 5.0);
                    d.density[d.geometry.index(i, j, k)] = float(std::min(1.0, 1.6 * std::exp(-0.5 * glm::dot(r, r))));
                }
        for (const char* preset : {"cloud", "leaf"}) {
            lb::LbParams p = lb::paramsFromPreset(*lb::findPreset(preset));
            p.sun = {0.3f, 1.0f, 0.2f};
            p.tolerance = 1e-5;
            p.maxSteps = 2000;
            lb::SolveStats st;
            LightingGrid lbOut = lb::solveLighting(d, p, nullptr, &st);
            ReferenceSettings s;
            s.paths = 1500000;
            ReferenceResult ref = normalizedReference(d, p, s);
            normalizeToUnobstructed(lbOut, p);
            const double err = relativeL2Interior(lbOut, ref.mean), noise = relativeNoiseInterior(ref.mean, ref.standardError);
            double lbMin = 1e9, refMin = 1e9;
            for (size_t i = 0; i < lbOut.rgb.size(); ++i) {
                lbMin = std::min(lbMin, double(lbOut.rgb[i]));
                refMin = std::min(refMin, double(ref.mean.rgb[i]));
            }
            qInfo("  %s blob %d^3: LB (%d steps) vs reference relative L2 %.4f (reference noise %.4f); darkest node LB %.3f, "
                  "reference %.3f",
                  preset, n, st.steps, err, noise, lbMin, refMin);
            QVERIFY(std::isfinite(err));
            QVERIFY(err < 0.6);
            QVERIFY(noise < 0.02);
        }
    }

    void cancelStops()
    {
        const DensityGrid d = randomGrid({8, 8, 8}, 1, 0.0);
        lb::LbParams p = lb::paramsFromPreset(*lb::findPreset("leaf"));
        int calls = 0;
        Progress progress;
        progress.setCallback([&](double, const std::string&) {
            if (++calls == 1) progress.cancel();
        });
        ReferenceSettings s;
        s.paths = 1000000;
        QVERIFY_THROWS_EXCEPTION(Cancelled, solveReference(d, p, s, &progress));
        QCOMPARE(calls, 1);
    }

    void badInputIsRefused()
    {
        const DensityGrid d = randomGrid({5, 5, 5}, 1, 0.0);
        lb::LbParams p = lb::paramsFromPreset(*lb::findPreset("leaf"));
        ReferenceSettings s;
        s.paths = 1;
        QVERIFY_THROWS_EXCEPTION(Error, solveReference(d, p, s));
        s.paths = 100;
        s.maxBounces = -2;
        QVERIFY_THROWS_EXCEPTION(Error, solveReference(d, p, s));
        s.maxBounces = -1;
        p.channels[2].sigmaS = 2.0f;
        QVERIFY_THROWS_EXCEPTION(Error, solveReference(d, p, s));
        p = lb::paramsFromPreset(*lb::findPreset("leaf"));
        DensityGrid bad = d;
        bad.density[3] = 1.5f;
        QVERIFY_THROWS_EXCEPTION(Error, solveReference(bad, p, s));
    }
};

QTEST_APPLESS_MAIN(TestReference)
#include "tst_reference.moc"
