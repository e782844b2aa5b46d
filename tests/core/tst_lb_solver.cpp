// LB solver against the naive kernel of Geist & Westall, "Lattice-Boltzmann Lighting Models", conservation,
// diffusion, symmetry, tolerance mode, fp16, validation; the shared control flow (lb_device.h) against a
// recording device.
#include <QTest>

#include <numeric>

#include <cmath>
#include <cstring>
#include <random>
#include <string>
#include <vector>

#include "core/base/error.h"
#include "core/base/progress.h"
#include "core/grid/grid.h"
#include "core/grid/grid_compare.h"
#include "core/lb/lattice.h"
#include "core/lb/lb_device.h"
#include "core/lb/lb_params.h"
#include "core/lb/lb_solver.h"
#include "core/lb/omega.h"

using namespace sylva;
using namespace sylva::lb;

namespace {

DensityGrid randomDensity(glm::ivec3 dims, uint32_t seed, double emptyShare, double woodShare)
{
    DensityGrid g;
    g.geometry.dims = dims;
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    g.density.resize(g.geometry.nodeCount());
    g.woodFraction.resize(g.geometry.nodeCount());
    for (size_t n = 0; n < g.density.size(); ++n) {
        g.density[n] = u(rng) < emptyShare ? 0.0f : u(rng);
        g.woodFraction[n] = u(rng) < woodShare ? 1.0f : 0.0f;
    }
    return g;
}

// The naive kernel of Geist & Westall (section 3.1) in double precision: dense Omega, every node pushes
// f_m + rho * (Omega f)_m to r + c_m when that node is interior; plants zero f_0 after each step.
std::vector<double> referenceSolve(const DensityGrid& d, const LbParams& p, int channel, int steps)
{
    const glm::ivec3 n = d.geometry.dims;
    const ChannelParams cp = p.channels[size_t(channel)];
    const DenseOmega green = buildOmega(cp), brown = buildOmega({cp.sigmaA, cp.sigmaS, -1.0f});
    auto idx = [&](int i, int j, int k, int m) { return ((size_t(i) * n.y + j) * kDirections + m) * n.z + k; };
    auto interior = [&](int i, int j, int k) { return i > 0 && j > 0 && k > 0 && i < n.x - 1 && j < n.y - 1 && k < n.z - 1; };
    std::vector<double> from(d.geometry.nodeCount() * kDirections, 0.0);
    const glm::dvec3 dir = -glm::normalize(glm::dvec3(p.sun));
    for (int i = 0; i < n.x; ++i)
        for (int j = 0; j < n.y; ++j)
            for (int k = 0; k < n.z; ++k)
                if (!interior(i, j, k))
                    for (int m = 1; m < kDirections; ++m) {
                        glm::dvec3 c(kC[m][0], kC[m][1], kC[m][2]);
                        from[idx(i, j, k, m)] = std::max(0.0, glm::dot(glm::normalize(c), dir));
                    }
    std::vector<double> to = from;
    for (int t = 0; t < steps; ++t) {
        for (int i = 0; i < n.x; ++i)
            for (int j = 0; j < n.y; ++j)
                for (int k = 0; k < n.z; ++k) {
                    const size_t node = d.geometry.index(i, j, k);
                    const double rho = d.density[node];
                    const bool isBrown = d.woodFraction[node] > p.brownThreshold;
                    const DenseOmega& om = isBrown ? brown : green;
                    for (int m = 0; m < kDirections; ++m) {
                        const int oi = i + kC[m][0], oj = j + kC[m][1], ok = k + kC[m][2];
                        if (!interior(oi, oj, ok)) continue;
                        double flow = 0;
                        for (int q = 0; q < kDirections; ++q) flow += om[size_t(m * kDirections + q)] * from[idx(i, j, k, q)];
                        to[idx(oi, oj, ok, m)] = from[idx(i, j, k, m)] + flow * rho;
                    }
                }
        if (p.zeroF0)
            for (int i = 1; i < n.x - 1; ++i)
                for (int j = 1; j < n.y - 1; ++j)
                    for (int k = 1; k < n.z - 1; ++k) to[idx(i, j, k, 0)] = 0.0;
        std::swap(from, to);
    }
    std::vector<double> total(d.geometry.nodeCount(), 0.0);
    for (int i = 0; i < n.x; ++i)
        for (int j = 0; j < n.y; ++j)
            for (int k = 0; k < n.z; ++k)
                for (int m = 0; m < kDirections; ++m) total[d.geometry.index(i, j, k)] += from[idx(i, j, k, m)];
    return total;
}

std::vector<float> pulseState(const DensityGrid& g, glm::ivec3 at, float sigmaA)
{
    const glm::ivec3 n = g.geometry.dims;
    std::vector<float> f(g.geometry.nodeCount() * kDirections, 0.0f);
    for (int m = 0; m < kDirections; ++m) {
        // The local equilibrium of the appendix, v / (1 + sigma_a), scaled to total mass 1000.
        const double v = m == 0 ? sigmaA : weight(m);
        f[((size_t(at.x) * n.y + at.y) * kDirections + m) * n.z + at.z] = float(1000.0 * v / (1.0 + sigmaA));
    }
    return f;
}

// A device that records what the shared control flow asks of it. No physics: a grid's totals are
// 1000 x sigma_a of the solve, and the change measured after t steps of a grid is 1/t.
class RecordingDevice final : public LbDevice {
public:
    std::vector<std::string> log;
    int levels = 7;                 // autoLevels() of every grid
    double available = 0.0;         // 0: no memory limit
    bool refuseAll = false;         // checkSupported throws

    void checkSupported(const LbParams&) const override
    {
        if (refuseAll) throw Error("the recording device does not run this");
    }
    double availableBytes() const override { return available; }
    std::string memoryName() const override { return "recorded memory"; }
    std::unique_ptr<LbGrid> makeGrid(const DensityGrid& density, const LbParams&, const std::vector<ChannelParams>& solves,
                                     Progress*) override;
    static std::string dims(glm::ivec3 d) { return std::to_string(d.x) + "x" + std::to_string(d.y) + "x" + std::to_string(d.z); }
};

class RecordingGrid final : public LbGrid {
public:
    RecordingGrid(RecordingDevice& device, glm::ivec3 dims, const std::vector<ChannelParams>& solves)
        : m_device(device), m_dims(dims), m_solves(solves)
    {
    }
    void setSolves(const std::vector<ChannelParams>& solves, bool interiorFollows) override
    {
        m_device.log.push_back("set " + name() + " " + std::to_string(solves.size()) + (interiorFollows ? " follows" : ""));
        m_solves = solves;
        m_steps = 0;
    }
    double advanceBlock(int levels, int compareLevel) override
    {
        m_device.log.push_back("advance " + name() + " " + std::to_string(levels) + "/" + std::to_string(compareLevel));
        const int before = m_steps;
        m_steps += levels;
        return compareLevel >= 1 ? 1.0 / double(before + compareLevel) : 0.0;
    }
    int autoLevels() const override { return m_device.levels; }
    void prolongateFrom(const LbGrid& coarse) override
    {
        m_device.log.push_back("prolong " + name() + " <- " + dynamic_cast<const RecordingGrid&>(coarse).name());
    }
    void totals(size_t s, std::vector<float>& out) override
    {
        m_device.log.push_back("totals " + name() + " " + std::to_string(s));
        out.assign(size_t(m_dims.x) * size_t(m_dims.y) * size_t(m_dims.z), 1000.0f * m_solves.at(s).sigmaA);
    }
    std::string name() const { return RecordingDevice::dims(m_dims); }

private:
    RecordingDevice& m_device;
    glm::ivec3 m_dims;
    std::vector<ChannelParams> m_solves;
    int m_steps = 0;
};

std::unique_ptr<LbGrid> RecordingDevice::makeGrid(const DensityGrid& density, const LbParams&,
                                                  const std::vector<ChannelParams>& solves, Progress*)
{
    log.push_back("make " + dims(density.geometry.dims) + " " + std::to_string(solves.size()));
    return std::make_unique<RecordingGrid>(*this, density.geometry.dims, solves);
}

// A device that forwards to another (the CPU one) and logs the grids made, solves set and prolongations.
class ForwardingDevice final : public LbDevice {
public:
    explicit ForwardingDevice(std::unique_ptr<LbDevice> inner) : m_inner(std::move(inner)) {}
    std::vector<std::string> log;

    class Grid final : public LbGrid {
    public:
        Grid(ForwardingDevice& device, glm::ivec3 dims, std::unique_ptr<LbGrid> inner)
            : m_device(device), m_dims(dims), m_inner(std::move(inner))
        {
        }
        void setSolves(const std::vector<ChannelParams>& solves, bool interiorFollows) override
        {
            m_device.log.push_back("set " + RecordingDevice::dims(m_dims) + " " + std::to_string(solves.size()));
            m_inner->setSolves(solves, interiorFollows);
        }
        double advanceBlock(int levels, int compareLevel) override { return m_inner->advanceBlock(levels, compareLevel); }
        int autoLevels() const override { return m_inner->autoLevels(); }
        void prolongateFrom(const LbGrid& coarse) override
        {
            m_device.log.push_back("prolong");
            m_inner->prolongateFrom(*dynamic_cast<const Grid&>(coarse).m_inner);
        }
        void totals(size_t s, std::vector<float>& out) override { m_inner->totals(s, out); }

    private:
        ForwardingDevice& m_device;
        glm::ivec3 m_dims;
        std::unique_ptr<LbGrid> m_inner;
    };

    double availableBytes() const override { return m_inner->availableBytes(); }
    std::string memoryName() const override { return m_inner->memoryName(); }
    std::unique_ptr<LbGrid> makeGrid(const DensityGrid& density, const LbParams& params, const std::vector<ChannelParams>& solves,
                                     Progress* progress) override
    {
        log.push_back("make " + RecordingDevice::dims(density.geometry.dims) + " " + std::to_string(solves.size()));
        return std::make_unique<Grid>(*this, density.geometry.dims, m_inner->makeGrid(density, params, solves, progress));
    }

private:
    std::unique_ptr<LbDevice> m_inner;
};

// The log's entries that start with one of `kinds`.
std::vector<std::string> only(const std::vector<std::string>& log, std::initializer_list<const char*> kinds)
{
    std::vector<std::string> out;
    for (const std::string& e : log)
        for (const char* k : kinds)
            if (e.rfind(k, 0) == 0) out.push_back(e);
    return out;
}

QString joined(const std::vector<std::string>& v)
{
    QString s;
    for (const std::string& e : v) s += QString::fromStdString(e) + "; ";
    return s;
}

} // namespace

class TestLbSolver : public QObject {
    Q_OBJECT
private Q_SLOTS:
    void matchesNaiveKernel_data()
    {
        QTest::addColumn<QString>("preset");
        QTest::addColumn<int>("nx");
        QTest::addColumn<int>("ny");
        QTest::addColumn<int>("nz");
        QTest::addColumn<double>("woodShare");
        QTest::addColumn<float>("sunX");
        QTest::addColumn<float>("sunY");
        QTest::addColumn<float>("sunZ");
        QTest::newRow("leaf 9x7x11") << "leaf" << 9 << 7 << 11 << 0.0 << 0.3f << 1.0f << 0.2f;
        QTest::newRow("leaf brown 10x9x13") << "leaf" << 10 << 9 << 13 << 0.3 << -0.5f << 0.8f << 0.1f;
        QTest::newRow("dogrose brown 8x12x17") << "dogrose" << 8 << 12 << 17 << 0.2 << 0.0f << 0.0f << 1.0f;
        QTest::newRow("cloud 12x6x9") << "cloud" << 12 << 6 << 9 << 0.0 << 1.0f << 1.0f << 1.0f;
        QTest::newRow("pmma 7x7x20") << "pmma" << 7 << 7 << 20 << 0.0 << -1.0f << 0.2f << -0.3f;
        QTest::newRow("isotropic 3x3x3") << "iso" << 3 << 3 << 3 << 0.0 << 0.0f << 1.0f << 0.0f;
        QTest::newRow("isotropic 5x4x3") << "iso" << 5 << 4 << 3 << 0.5 << 0.2f << 1.0f << 0.7f;
    }
    void matchesNaiveKernel()
    {
        QFETCH(QString, preset);
        QFETCH(int, nx);
        QFETCH(int, ny);
        QFETCH(int, nz);
        QFETCH(double, woodShare);
        QFETCH(float, sunX);
        QFETCH(float, sunY);
        QFETCH(float, sunZ);
        LbParams p;
        if (preset == "iso") {
            p.channels = {{{0.2f, 0.7f, 0.0f}, {0.05f, 0.95f, 0.0f}, {0.5f, 0.5f, 0.0f}}};
            p.zeroF0 = false;
        } else {
            p = paramsFromPreset(*findPreset(preset.toStdString()));
        }
        p.sun = {sunX, sunY, sunZ};
        p.steps = 2 * std::max(nx, std::max(ny, nz));
        const DensityGrid d = randomDensity({nx, ny, nz}, uint32_t(nx * 131 + ny * 17 + nz), 0.3, woodShare);
        const LightingGrid out = solveLighting(d, p);
        for (int c = 0; c < 3; ++c) {
            const std::vector<double> ref = referenceSolve(d, p, c, p.steps);
            double maxRef = 0, maxErr = 0;
            for (size_t n = 0; n < ref.size(); ++n) {
                maxRef = std::max(maxRef, std::fabs(ref[n]));
                maxErr = std::max(maxErr, std::fabs(ref[n] - double(out.rgb[n * 3 + size_t(c)])));
            }
            QVERIFY(maxRef > 0.1);
            QVERIFY2(maxErr <= 2e-6 * maxRef, qPrintable(QString("channel %1: max error %2 of %3").arg(c).arg(maxErr).arg(maxRef)));
        }
    }

    void massConservedWithoutAbsorptionLoss()
    {
        // A pulse far from the boundary: nothing reaches it, so the total is conserved when f_0 is kept
        // (for any sigma_a: absorbed mass is re-emitted), and falls by the zeroed f_0 otherwise.
        DensityGrid d = randomDensity({31, 31, 31}, 5, 0.2, 0.0);
        for (float sa : {0.0f, 0.3f}) {
            LbParams p;
            p.channels[0] = {sa, 1.0f - sa, 0.4f};
            p.zeroF0 = false;
            std::vector<float> f = pulseState(d, {15, 15, 15}, sa);
            double before = 0;
            for (float v : f) before += v;
            advance(d, p, f, 12);
            double after = 0;
            for (float v : f) {
                QVERIFY(v >= 0.0f && std::isfinite(v));
                after += v;
            }
            QVERIFY2(std::fabs(after - before) < 1e-4 * before, qPrintable(QString("%1 -> %2").arg(before).arg(after)));
        }
    }

    void pulseSpreadsWithSeedDiffusionCoefficient()
    {
        // Geist & Westall's equation (4) with lambda = tau = 1: D = ((2/sigma_t) - 1) / (4 (1 + sigma_a)); in
        // 3D the second moment of the density grows as d<r^2>/dt = 6 D. Measured between steps 20 and 40 in a
        // uniform medium; within 1%.
        const int n = 91, c = 45;
        DensityGrid d;
        d.geometry.dims = {n, n, n};
        d.density.assign(d.geometry.nodeCount(), 1.0f);
        for (auto [sa, ss] : {std::pair{0.0f, 0.8f}, std::pair{0.1f, 0.8f}}) {
            LbParams p;
            p.channels[0] = {sa, ss, 0.0f};
            p.zeroF0 = false;
            auto moment = [&](const std::vector<float>& f) {
                double m0 = 0, m2 = 0;
                for (int i = 0; i < n; ++i)
                    for (int j = 0; j < n; ++j)
                        for (int mm = 0; mm < kDirections; ++mm)
                            for (int k = 0; k < n; ++k) {
                                const double v = f[((size_t(i) * n + j) * kDirections + mm) * n + k];
                                m0 += v;
                                m2 += v * double((i - c) * (i - c) + (j - c) * (j - c) + (k - c) * (k - c));
                            }
                return m2 / m0;
            };
            std::vector<float> f = pulseState(d, {c, c, c}, sa);
            advance(d, p, f, 20);
            const double r20 = moment(f);
            advance(d, p, f, 20);
            const double r40 = moment(f);
            const double measured = (r40 - r20) / 20.0 / 6.0;
            const double st = double(sa) + double(ss);
            const double expected = (2.0 / st - 1.0) / (4.0 * (1.0 + double(sa)));
            qInfo("sigma_a=%.2f sigma_s=%.2f: D measured %.4f, seed (4) %.4f", double(sa), double(ss), measured, expected);
            QVERIFY2(std::fabs(measured - expected) < 0.01 * expected,
                     qPrintable(QString("D measured %1, expected %2").arg(measured).arg(expected)));
        }
    }

    void symmetricInputGivesSymmetricOutput()
    {
        // Density mirrored in x, sun in the y-z plane: the lighting is mirror-symmetric in x.
        DensityGrid d = randomDensity({13, 11, 9}, 21, 0.3, 0.2);
        const glm::ivec3 n = d.geometry.dims;
        for (int i = 0; i < n.x / 2; ++i)
            for (int j = 0; j < n.y; ++j)
                for (int k = 0; k < n.z; ++k) {
                    d.density[d.geometry.index(n.x - 1 - i, j, k)] = d.density[d.geometry.index(i, j, k)];
                    d.woodFraction[d.geometry.index(n.x - 1 - i, j, k)] = d.woodFraction[d.geometry.index(i, j, k)];
                }
        LbParams p = paramsFromPreset(*findPreset("leaf"));
        p.sun = {0.0f, 1.0f, 0.4f};
        const LightingGrid out = solveLighting(d, p);
        float maxV = 0, maxDiff = 0;
        for (int i = 0; i < n.x; ++i)
            for (int j = 0; j < n.y; ++j)
                for (int k = 0; k < n.z; ++k)
                    for (int c = 0; c < 3; ++c) {
                        maxV = std::max(maxV, out.at(i, j, k, c));
                        maxDiff = std::max(maxDiff, std::fabs(out.at(i, j, k, c) - out.at(n.x - 1 - i, j, k, c)));
                    }
        QVERIFY2(maxDiff <= 1e-5f * maxV, qPrintable(QString("asymmetry %1 of %2").arg(maxDiff).arg(maxV)));
    }

    void passThroughWhenNothingInteracts()
    {
        // sigma_a = 0, g = 1 (any density) equals an empty grid: light streams straight through.
        DensityGrid dense = randomDensity({10, 9, 8}, 2, 0.0, 0.0);
        DensityGrid empty = dense;
        std::fill(empty.density.begin(), empty.density.end(), 0.0f);
        LbParams p;
        p.channels = {{{0.0f, 1.0f, 1.0f}, {0.0f, 0.5f, 1.0f}, {0.0f, 0.0f, 0.0f}}};
        p.zeroF0 = false;
        p.sun = {0.3f, 1.0f, -0.2f};
        const LightingGrid a = solveLighting(dense, p), b = solveLighting(empty, p);
        QVERIFY(relativeL2(a, b) < 1e-6);
    }

    void toleranceModeReachesFixedStepAnswer()
    {
        DensityGrid d = randomDensity({24, 30, 24}, 9, 0.5, 0.1);
        LbParams p = paramsFromPreset(*findPreset("leaf"));
        p.sun = {0.2f, 1.0f, 0.3f};
        const LightingGrid fixed = solveLighting(d, p);
        p.tolerance = 1e-3;
        p.checkEvery = 4;
        SolveStats st;
        const LightingGrid tol = solveLighting(d, p, nullptr, &st);
        qInfo("tolerance 1e-3: %d steps (fixed %d), converged %d, rel L2 %.2e", st.steps, 2 * 30, int(st.converged), relativeL2(tol, fixed));
        QVERIFY(st.converged);
        QVERIFY(st.steps < 60);
        QVERIFY(relativeL2(tol, fixed) < 0.01);
    }

    // Coarse start: the same steady state (within the tolerance's error), in fewer fine steps than a
    // tolerance run from zero, with the coarse levels' steps counted; an empty grid starts converged.
    void coarseStartReachesTheSameAnswer()
    {
        DensityGrid d = randomDensity({40, 48, 36}, 5, 0.5, 0.1);
        LbParams p = paramsFromPreset(*findPreset("leaf"));
        p.sun = {0.2f, 1.0f, 0.3f};
        p.steps = 4 * 48;   // well converged reference
        const LightingGrid ref = solveLighting(d, p);
        p.steps = 0;
        p.tolerance = 1e-3;
        SolveStats plain, coarse;
        const LightingGrid a = solveLighting(d, p, nullptr, &plain);
        p.coarseStart = true;
        const LightingGrid b = solveLighting(d, p, nullptr, &coarse);
        qInfo("tolerance 1e-3: from zero %d steps, rel L2 %.2e; coarse start %d fine + %d coarse steps, rel L2 %.2e", plain.steps,
              relativeL2(a, ref), coarse.steps, coarse.coarseSteps, relativeL2(b, ref));
        QVERIFY(coarse.coarseSteps > 0);
        QVERIFY(coarse.steps < plain.steps);
        QVERIFY(relativeL2(b, ref) < relativeL2(a, ref));   // closer to the steady state, in fewer fine steps
        QVERIFY(relativeL2(b, ref) < 0.02);

        DensityGrid empty = d;
        std::fill(empty.density.begin(), empty.density.end(), 0.0f);
        SolveStats e;
        const LightingGrid open = solveLighting(empty, p, nullptr, &e);
        const std::vector<float> bc = boundaryDistribution(p.sun);
        const float free = std::accumulate(bc.begin(), bc.end(), 0.0f);
        for (float v : open.rgb) QVERIFY(std::fabs(v - free) < 1e-5f * free);
        QVERIFY(e.steps <= 16);
    }

    void fp16StorageCloseToFp32()
    {
        DensityGrid d = randomDensity({20, 24, 18}, 4, 0.4, 0.1);
        LbParams p = paramsFromPreset(*findPreset("leaf"));
        p.sun = {0.5f, 1.0f, 0.0f};
        const LightingGrid a = solveLighting(d, p);
        p.storage = Storage::Fp16;
        const LightingGrid b = solveLighting(d, p);
        const double err = relativeL2(b, a);
        qInfo("fp16 storage: rel L2 error %.2e", err);
        QVERIFY(err < 5e-3);
    }

    void equalChannelsShareOneSolve()
    {
        DensityGrid d = randomDensity({9, 9, 9}, 1, 0.3, 0.0);
        LbParams p = paramsFromPreset(*findPreset("cloud"));
        p.intensity = {1.0f, 0.5f, 2.0f};
        SolveStats st;
        const LightingGrid out = solveLighting(d, p, nullptr, &st);
        QCOMPARE(st.channelSolves, 1);
        const std::vector<double> ref = referenceSolve(d, p, 0, 18);
        for (size_t n = 0; n < ref.size(); ++n)
            for (int c = 0; c < 3; ++c)
                QVERIFY(std::fabs(out.rgb[n * 3 + size_t(c)] - p.intensity[c] * ref[n]) <= 2e-6 * std::max(1.0, p.intensity[c] * ref[n]));
    }

    void blockDepthDoesNotChangeTheResult()
    {
        // The wavefront (temporal blocking) reorders work but not arithmetic: bit-identical output.
        DensityGrid d = randomDensity({17, 12, 10}, 8, 0.3, 0.2);
        LbParams p = paramsFromPreset(*findPreset("dogrose"));
        p.sun = {0.4f, 1.0f, -0.3f};
        p.steps = 23;
        p.blockSteps = 1;
        const LightingGrid one = solveLighting(d, p);
        for (int block : {2, 5, 16, 40}) {
            p.blockSteps = block;
            const LightingGrid other = solveLighting(d, p);
            QVERIFY2(std::memcmp(one.rgb.data(), other.rgb.data(), one.rgb.size() * sizeof(float)) == 0,
                     qPrintable(QString("block %1 differs").arg(block)));
        }
    }

    void channelsOneAtATimeEqualAllAtOnce()
    {
        // The memory fallback (one channel solve per pass) computes the same numbers.
        DensityGrid d = randomDensity({11, 9, 10}, 12, 0.3, 0.2);
        LbParams p = paramsFromPreset(*findPreset("leaf"));
        p.sun = {0.1f, 1.0f, 0.6f};
        const LightingGrid all = solveLighting(d, p);
        p.solvesPerPass = 1;
        const LightingGrid one = solveLighting(d, p);
        QVERIFY(std::memcmp(all.rgb.data(), one.rgb.data(), all.rgb.size() * sizeof(float)) == 0);
    }

    void reusedMemoryGivesEachChannelItsOwnSolve()
    {
        // Channel solves run one after another in the same memory (and the same coarse-start levels,
        // which only rewrite what the next solve reads). Each channel must equal a solve of that
        // channel alone in fresh memory, to the bit, in fixed-step, tolerance and coarse-start modes.
        DensityGrid d = randomDensity({40, 34, 37}, 21, 0.4, 0.15);
        LbParams p = paramsFromPreset(*findPreset("dogrose"));
        p.sun = {0.3f, 1.0f, -0.5f};
        p.storage = Storage::Fp16;
        for (int mode = 0; mode < 3; ++mode) {
            LbParams q = p;
            if (mode == 0) q.steps = 30;
            if (mode >= 1) q.tolerance = 2e-3;
            if (mode == 2) q.coarseStart = true;
            SolveStats all;
            const LightingGrid together = solveLighting(d, q, nullptr, &all);
            QCOMPARE(all.channelSolves, 3);
            if (mode == 2) QVERIFY(all.coarseSteps > 0);
            for (int c = 0; c < 3; ++c) {
                LbParams alone = q;
                for (int o = 0; o < 3; ++o) alone.channels[size_t(o)] = q.channels[size_t(c)];
                const LightingGrid one = solveLighting(d, alone);
                for (size_t n = 0; n < d.geometry.nodeCount(); ++n)
                    QVERIFY2(together.rgb[n * 3 + size_t(c)] == one.rgb[n * 3 + size_t(c)],
                             qPrintable(QString("mode %1 channel %2 node %3: %4 vs %5").arg(mode).arg(c).arg(n)
                                            .arg(double(together.rgb[n * 3 + size_t(c)])).arg(double(one.rgb[n * 3 + size_t(c)]))));
            }
        }
    }

    // Fixed steps: blocks of the device's depth, solves per pass grouped, each channel's output the
    // totals of its solve times its intensity, progress after each block.
    void controlDrivesTheDeviceInFixedSteps()
    {
        const DensityGrid d = randomDensity({6, 5, 4}, 1, 0.5, 0.0);
        LbParams p = paramsFromPreset(*findPreset("leaf"));   // three distinct channels
        p.intensity = {1.0f, 2.0f, 0.5f};
        p.steps = 20;
        p.solvesPerPass = 2;
        RecordingDevice device;
        std::vector<std::pair<double, std::string>> reports;
        Progress progress([&](double f, const std::string& m) { reports.emplace_back(f, m); });
        SolveStats st;
        const LightingGrid out = solveOnDevice(device, d, p, &progress, &st);
        const std::vector<std::string> expected = {
            "make 6x5x4 2",      "advance 6x5x4 7/0", "advance 6x5x4 7/0", "advance 6x5x4 6/0", "totals 6x5x4 0",
            "totals 6x5x4 1",    "set 6x5x4 1",       "advance 6x5x4 7/0", "advance 6x5x4 7/0", "advance 6x5x4 6/0",
            "totals 6x5x4 0"};
        QVERIFY2(device.log == expected, qPrintable(joined(device.log)));
        QCOMPARE(st.steps, 20);
        QCOMPARE(st.channelSolves, 3);
        QCOMPARE(st.blockSteps, 7);
        QVERIFY(!st.converged);
        QCOMPARE(st.bytesPerStep, 2.0 * 120 * kDirections * 4 * 3);
        QCOMPARE(out.rgb.size(), size_t(120 * 3));
        for (size_t n = 0; n < 120; ++n)
            for (int c = 0; c < 3; ++c)
                QCOMPARE(out.rgb[n * 3 + size_t(c)], 1000.0f * p.channels[size_t(c)].sigmaA * p.intensity[c]);
        QCOMPARE(reports.size(), size_t(6));
        QCOMPARE(reports.back().first, 1.0);
        QCOMPARE(QString::fromStdString(reports.back().second), QString("LB step 20/20 (channel group 2/2)"));
        QCOMPARE(reports[2].first, 0.5);
    }

    // Tolerance mode: with a check period every block measures the change between its last two
    // steps and the solve stops under the tolerance; without one, every third block of 7 (~16 steps)
    // and the last block are checked.
    void controlDrivesTheDeviceToTheTolerance()
    {
        const DensityGrid d = randomDensity({6, 5, 4}, 1, 0.5, 0.0);
        LbParams p = paramsFromPreset(*findPreset("cloud"));   // one solve for the three channels
        p.tolerance = 1.0 / 30.0;
        p.checkEvery = 5;
        p.maxSteps = 100;
        RecordingDevice device;
        SolveStats st;
        solveOnDevice(device, d, p, nullptr, &st);
        // The change after t steps is 1/t: checks at t = 4, 9, ..., 34, the first under 1/30.
        const std::vector<std::string> advances = only(device.log, {"advance"});
        QCOMPARE(advances.size(), size_t(7));
        for (const std::string& a : advances) QCOMPARE(QString::fromStdString(a), QString("advance 6x5x4 5/4"));
        QCOMPARE(st.channelSolves, 1);
        QVERIFY(st.converged);
        QCOMPARE(st.steps, 35);
        QCOMPARE(st.changeHistory.size(), size_t(7));
        QCOMPARE(st.changeHistory.back().first, 35);
        QCOMPARE(st.changeHistory.back().second, 1.0 / 34.0);
        QCOMPARE(st.lastChange, 1.0 / 34.0);

        p.checkEvery = 0;
        p.tolerance = 1e-9;   // never reached
        p.maxSteps = 45;
        device.log.clear();
        solveOnDevice(device, d, p, nullptr, &st);
        const std::vector<std::string> expected = {"advance 6x5x4 7/0", "advance 6x5x4 7/0", "advance 6x5x4 7/6",
                                                   "advance 6x5x4 7/0", "advance 6x5x4 7/0", "advance 6x5x4 7/6",
                                                   "advance 6x5x4 3/2"};
        QVERIFY2(only(device.log, {"advance"}) == expected, qPrintable(joined(device.log)));
        QVERIFY(!st.converged);
        QCOMPARE(st.steps, 45);
        QCOMPARE(st.changeHistory.size(), size_t(3));
    }

    // Coarse start: the levels (half resolution while the longest edge is >= 32) are made once, solved
    // coarsest first, each started from the next coarser one, and the fine grid from the finest level;
    // the next channel solve reuses every grid, writing only what the interpolation does not.
    void controlDrivesTheCoarseStartLevels()
    {
        const DensityGrid d = randomDensity({70, 40, 33}, 1, 0.5, 0.0);
        LbParams p = paramsFromPreset(*findPreset("leaf"));
        p.tolerance = 0.2;   // the scripted change 1/t falls under it at the first check
        p.checkEvery = 7;
        p.coarseStart = true;
        RecordingDevice device;
        SolveStats st;
        solveOnDevice(device, d, p, nullptr, &st);
        const std::vector<std::string> expected = {
            "make 70x40x33 1",          "make 19x11x9 1",
            "make 36x21x17 1",          "prolong 36x21x17 <- 19x11x9",
            "prolong 70x40x33 <- 36x21x17",
            "set 70x40x33 1 follows",   "set 19x11x9 1",
            "set 36x21x17 1 follows",   "prolong 36x21x17 <- 19x11x9",
            "prolong 70x40x33 <- 36x21x17",
            "set 70x40x33 1 follows",   "set 19x11x9 1",
            "set 36x21x17 1 follows",   "prolong 36x21x17 <- 19x11x9",
            "prolong 70x40x33 <- 36x21x17"};
        const std::vector<std::string> structure = only(device.log, {"make", "set", "prolong"});
        QVERIFY2(structure == expected, qPrintable(joined(structure)));
        // Each level runs one block of 7 steps to its first check (1/6 < 0.2), the fine grid too.
        QCOMPARE(st.coarseSteps, 14);
        QCOMPARE(st.steps, 7);
        QVERIFY(st.converged);
        // Without tolerance mode there is no coarse start.
        p.tolerance = 0.0;
        p.steps = 3;
        device.log.clear();
        solveOnDevice(device, d, p, nullptr, &st);
        QVERIFY2(only(device.log, {"prolong"}).empty(), qPrintable(joined(device.log)));
        QCOMPARE(st.coarseSteps, 0);
    }

    // Memory: a device without room for one channel solve refuses with its message and makes no grid;
    // with room for one but not all, solves per pass falls back to one. checkSupported comes first.
    void controlChecksTheDevicesMemoryAndSupport()
    {
        const DensityGrid d = randomDensity({10, 10, 10}, 1, 0.5, 0.0);
        LbParams p = paramsFromPreset(*findPreset("leaf"));
        p.steps = 2;
        p.solvesPerPass = 3;
        RecordingDevice device;
        const double perSolve = 2.0 * 1000 * kDirections * 4, other = 1000 * 20.0;
        device.available = (perSolve + other) / 0.8 * 1.01;
        solveOnDevice(device, d, p, nullptr, nullptr);
        QVERIFY2(only(device.log, {"make"}) == std::vector<std::string>{"make 10x10x10 1"}, qPrintable(joined(device.log)));
        device.available = (perSolve * 3 + other) / 0.8 * 1.01;
        device.log.clear();
        solveOnDevice(device, d, p, nullptr, nullptr);
        QVERIFY2(only(device.log, {"make"}) == std::vector<std::string>{"make 10x10x10 3"}, qPrintable(joined(device.log)));
        device.available = 1000;
        device.log.clear();
        try {
            solveOnDevice(device, d, p, nullptr, nullptr);
            QFAIL("a grid too large for the device was accepted");
        } catch (const Error& e) {
            QVERIFY2(QString(e.what()).contains("of recorded memory is available"), e.what());
        }
        QVERIFY(device.log.empty());
        device.available = 0;
        device.refuseAll = true;
        QVERIFY_THROWS_EXCEPTION(Error, solveOnDevice(device, d, p, nullptr, nullptr));
        QVERIFY(device.log.empty());
    }

    // Cancel between blocks stops the solve: no further block is asked for.
    void controlStopsOnCancel()
    {
        const DensityGrid d = randomDensity({6, 5, 4}, 1, 0.5, 0.0);
        LbParams p = paramsFromPreset(*findPreset("leaf"));
        p.steps = 40;
        RecordingDevice device;
        Progress progress;
        progress.setCallback([&](double, const std::string&) { progress.cancel(); });
        QVERIFY_THROWS_EXCEPTION(Cancelled, solveOnDevice(device, d, p, &progress, nullptr));
        QCOMPARE(only(device.log, {"advance"}).size(), size_t(1));
    }

    // The CPU device driven through the interface (a device that forwards to it and logs): the same
    // bits and stats as solveLighting, with coarse start and two solves per pass.
    void cpuDeviceThroughTheInterfaceEqualsSolveLighting()
    {
        DensityGrid d = randomDensity({34, 20, 18}, 9, 0.5, 0.1);
        LbParams p = paramsFromPreset(*findPreset("leaf"));
        p.tolerance = 1e-3;
        p.coarseStart = true;
        p.solvesPerPass = 2;
        SolveStats a, b;
        const LightingGrid direct = solveLighting(d, p, nullptr, &a);
        ForwardingDevice device(makeCpuDevice());
        const LightingGrid driven = solveOnDevice(device, d, p, nullptr, &b);
        QVERIFY(std::memcmp(direct.rgb.data(), driven.rgb.data(), direct.rgb.size() * sizeof(float)) == 0);
        QCOMPARE(b.steps, a.steps);
        QCOMPARE(b.coarseSteps, a.coarseSteps);
        QVERIFY(a.coarseSteps > 0);
        QVERIFY(b.changeHistory == a.changeHistory);
        const std::vector<std::string> expected = {"make 34x20x18 2", "make 18x11x10 2", "prolong", "set 34x20x18 1",
                                                   "set 18x11x10 1", "prolong"};
        QVERIFY2(device.log == expected, qPrintable(joined(device.log)));
    }

    void invalidParametersAreRefused_data()
    {
        QTest::addColumn<float>("sa");
        QTest::addColumn<float>("ss");
        QTest::addColumn<float>("g");
        QTest::addColumn<QString>("mentions");
        QTest::newRow("sigma_t > 1") << 0.5f << 0.6f << 0.0f << "stability bound 1";
        QTest::newRow("negative sigma_a") << -0.1f << 0.5f << 0.0f << "sigma_a";
        QTest::newRow("negative sigma_s") << 0.1f << -0.5f << 0.0f << "sigma_s";
        QTest::newRow("g > 1") << 0.1f << 0.5f << 1.5f << "g = ";
        QTest::newRow("NaN g") << 0.1f << 0.5f << NAN << "g = ";
        QTest::newRow("inf sigma_s") << 0.1f << INFINITY << 0.0f << "sigma_s";
    }
    void invalidParametersAreRefused()
    {
        QFETCH(float, sa);
        QFETCH(float, ss);
        QFETCH(float, g);
        QFETCH(QString, mentions);
        DensityGrid d = randomDensity({5, 5, 5}, 1, 0.0, 0.0);
        LbParams p;
        p.channels[1] = {sa, ss, g};
        try {
            solveLighting(d, p);
            QFAIL("accepted invalid parameters");
        } catch (const Error& e) {
            QVERIFY2(QString(e.what()).contains(mentions), e.what());
            QVERIFY2(QString(e.what()).contains("channel G"), e.what());
        }
    }

    void invalidDensityIsRefused()
    {
        DensityGrid d = randomDensity({5, 5, 5}, 1, 0.0, 0.0);
        LbParams p;
        d.density[17] = 1.5f;
        QVERIFY_THROWS_EXCEPTION(Error, solveLighting(d, p));
        d.density[17] = NAN;
        QVERIFY_THROWS_EXCEPTION(Error, solveLighting(d, p));
        d.density[17] = 0.5f;
        d.geometry.dims = {2, 5, 5};
        QVERIFY_THROWS_EXCEPTION(Error, solveLighting(d, p));
        d.geometry.dims = {5, 5, 5};
        p.sun = {0, 0, 0};
        QVERIFY_THROWS_EXCEPTION(Error, solveLighting(d, p));
    }

    void cancelStopsTheSolve()
    {
        DensityGrid d = randomDensity({16, 16, 16}, 1, 0.0, 0.0);
        LbParams p = paramsFromPreset(*findPreset("leaf"));
        int calls = 0;
        Progress progress;
        progress.setCallback([&](double, const std::string&) {
            if (++calls == 1) progress.cancel();
        });
        QVERIFY_THROWS_EXCEPTION(Cancelled, solveLighting(d, p, &progress));
        QCOMPARE(calls, 1);
    }
};

QTEST_APPLESS_MAIN(TestLbSolver)
#include "tst_lb_solver.moc"
