// The distributed LB grid (`sylva light --mpi`, docs/DISTRIBUTED.md "The distributed LB grid"): one
// grid split into slabs along x over the ranks of an MPI job (core/lb/lb_slab.h), each rank holding its
// planes and one halo plane per side. Every step each rank posts its two edge planes to its neighbours
// and its halos' receives (MPI_Isend / MPI_Irecv), steps the planes that need no halo while the
// messages travel (testing them between planes, so the transfer progresses), waits, then steps the two
// planes next to the halos. Rank 0 gathers the node totals and returns the lighting grid; it is the
// single-process solve's to the bit (fp32 and fp16), at any rank count. Fixed step counts only.
//
// Waits are bounded: a neighbour that sends nothing for the timeout plus three times this rank's
// slowest step ends the job with a message naming it (MPI_Abort, exit 1), never a hang.
#pragma once

#include <cstddef>
#include <functional>

#include "core/base/progress.h"
#include "core/grid/grid.h"
#include "core/lb/lb_params.h"

namespace sylva::mpi {

struct DistributedStats {
    int ranks = 1;
    int steps = 0;               // per channel solve
    int solves = 0;              // distinct channel solves
    int ownedPlanes = 0;         // this rank's x-planes
    size_t planeBytes = 0;       // one halo message
    double seconds = 0.0;        // the whole solve on this rank (gather included)
    double interiorSeconds = 0.0;   // stepping the planes that need no halo, the messages in flight
    double waitSeconds = 0.0;       // waiting for the halos after that
    double edgeSeconds = 0.0;       // stepping the two planes next to the halos
    double gatherSeconds = 0.0;     // the totals to rank 0
};

// Every rank makes this call with the same arguments (the whole density grid on every rank) inside
// runLightSession's body. Rank 0 returns the lighting grid, the others an empty one. Throws Error
// for a tolerance or coarse-start solve, or a grid with fewer interior x-planes than ranks.
LightingGrid solveDistributed(const DensityGrid& density, const lb::LbParams& params, Progress* progress = nullptr,
                              DistributedStats* stats = nullptr);

// The session of `sylva light --mpi` (and the tests' and benchmark's): MPI started and the builds
// checked, then body(rank, ranks) on every rank. An Error on any rank ends the job with its message
// (exit 1), a signal from mpirun with 128 + 15. `timeoutSeconds` bounds the waits of solveDistributed.
int runLightSession(const std::function<int(int rank, int ranks)>& body, double timeoutSeconds = 10.0);

} // namespace sylva::mpi
