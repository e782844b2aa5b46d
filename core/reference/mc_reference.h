// Monte Carlo reference for the LB lighting model: volumetric light transport on the same grid and optics.
#pragma once

#include <cstdint>
#include <vector>

#include "core/base/progress.h"
#include "core/grid/grid.h"
#include "core/lb/lb_params.h"

namespace sylva {

// The model the reference solves (docs/ACCURACY.md "The reference solver"), in node units (1 = node spacing):
// - Medium: node-centred cubic cells ([i-0.5, i+0.5] per axis, the voxelizer's cells), each homogeneous with
//   the node's density rho (nearest node). The domain is the union of all cells, [-0.5, N-0.5] per axis;
//   outside is vacuum and light that leaves is gone (the LB drops flow into boundary nodes).
// - Per channel: extinction sigma_t * rho per node spacing, scattering sigma_s * rho with continuous
//   Henyey-Greenstein g (g = -1 at brown nodes, wood fraction > brownThreshold; |g| = 1 is the delta limit).
// - sigma_a: zeroF0 (plants) -> absorbed light is removed (true absorption, as the LB's zeroed f_0);
//   keep f_0 (clouds, plastics) -> absorbed light is re-emitted isotropically, as the LB's f_0 row does
//   (Omega_i0 = w_i), so sigma_a acts as isotropic scattering. The LB's resting population f_0 itself is
//   not light in flight and has no counterpart here.
// - Output: fluence averaged over each node's cell (track-length estimator), per channel and node.
enum class Incidence {
    LatticeBeams,   // the LB boundary condition: a collimated beam along each lattice direction n_m with
                    // fluence I * max(0, n_m . d), d = -normalize(sun) (lb::boundaryDistribution)
    Collimated,     // the physical sun: one collimated beam along d with fluence I * sum_m max(0, n_m . d)
};

// 24 bytes.
struct ReferenceSettings {
    uint64_t paths = 1000000;   // paths per distinct channel solve (channels with equal optics share one)
    uint64_t seed = 1;          // path p of a solve uses a generator seeded by a hash of (seed, channel, p)
    int maxBounces = -1;        // scattering events per path; -1 unlimited, 0 uncollided light, 1 single scattering
    Incidence incidence = Incidence::LatticeBeams;
};

struct ReferenceResult {
    LightingGrid mean;                  // cell-averaged fluence per node and channel, on the LB's scale
                                        // (both are I * sum_m max(0, n_m . d) in unobstructed space)
    std::vector<float> standardError;   // standard error of each value of mean.rgb (same layout)
    uint64_t paths = 0;                 // paths per channel solve
    int channelSolves = 0;              // distinct channel solves run
    double collisionsPerPath = 0.0;     // real (non-null) collisions per path, mean over the solves
    double seconds = 0.0;
};

// Largest settings.paths accepted: the per-node fixed-point sums stay far from overflow below it.
inline constexpr uint64_t kMaxReferencePaths = 10'000'000'000ull;

// Traces settings.paths paths per distinct channel from the sun side, delta tracking (Woodcock) through
// the density, scoring track lengths per cell. Multithreaded (oneTBB); bit-identical for a given seed at
// any thread count. Uses params.channels, zeroF0, sun, intensity and brownThreshold (steps, tolerance and
// storage are the LB's own). Throws Error on invalid parameters, density or settings; Cancelled when
// progress is cancelled.
ReferenceResult solveReference(const DensityGrid& density, const lb::LbParams& params, const ReferenceSettings& settings,
                               Progress* progress = nullptr);

// ---- Comparable outputs (docs/ACCURACY.md "Normalization") ----

// The value of a channel in unobstructed space, the same for both solvers: I_c * sum_{m=1..18} max(0, n_m . d).
// The LB's boundary nodes hold exactly this total, and an empty grid converges to it everywhere; the
// reference's incident light has this fluence.
double unobstructedValue(const lb::LbParams& params, int channel);

// Divides every node's channel c (and its standard error, when given) by unobstructedValue(params, c),
// so that an empty grid gives 1 everywhere for both solvers. Channels of intensity 0 stay 0.
void normalizeToUnobstructed(LightingGrid& grid, const lb::LbParams& params, std::vector<float>* standardError = nullptr);

// ||a - b||_2 / ||b||_2 over the interior nodes (not on the lattice boundary) and all channels (or only
// `channel` when it is 0, 1 or 2); b is the reference. LB boundary nodes hold the prescribed incident
// light by definition, so they are left out.
double relativeL2Interior(const LightingGrid& a, const LightingGrid& b, int channel = -1);

// The reference's own noise on the same scale: sqrt(sum se^2 / sum ref^2) over the interior nodes. A
// relative L2 error near this value is indistinguishable from the reference's noise.
double relativeNoiseInterior(const LightingGrid& ref, const std::vector<float>& standardError);

} // namespace sylva
