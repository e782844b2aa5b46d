// Boundary distributions per lattice direction and relighting by linearity: the LB update is linear in
// the boundary values, so the lighting for any boundary (a sun, a sky, their sum) is the weighted sum of
// the solves for the unit boundaries e_m, one per lattice direction m (the "basis").
#pragma once

#include <array>
#include <vector>

#include <glm/glm.hpp>

#include "core/grid/grid.h"
#include "core/lb/lattice.h"
#include "core/lb/lb_params.h"

namespace sylva::sky {
struct Sky;
}

namespace sylva::lb {

// A boundary condition as weights per channel and lattice direction: boundary node value f_m of channel
// c = w[c][m] (m = 0..18; w[c][0] = 0). The sun of docs/LB_MODEL.md is sunWeights; a sky adds skyWeights.
struct BoundaryWeights {
    std::array<std::array<float, kDirections>, 3> w{};
    BoundaryWeights& operator+=(const BoundaryWeights& o);
    // The free-field total sum_m w[c][m] per channel (what the grid holds in unobstructed space).
    glm::vec3 totals() const;
};

// The papers' sun (docs/LB_MODEL.md "Boundary condition"): w[c][m] = intensity_c x max(0, n_m . d), d =
// -normalize(sun).
BoundaryWeights sunWeights(const glm::vec3& sun, const glm::vec3& intensity);
// The sky (without its sun): each direction m gets the sky's radiance integrated over its
// share of the sphere, the directions w whose light travels nearest to n_m (w nearest -n_m), divided
// per channel by `unit` (the renderer scales the grid by the sun's radiance, so a sky boundary beside
// a sun of intensity 1 is given in units of the sun's radiance; a channel with unit 0 gets 0). Shares
// are computed on skyToMap(sky, width) (core/sky/sky_light.h).
BoundaryWeights skyWeights(const sky::Sky& sky, const glm::vec3& unit, int width = 256);

// A boundary given per channel as solves whose boundary is one distribution (LbParams::boundary) x an
// intensity per channel, what the solvers take: weights that are one distribution x a factor per channel
// (to 1e-6 of the largest) make one solve of every channel; any other (the sun plus a coloured sky) one
// solve per channel, its optics in all three (one channel solve each, as many as the channels' own). A
// channel whose weights are all 0 is in no solve (its light is 0). Throws Error on a negative or
// non-finite weight. Used by pipeline/lighting_job.h lightingForWeights and the reference comparisons.
struct WeightedSolve {
    LbParams params;
    std::array<bool, 3> channels{};   // which channels of the result this solve gives
};
std::vector<WeightedSolve> weightedSolves(const LbParams& params, const BoundaryWeights& w);

// Which lattice directions a basis holds: every moving direction (18), or those a sun above the
// horizon (direction toward it with y > 0) can light (17: +y never is).
enum class BasisSet { All, UpperSun };
std::vector<int> basisDirections(BasisSet set);
// The numerical rank of the boundary vectors of `count` suns spread over the sphere (upper: the upper
// hemisphere) in R^18: how many basis solves a basis for every sun needs at least.
int sunBoundaryRank(bool upperOnly, int count = 2000);

// The parameters of basis solve m: params with boundary e_m and unit intensity. Throws Error in
// tolerance mode (the step count would depend on the boundary: the sum would not be a solve).
LbParams basisParams(const LbParams& params, int m);

// The lighting for weights w from basis solves: out_c(n) = sum_k w[c][dirs[k]] basis[k]_c(n). Throws
// Error when a direction with a non-zero weight has no basis grid, or the grids' geometries differ.
LightingGrid composeLighting(const std::vector<int>& dirs, const std::vector<const LightingGrid*>& basis,
                             const BoundaryWeights& w);

// The LB field with the first collision separated: the light that reached each node
// without scattering, as the same LB solve with sigma_s = 0, sigma_a = sigma_t and f_0 zeroed (the
// streamed boundary attenuated by (1 - rho sigma_t) per step along each lattice direction: a
// discrete Beer-Lambert along the sun). Scattered light = the full solve minus this.
LbParams uncollidedParams(const LbParams& params);
// full - uncollided per node and channel, clamped at 0 (rounding); the geometries must match.
LightingGrid scatteredPart(const LightingGrid& full, const LightingGrid& uncollided);

} // namespace sylva::lb
