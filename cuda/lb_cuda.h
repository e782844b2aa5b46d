// The LB lighting solve on the GPU (docs/LB_MODEL.md): the same per-node collision as the CPU, z-fastest layout.
#pragma once

#include "core/base/progress.h"
#include "core/grid/grid.h"
#include "core/lb/lb_params.h"
#include "core/lb/lb_solver.h"

namespace sylva::cuda {

// Solves all three channels on the current device with the CPU's control flow (lb::solveOnDevice):
// every LbParams option as on the CPU (channels with equal optics share one solve, solves per pass,
// coarse start, check period). A grid too large for the free device memory throws BackendError.
// Throws Error on bad input, BackendError on device trouble, Cancelled when cancelled.
LightingGrid solveLightingCuda(const DensityGrid& density, const lb::LbParams& params, Progress* progress,
                               lb::SolveStats* stats);

// Device-to-device copy bandwidth in bytes per second (bytes read + written), median of reps copies
// of `bytes`: the memory floor the LB kernel is compared against.
double deviceCopyBandwidth(size_t bytes, int reps);

} // namespace sylva::cuda
