// Boundary weights (sun, sky) and relighting from basis solves (lb_basis.h).
#include "core/lb/lb_basis.h"

#include <algorithm>
#include <cmath>
#include <string>

#include <tbb/parallel_for.h>

#include "core/base/error.h"
#include "core/lb/lb_solver.h"
#include "core/sky/sky_light.h"

namespace sylva::lb {

BoundaryWeights& BoundaryWeights::operator+=(const BoundaryWeights& o)
{
    for (int c = 0; c < 3; ++c)
        for (int m = 0; m < kDirections; ++m) w[size_t(c)][size_t(m)] += o.w[size_t(c)][size_t(m)];
    return *this;
}

glm::vec3 BoundaryWeights::totals() const
{
    glm::vec3 t(0.0f);
    for (int c = 0; c < 3; ++c)
        for (int m = 0; m < kDirections; ++m) t[c] += w[size_t(c)][size_t(m)];
    return t;
}

BoundaryWeights sunWeights(const glm::vec3& sun, const glm::vec3& intensity)
{
    const std::vector<float> bc = boundaryDistribution(sun);
    BoundaryWeights b;
    for (int c = 0; c < 3; ++c)
        for (int m = 1; m < kDirections; ++m) b.w[size_t(c)][size_t(m)] = intensity[c] * bc[size_t(m)];
    return b;
}

BoundaryWeights skyWeights(const sky::Sky& sky, const glm::vec3& unit, int width)
{
    // Light arriving from sky direction w travels along -w: it goes to the lattice direction nearest -w,
    // i.e. the sky share nearest to -n_m. Only the upper hemisphere is sky; below the horizon is the ground
    // (not a light source here).
    std::vector<glm::vec3> against;
    for (int m = 1; m < kDirections; ++m) against.push_back(-glm::vec3(float(kC[m][0]), float(kC[m][1]), float(kC[m][2])));
    const std::vector<glm::dvec3> share = sky::skyDirectionShares(sky, against, width, true);
    BoundaryWeights b;
    for (int c = 0; c < 3; ++c)
        for (int m = 1; m < kDirections; ++m)
            b.w[size_t(c)][size_t(m)] = unit[c] > 0.0f ? float(share[size_t(m - 1)][c] / double(unit[c])) : 0.0f;
    return b;
}

std::vector<WeightedSolve> weightedSolves(const LbParams& params, const BoundaryWeights& w)
{
    // Each channel's distribution scaled to a largest value of 1, and that scale.
    std::array<std::vector<float>, 3> dist;
    glm::vec3 scale(0.0f);
    for (int c = 0; c < 3; ++c) {
        for (int m = 1; m < kDirections; ++m) {
            const float v = w.w[size_t(c)][size_t(m)];
            if (!std::isfinite(v) || v < 0.0f) throw Error("LB boundary: a weight is negative or not finite");
            scale[c] = std::max(scale[c], v);
        }
        dist[size_t(c)].assign(kDirections, 0.0f);
        if (scale[c] > 0.0f)
            for (int m = 1; m < kDirections; ++m) dist[size_t(c)][size_t(m)] = w.w[size_t(c)][size_t(m)] / scale[c];
    }
    std::vector<int> lit;
    for (int c = 0; c < 3; ++c)
        if (scale[c] > 0.0f) lit.push_back(c);
    if (lit.empty()) return {};
    bool same = true;   // every lit channel the same distribution (to float rounding)
    for (int c : lit)
        for (int m = 1; m < kDirections; ++m)
            same = same && std::fabs(dist[size_t(c)][size_t(m)] - dist[size_t(lit[0])][size_t(m)]) <= 1e-6f;
    std::vector<WeightedSolve> out;
    if (same) {
        WeightedSolve s{params, {}};
        s.params.boundary = dist[size_t(lit[0])];
        s.params.intensity = scale;
        for (int c : lit) s.channels[size_t(c)] = true;
        out.push_back(std::move(s));
        return out;
    }
    for (int c : lit) {
        WeightedSolve s{params, {}};
        s.params.channels = {params.channels[size_t(c)], params.channels[size_t(c)], params.channels[size_t(c)]};
        s.params.boundary = dist[size_t(c)];
        s.params.intensity = glm::vec3(scale[c]);
        s.channels[size_t(c)] = true;
        out.push_back(std::move(s));
    }
    return out;
}

std::vector<int> basisDirections(BasisSet set)
{
    std::vector<int> d;
    for (int m = 1; m < kDirections; ++m)
        if (set == BasisSet::All || kC[m][1] < 1 || kC[m][0] != 0 || kC[m][2] != 0) d.push_back(m);
    return d;
}

int sunBoundaryRank(bool upperOnly, int count)
{
    // Suns on a Fibonacci sphere (or hemisphere); Gram-Schmidt in double with a relative threshold.
    std::vector<std::array<double, 18>> basis;
    const double golden = 3.14159265358979323846 * (3.0 - std::sqrt(5.0));
    for (int i = 0; i < count; ++i) {
        const double y = upperOnly ? 1.0 - (double(i) + 0.5) / double(count) : 1.0 - 2.0 * (double(i) + 0.5) / double(count);
        const double r = std::sqrt(std::max(0.0, 1.0 - y * y)), phi = golden * double(i);
        const std::vector<float> bc = boundaryDistribution(glm::vec3(float(r * std::cos(phi)), float(y), float(r * std::sin(phi))));
        std::array<double, 18> v{};
        double norm0 = 0.0;
        for (int m = 0; m < 18; ++m) norm0 += (v[size_t(m)] = double(bc[size_t(m) + 1])) * v[size_t(m)];
        for (int pass = 0; pass < 2; ++pass)
            for (const auto& b : basis) {
                double dot = 0.0;
                for (int m = 0; m < 18; ++m) dot += v[size_t(m)] * b[size_t(m)];
                for (int m = 0; m < 18; ++m) v[size_t(m)] -= dot * b[size_t(m)];
            }
        double norm = 0.0;
        for (double x : v) norm += x * x;
        if (norm > 1e-16 * norm0 && norm > 1e-20) {
            for (double& x : v) x /= std::sqrt(norm);
            basis.push_back(v);
        }
    }
    return int(basis.size());
}

LbParams basisParams(const LbParams& params, int m)
{
    if (m < 1 || m >= kDirections) throw Error("LB basis: direction " + std::to_string(m) + " is not a moving lattice direction");
    if (params.tolerance > 0.0)
        throw Error("LB basis: a tolerance solve is not linear in the boundary (its step count depends on it); use fixed steps");
    LbParams p = params;
    p.boundary.assign(kDirections, 0.0f);
    p.boundary[size_t(m)] = 1.0f;
    p.intensity = glm::vec3(1.0f);
    return p;
}

LightingGrid composeLighting(const std::vector<int>& dirs, const std::vector<const LightingGrid*>& basis, const BoundaryWeights& w)
{
    if (dirs.size() != basis.size() || basis.empty()) throw Error("LB basis: as many grids as directions are needed");
    for (int m = 1; m < kDirections; ++m) {
        const bool have = std::find(dirs.begin(), dirs.end(), m) != dirs.end();
        for (int c = 0; c < 3; ++c)
            if (!have && w.w[size_t(c)][size_t(m)] != 0.0f)
                throw Error("LB basis: the boundary lights lattice direction " + std::to_string(m) + ", which the basis does not hold");
    }
    const GridGeometry& g = basis[0]->geometry;
    for (const LightingGrid* b : basis)
        if (b->geometry.dims != g.dims || b->rgb.size() != g.nodeCount() * 3) throw Error("LB basis: the grids differ in size");
    // Per channel the non-zero terms only (a sun lights about half the directions).
    std::array<std::vector<std::pair<const float*, float>>, 3> terms;
    for (size_t k = 0; k < dirs.size(); ++k)
        for (int c = 0; c < 3; ++c) {
            const float wk = w.w[size_t(c)][size_t(dirs[k])];
            if (wk != 0.0f) terms[size_t(c)].emplace_back(basis[k]->rgb.data(), wk);
        }
    LightingGrid out;
    out.geometry = g;
    out.rgb.assign(g.nodeCount() * 3, 0.0f);
    const size_t n = out.rgb.size();
    constexpr size_t kChunk = 3 * 4096;
    tbb::parallel_for(size_t(0), (n + kChunk - 1) / kChunk, [&](size_t chunk) {
        const size_t b0 = chunk * kChunk, b1 = std::min(n, b0 + kChunk);
        float* o = out.rgb.data();
        for (int c = 0; c < 3; ++c)
            for (const auto& [src, wk] : terms[size_t(c)])
                for (size_t i = b0 + size_t(c); i < b1; i += 3) o[i] += wk * src[i];
    });
    return out;
}

LbParams uncollidedParams(const LbParams& params)
{
    LbParams p = params;
    for (ChannelParams& c : p.channels) c = ChannelParams{c.sigmaA + c.sigmaS, 0.0f, 0.0f};
    p.zeroF0 = true;   // what is absorbed or scattered leaves the uncollided field
    return p;
}

LightingGrid scatteredPart(const LightingGrid& full, const LightingGrid& uncollided)
{
    if (full.geometry.dims != uncollided.geometry.dims || full.rgb.size() != uncollided.rgb.size())
        throw Error("LB scattered part: the two grids differ in size");
    LightingGrid out = full;
    for (size_t i = 0; i < out.rgb.size(); ++i) out.rgb[i] = std::max(0.0f, full.rgb[i] - uncollided.rgb[i]);
    return out;
}

} // namespace sylva::lb
