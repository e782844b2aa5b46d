// One LB grid split into slabs along x for a solve spread over processes (`sylva light --mpi`,
// pipeline/mpi/mpi_lb.h; docs/DISTRIBUTED.md "The distributed LB grid"). No MPI here: the slab is
// the CPU solver's own node update on a part of the grid, the messages are the caller's.
//
// The grid's interior x-planes 1..X-2 are dealt out to the slabs in order (slabOwned). A slab's local
// grid is its planes plus one plane each side: the neighbour's edge plane (a halo), or the grid's x
// face. The solver never writes a local grid's x faces, so a halo is read by the step exactly as the
// whole grid's solve reads that plane, and the caller keeps it current: before each step it copies
// the neighbours' edge planes (local planes 1 and X-2 of their current state) into this slab's halos
// (planes 0 and X-1). Every node update is the whole grid's (same density, same neighbours, same
// order of operations per node), so the slabs' results equal the single solve's to the bit.
#pragma once

#include <memory>
#include <vector>

#include "core/base/progress.h"
#include "core/grid/grid.h"
#include "core/lb/lb_params.h"

namespace sylva::lb {

// The interior x-planes [begin, end) of a grid of X planes that slab `index` of `count` owns: X - 2
// planes in contiguous runs, the first (X - 2) mod count slabs one plane more. Throws Error when a
// slab would get none (count > X - 2).
struct SlabRange {
    int begin = 0, end = 0;
};
SlabRange slabOwned(int X, int index, int count);

// The local grid of a slab: planes [owned.begin - 1, owned.end + 1) of `density`, origin moved with them.
DensityGrid slabDensity(const DensityGrid& density, SlabRange owned);

// The state of one channel solve on a slab's local grid, advanced a step at a time in parts: the
// planes that need no halo first (while the halos travel), then the two next to them.
class LbSlab {
public:
    virtual ~LbSlab() = default;
    // Starts the solve `solve` (the parameters' boundary; warm start as the parameters say), reusing memory.
    virtual void setSolve(const ChannelParams& solve) = 0;
    // One step of source planes [x0, x1) of the local grid (0..planes()-1) into the next state. A step
    // is complete when every plane was stepped once; then finishStep makes the next state current.
    // Planes 2..X-3 of the next state depend on the current planes 1..X-2 alone; planes 1 and X-2 also
    // on the halos 0 and X-1, so stepping 1..X-2 needs no halo and 0, X-1 must wait for them.
    virtual void stepPlanes(int x0, int x1) = 0;
    virtual void finishStep() = 0;
    // Local plane x of the current state: planeBytes() bytes (Y x 19 x Z values in storage form,
    // docs/LB_MODEL.md's order), what a halo message carries.
    virtual void* plane(int x) = 0;
    virtual size_t planeBytes() const = 0;
    virtual int planes() const = 0;
    // Node totals sum_m f_m of the current state at unit intensity, the local grid's nodes (z fastest).
    virtual void totals(std::vector<float>& out) = 0;
};

// A slab on the CPU (the storage params.storage names). `local` is slabDensity's grid; params must be
// valid and in fixed-step mode (the step count is the caller's).
std::unique_ptr<LbSlab> makeCpuSlab(const DensityGrid& local, const LbParams& params, Progress* progress = nullptr);

// The distinct channel solves of `params` (channels with equal optics share one, the result being
// linear in the intensity) and, per channel, the index of its solve: what every solve of a grid runs.
std::vector<ChannelParams> distinctSolves(const LbParams& params, int (&solveOf)[3]);

} // namespace sylva::lb
