// Shared helpers of the LB extremes tests: density kinds, explicit states, post-collision values and photon balance.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <string>
#include <vector>

#include <QString>
#include <QTest>

#include <glm/glm.hpp>

#include "core/grid/grid.h"
#include "core/lb/lattice.h"
#include "core/lb/lb_params.h"
#include "core/lb/lb_solver.h"
#include "core/scene/scene.h"

// QVERIFY2 builds its message even when the check passes; in the sweeps' inner loops only a failure should.
#define LBX_CHECK(cond, message)                                                               \
    do {                                                                                        \
        if (!(cond)) QFAIL(qPrintable(QString("'%1' failed: %2").arg(#cond).arg(message)));   \
    } while (false)

namespace sylva::lbx {

using lb::kC;
using lb::kDirections;

// The g values of the sweep: both |g| = 1 limits and values just under them.
inline const std::vector<float>& sweepG()
{
    static const std::vector<float> g = {-1.0f, -0.999999f, -0.5f, 0.0f, 0.5f, 0.999999f, 1.0f};
    return g;
}
inline const std::vector<float>& sweepSigmaA()
{
    static const std::vector<float> a = {0.0f, 1e-7f, 0.5f, 1.0f};
    return a;
}
// sigma_s for a given sigma_a: none, half the room, and the stability bound sigma_a + sigma_s = 1 exactly.
inline std::vector<float> sweepSigmaS(float sigmaA)
{
    std::vector<float> s = {0.0f};
    if (sigmaA < 1.0f) {
        s.push_back(0.5f * (1.0f - sigmaA));
        s.push_back(1.0f - sigmaA);   // the float sum sigma_a + sigma_s is exactly 1 for every sweep value
    }
    return s;
}

enum class DensityKind { Zero, One, Random };
inline const char* densityName(DensityKind k) { return k == DensityKind::Zero ? "rho0" : (k == DensityKind::One ? "rho1" : "rhoRand"); }

// Density everywhere (margin nodes included: the solver must cope with medium on its boundary).
// Random: a quarter empty, a quarter full, some 1e-7 and the rest uniform; a tenth of the nodes brown.
inline DensityGrid makeDensity(glm::ivec3 dims, DensityKind kind, uint32_t seed = 1)
{
    DensityGrid d;
    d.geometry.dims = dims;
    d.geometry.spacing = 1.0;
    const size_t n = d.geometry.nodeCount();
    d.density.assign(n, kind == DensityKind::One ? 1.0f : 0.0f);
    d.woodFraction.assign(n, 0.0f);
    if (kind == DensityKind::Random) {
        std::mt19937 rng(seed);
        std::uniform_real_distribution<float> u(0.0f, 1.0f);
        for (size_t i = 0; i < n; ++i) {
            const float pick = u(rng);
            d.density[i] = pick < 0.25f ? 0.0f : (pick < 0.5f ? 1.0f : (pick < 0.55f ? 1e-7f : u(rng)));
            d.woodFraction[i] = u(rng) < 0.1f ? 1.0f : 0.0f;
        }
    }
    return d;
}

struct SunCase {
    std::string name;
    glm::vec3 sun;
};

// Along axes, along lattice (face and body) diagonals, grazing (0.01 degrees above the horizon).
inline const std::vector<SunCase>& sweepSuns()
{
    static const std::vector<SunCase> s = {
        {"+y", {0.0f, 1.0f, 0.0f}},
        {"-x", {-1.0f, 0.0f, 0.0f}},
        {"+z", {0.0f, 0.0f, 1.0f}},
        {"diag(1,1,0)", {1.0f, 1.0f, 0.0f}},
        {"diag(0,-1,1)", {0.0f, -1.0f, 1.0f}},
        {"body(1,1,1)", {1.0f, 1.0f, 1.0f}},
        {"grazing 0.01deg az 30", sunDirection(0.01, 30.0)},
        {"grazing 0.01deg az 0", sunDirection(0.01, 0.0)},
    };
    return s;
}

inline size_t fIndex(const glm::ivec3& n, int i, int j, int k, int m)
{
    return ((size_t(i) * size_t(n.y) + size_t(j)) * size_t(kDirections) + size_t(m)) * size_t(n.z) + size_t(k);
}
inline bool interior(const glm::ivec3& n, int i, int j, int k)
{
    return i > 0 && j > 0 && k > 0 && i < n.x - 1 && j < n.y - 1 && k < n.z - 1;
}

// The solver's initial state: boundary nodes hold the sun's distribution (unit intensity), interior nodes 0.
inline std::vector<float> initialState(const glm::ivec3& n, const glm::vec3& sun)
{
    const std::vector<float> bc = lb::boundaryDistribution(sun);
    std::vector<float> f(size_t(n.x) * size_t(n.y) * size_t(n.z) * kDirections, 0.0f);
    for (int i = 0; i < n.x; ++i)
        for (int j = 0; j < n.y; ++j)
            for (int k = 0; k < n.z; ++k)
                if (!interior(n, i, j, k))
                    for (int m = 0; m < kDirections; ++m) f[fIndex(n, i, j, k, m)] = bc[size_t(m)];
    return f;
}

// Post-collision values post_m(r) = f_m(r) + rho (Omega f)_m of every node (boundary nodes included),
// observed through the solver itself: the grid is embedded two nodes deep in an empty, dark lattice and
// advanced one step, so every post_m(r) lands on the interior node r + c_m of the larger lattice.
// post_0 reads 0 with zeroF0 (the solver drops it before streaming). Same layout as f.
inline std::vector<float> postCollision(const DensityGrid& d, const lb::LbParams& p, const std::vector<float>& f)
{
    const glm::ivec3 n = d.geometry.dims, big = n + 4;
    DensityGrid e;
    e.geometry.dims = big;
    e.density.assign(e.geometry.nodeCount(), 0.0f);
    e.woodFraction.assign(e.geometry.nodeCount(), 0.0f);
    std::vector<float> F(e.geometry.nodeCount() * kDirections, 0.0f);
    for (int i = 0; i < n.x; ++i)
        for (int j = 0; j < n.y; ++j)
            for (int k = 0; k < n.z; ++k) {
                const size_t src = d.geometry.index(i, j, k), dst = e.geometry.index(i + 2, j + 2, k + 2);
                e.density[dst] = d.density[src];
                if (!d.woodFraction.empty()) e.woodFraction[dst] = d.woodFraction[src];
                for (int m = 0; m < kDirections; ++m) F[fIndex(big, i + 2, j + 2, k + 2, m)] = f[fIndex(n, i, j, k, m)];
            }
    lb::advance(e, p, F, 1);
    std::vector<float> post(f.size(), 0.0f);
    for (int i = 0; i < n.x; ++i)
        for (int j = 0; j < n.y; ++j)
            for (int k = 0; k < n.z; ++k)
                for (int m = 0; m < kDirections; ++m)
                    post[fIndex(n, i, j, k, m)] =
                        F[fIndex(big, i + 2 + kC[m][0], j + 2 + kC[m][1], k + 2 + kC[m][2], m)];
    return post;
}

// Photon bookkeeping of one step from state f (docs/LB_MODEL.md "Update"): content = sum of f over the
// interior; inflow = post values that boundary nodes send into the interior; outflow = post values
// that interior nodes send onto the boundary (dropped); absorbed = what interior collisions remove
// (f_0 dropped by plants). With these, content(t+1) = content(t) + inflow - outflow - absorbed.
struct StepBalance {
    double content = 0.0, inflow = 0.0, outflow = 0.0, absorbed = 0.0;
    double minPost = 0.0;      // smallest post-collision value anywhere
    double maxNodeGain = 0.0;  // largest (sum post - sum f) / sum f at one node: photons made by a collision (~0)
};

inline StepBalance stepBalance(const DensityGrid& d, const lb::LbParams& p, const std::vector<float>& f)
{
    const glm::ivec3 n = d.geometry.dims;
    const std::vector<float> post = postCollision(d, p, f);
    StepBalance b;
    b.minPost = 1e300;
    b.maxNodeGain = -1e300;
    for (int i = 0; i < n.x; ++i)
        for (int j = 0; j < n.y; ++j)
            for (int k = 0; k < n.z; ++k) {
                const bool in = interior(n, i, j, k);
                double before = 0.0, after = 0.0;
                for (int m = 0; m < kDirections; ++m) {
                    const double v = post[fIndex(n, i, j, k, m)];
                    before += f[fIndex(n, i, j, k, m)];
                    after += v;
                    b.minPost = std::min(b.minPost, v);
                    const bool toInterior = m != 0 && interior(n, i + kC[m][0], j + kC[m][1], k + kC[m][2]);
                    if (in && m != 0 && !toInterior) b.outflow += v;
                    if (!in && toInterior) b.inflow += v;
                }
                if (before > 0.0) b.maxNodeGain = std::max(b.maxNodeGain, (after - before) / before);
                else b.maxNodeGain = std::max(b.maxNodeGain, after > 0.0 ? 1.0 : 0.0);
                if (in) {
                    b.content += before;
                    b.absorbed += before - after;
                }
            }
    return b;
}

inline double interiorContent(const glm::ivec3& n, const std::vector<float>& f)
{
    double s = 0.0;
    for (int i = 1; i < n.x - 1; ++i)
        for (int j = 1; j < n.y - 1; ++j)
            for (int m = 0; m < kDirections; ++m)
                for (int k = 1; k < n.z - 1; ++k) s += f[fIndex(n, i, j, k, m)];
    return s;
}

// The photon density of unobstructed space for unit intensity (sum of the boundary distribution).
inline double freeDensity(const glm::vec3& sun)
{
    double s = 0.0;
    for (float v : lb::boundaryDistribution(sun)) s += v;
    return s;
}

// Channel label for messages.
inline std::string channelText(const lb::ChannelParams& c)
{
    char buf[128];
    std::snprintf(buf, sizeof buf, "sigma_a=%g sigma_s=%g g=%.7g", double(c.sigmaA), double(c.sigmaS), double(c.g));
    return buf;
}

// Every (sigma_a, sigma_s, g) of the sweep: 7 g x 10 optics.
inline std::vector<lb::ChannelParams> allChannels()
{
    std::vector<lb::ChannelParams> out;
    for (float g : sweepG())
        for (float sa : sweepSigmaA())
            for (float ss : sweepSigmaS(sa)) out.push_back({sa, ss, g});
    return out;
}

// Checks one solve's output. Finite and >= 0 everywhere; boundary nodes hold the unobstructed density
// (they never change); an empty grid is unobstructed everywhere (relative tolerance tol); nothing exceeds
// `bound` x the unobstructed density. Returns an empty string when it passes, else what failed.
// maxRatio receives the largest output / unobstructed density seen.
inline QString checkSolve(const DensityGrid& d, const lb::LbParams& p, const LightingGrid& out, double tol, double bound,
                          const QString& what, double* maxRatio)
{
    const glm::ivec3 n = d.geometry.dims;
    const double free = freeDensity(p.sun);
    const bool empty = std::all_of(d.density.begin(), d.density.end(), [](float r) { return r == 0.0f; });
    for (int i = 0; i < n.x; ++i)
        for (int j = 0; j < n.y; ++j)
            for (int k = 0; k < n.z; ++k)
                for (int c = 0; c < 3; ++c) {
                    const float v = out.at(i, j, k, c);
                    const double ref = free * double(p.intensity[c]);
                    auto where = [&](const char* why) {
                        return QString("%1, channel %2 (%3), node (%4,%5,%6) = %7: %8")
                            .arg(what).arg(c).arg(channelText(p.channels[size_t(c)]).c_str())
                            .arg(i).arg(j).arg(k).arg(double(v), 0, 'g', 9).arg(why);
                    };
                    if (!std::isfinite(v) || v < 0.0f) return where("not finite or negative");
                    *maxRatio = std::max(*maxRatio, double(v) / ref);
                    if ((!interior(n, i, j, k) || empty) && std::fabs(double(v) - ref) > tol * ref)
                        return where("differs from the unobstructed density");
                    if (double(v) > bound * ref) return where("above the bound");
                }
    return {};
}

// fp16 against fp32 on the same solve: per channel, relative L2 error <= 5e-3 and no value off by
// more than maxErr x the unobstructed density; and no flush to zero: wherever fp32 sees more than 1e-4
// of the unobstructed density (about fp16's smallest normal), fp16 sees light too. Returns an empty
// string when it passes; worst receives the largest error seen (fraction of the unobstructed density).
inline QString compareFp16(const lb::LbParams& p, const LightingGrid& fp32, const LightingGrid& fp16, double maxErr,
                           const QString& what, double* worst)
{
    const double free = freeDensity(p.sun);
    double diff[3] = {0.0, 0.0, 0.0}, norm[3] = {0.0, 0.0, 0.0};
    for (size_t i = 0; i < fp32.rgb.size(); ++i) {
        const size_t c = i % 3;
        const double ref = free * double(p.intensity[int(c)]);
        const double d = double(fp16.rgb[i]) - double(fp32.rgb[i]);
        const double err = std::fabs(d) / ref;
        diff[c] += d * d;
        norm[c] += double(fp32.rgb[i]) * double(fp32.rgb[i]);
        *worst = std::max(*worst, err);
        if (!(err <= maxErr) || (double(fp32.rgb[i]) > 1e-4 * ref && !(fp16.rgb[i] > 0.0f)))
            return QString("%1, channel %2 (%3), value %4: fp16 %5, fp32 %6")
                .arg(what).arg(c).arg(channelText(p.channels[c]).c_str()).arg(i / 3)
                .arg(double(fp16.rgb[i]), 0, 'g', 9).arg(double(fp32.rgb[i]), 0, 'g', 9);
    }
    for (size_t c = 0; c < 3; ++c)
        if (norm[c] > 0.0 && !(std::sqrt(diff[c] / norm[c]) <= 5e-3))
            return QString("%1, channel %2 (%3): fp16 relative L2 error %4")
                .arg(what).arg(c).arg(channelText(p.channels[c]).c_str()).arg(std::sqrt(diff[c] / norm[c]));
    return {};
}

// The sweep on one density grid: the given optics three channels per solve (R, G, B with intensities
// 1, 0.25, 3), every given sun, f_0 kept and zeroed (alternateF0: one of the two per solve, in turn),
// fp32 and (when fp16) fp16 compared with it (compareFp16 with fp16Error).
struct SweepResult {
    QString failure;      // empty when everything passed
    int solves = 0;
    double maxRatio = 0.0, maxFp16Error = 0.0;
};
inline SweepResult sweepGrid(const DensityGrid& d, const std::vector<lb::ChannelParams>& channels,
                             const std::vector<SunCase>& suns, bool fp16, double bound, bool alternateF0 = false,
                             double fp16Error = 5e-3)
{
    SweepResult r;
    int turn = 0;
    const glm::ivec3 n = d.geometry.dims;
    const QString grid = QString("%1x%2x%3").arg(n.x).arg(n.y).arg(n.z);
    for (size_t c0 = 0; c0 < channels.size(); c0 += 3)
        for (const SunCase& sun : suns) {
            const bool onlyZeroF0 = (turn++ & 1) == 0;   // with alternateF0: the one f_0 mode of this solve
            for (bool zeroF0 : {true, false}) {
                if (alternateF0 && zeroF0 != onlyZeroF0) continue;
                lb::LbParams p;
                for (size_t c = 0; c < 3; ++c) p.channels[c] = channels[std::min(c0 + c, channels.size() - 1)];
                p.sun = sun.sun;
                p.zeroF0 = zeroF0;
                p.intensity = {1.0f, 0.25f, 3.0f};
                const QString what = QString("%1 sun %2 %3").arg(grid).arg(sun.name.c_str()).arg(zeroF0 ? "zeroF0" : "keepF0");
                const LightingGrid a = lb::solveLighting(d, p);
                ++r.solves;
                r.failure = checkSolve(d, p, a, 1e-5, bound, what + " fp32", &r.maxRatio);
                if (!r.failure.isEmpty() || !fp16) {
                    if (!r.failure.isEmpty()) return r;
                    continue;
                }
                p.storage = lb::Storage::Fp16;
                const LightingGrid h = lb::solveLighting(d, p);
                ++r.solves;
                double ignored = 0.0;
                r.failure = checkSolve(d, p, h, 2e-3, bound, what + " fp16", &ignored);
                if (r.failure.isEmpty()) r.failure = compareFp16(p, a, h, fp16Error, what, &r.maxFp16Error);
                if (!r.failure.isEmpty()) return r;
            }
        }
    return r;
}

} // namespace sylva::lbx
