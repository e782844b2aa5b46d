// The control flow of an LB solve, written once (lb_control.cpp), over a small device interface: the CPU
// (lb_solver.cpp, oneTBB) and CUDA (cuda/lb_cuda.cu) supply the storage and the kernels.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "core/base/progress.h"
#include "core/grid/grid.h"
#include "core/lb/lb_params.h"
#include "core/lb/lb_solver.h"

namespace sylva::lb {

// The state of the channel solves advanced together on one grid (two copies of f per solve), held by a
// device. All solves of a grid take the same steps.
class LbGrid {
public:
    virtual ~LbGrid() = default;
    // Makes `solves` the grid's channel solves, each starting from the boundary condition (everywhere
    // with warmStart) and zero inside. With interiorFollows the caller writes the interior of the
    // current state next (prolongateFrom), so the device may leave it as it is.
    virtual void setSolves(const std::vector<ChannelParams>& solves, bool interiorFollows) = 0;
    // Advances every solve by `levels` steps. With compareLevel in [1, levels) it returns the relative
    // L2 change sqrt(sum (T_c - T_{c-1})^2 / sum T_c^2) of the node totals T_l after l of the steps
    // (l = compareLevel); else 0. Throws Cancelled when the progress given to makeGrid is cancelled.
    virtual double advanceBlock(int levels, int compareLevel) = 0;
    // The steps per block when LbParams::blockSteps is 0 (the CPU: the cache-sized wavefront depth).
    virtual int autoLevels() const = 0;
    // Starts every solve from the current state of `coarse`, a grid of the same device holding the same
    // solves on coarsen() of this grid: interior nodes interpolate it trilinearly at (i/2, j/2, k/2),
    // boundary nodes keep the boundary condition.
    virtual void prolongateFrom(const LbGrid& coarse) = 0;
    // Node totals sum_m f_m of the current state of solve s (unit intensity), z fastest.
    virtual void totals(size_t s, std::vector<float>& out) = 0;
};

// A device: where grids live and how much memory they may take.
class LbDevice {
public:
    virtual ~LbDevice() = default;
    // Throws Error naming the option when the device cannot run what `params` asks for.
    virtual void checkSupported(const LbParams& params) const { (void)params; }
    // Bytes free for the distributions (0: unknown, no limit checked) and what the message calls them.
    virtual double availableBytes() const = 0;
    virtual std::string memoryName() const = 0;
    // Throws the error a grid too large for the device's memory gets (message: one line).
    [[noreturn]] virtual void refuseMemory(const std::string& message) const;
    // A grid on `density` holding `solves` (as after setSolves(solves, false)); it checks `progress`
    // for cancel. Every grid a solve makes lives until the solve ends.
    virtual std::unique_ptr<LbGrid> makeGrid(const DensityGrid& density, const LbParams& params,
                                             const std::vector<ChannelParams>& solves, Progress* progress) = 0;
};

// The CPU device: oneTBB over rows, 8-wide collisions, wavefront blocks, fp32 or fp16 (F16C) storage.
std::unique_ptr<LbDevice> makeCpuDevice();

// The whole solve on `device`: validation, channels with equal optics grouped into one solve, solves
// per pass, coarse start, the step count or tolerance loop with its check period, progress, stats.
// solveLighting is this on the CPU device; the CUDA backend runs it on its own.
LightingGrid solveOnDevice(LbDevice& device, const DensityGrid& density, const LbParams& params, Progress* progress,
                           SolveStats* stats);

// Coarse start: a grid of half the resolution whose node I sits on fine node 2I (the last one may
// lie past the fine edge). Density is the full-weighting average of the fine nodes around 2I,
// doubled (a coarse step crosses two fine cells) and capped at 1; wood fraction is averaged.
DensityGrid coarsen(const DensityGrid& fine);

} // namespace sylva::lb
