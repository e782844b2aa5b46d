// The LB lighting solve on the CPU: density grid in, RGB lighting grid out (docs/LB_MODEL.md is the contract).
#pragma once

#include <vector>

#include "core/base/progress.h"
#include "core/grid/grid.h"
#include "core/lb/lb_params.h"

namespace sylva::lb {

struct SolveStats {
    int steps = 0;                  // steps taken (per channel)
    bool converged = false;         // tolerance mode: the change fell under the tolerance
    double lastChange = 0.0;        // last measured relative L2 change per step
    int channelSolves = 0;          // distinct channel solves (channels with equal optics share one)
    double seconds = 0.0;
    int blockSteps = 0;             // steps per wavefront block
    int coarseSteps = 0;            // coarse start: steps taken on the coarser grids (each 1/8 the work of the next)
    double bytesPerStep = 0.0;      // f bytes read + written per step, all solved channels
    std::vector<std::pair<int, double>> changeHistory;   // (step, relative change) at each check
};

// Solves the lighting for all three channels. Throws Error on invalid parameters or density,
// Cancelled when progress is cancelled.
LightingGrid solveLighting(const DensityGrid& density, const LbParams& params, Progress* progress = nullptr,
                           SolveStats* stats = nullptr);

// Advances an explicit state of channel 0 (19 values per node in the storage order of docs/LB_MODEL.md:
// ((i*Y + j)*19 + m)*Z + k) by `steps` steps with the same code as solveLighting. Boundary nodes keep
// their values. For tests and tools.
void advance(const DensityGrid& density, const LbParams& params, std::vector<float>& f, int steps);

// Boundary value f_m = max(0, n_m . d) for unit intensity, d = -normalize(sun) (docs/LB_MODEL.md "Boundary
// condition").
std::vector<float> boundaryDistribution(const glm::vec3& sun);
// The sun as a beam rather than the model's cosine lobe: its travel direction -normalize(sun) as a
// non-negative sum of the three lattice directions (unit vectors) of the tightest cone holding it (fewer
// where it lies on a cone's face or edge), weights summing to 1. For pure transport without scattering (the
// landscape's lattice, forest_grid.h), where the lobe's directions far from the sun would cast shadows the
// sun does not. Zero sun: all 0.
std::vector<float> beamDistribution(const glm::vec3& sun);
// The boundary a solve with these parameters uses, for unit intensity: params.boundary, or the sun's.
std::vector<float> boundaryOf(const LbParams& params);

} // namespace sylva::lb
