// `sylva render --mpi`: one frame traced by the ranks of an MPI job (docs/DISTRIBUTED.md). Built only with
// MPI (SYLVA_ENABLE_MPI); nothing outside pipeline/mpi includes an MPI header.
//
// Rank 0 runs the render exactly as the single-process path does, except that its tracing goes
// through a FilmRowsTracer: when it starts, rank 0 hands the built frame's arrays to the other ranks
// (the ranks of a host share one copy in an MPI shared-memory window, which rank 0 fills on its host and
// the first rank of every other host receives by broadcast; the others wait for it. Or, with
// broadcastScene false, each rank builds its own frame from the species assets in the shared grid
// cache), then cuts the rows into tiles (mpi_tiles.h: 32 x 32, smaller when a
// frame has few per rank, quarters at the end of the queue) and hands them from a work queue to the
// ranks that ask, two ahead; rank 0 traces tiles too between its messages. A tile is renderFilmRect, shadePixel's parts per pixel, so the picture is bit-identical to a
// single-process CPU render at any rank count. Rank 0 gathers, composes and writes with the
// single-process writer.
//
// Faults: ranks send heartbeats while they work; rank 0 sends them to ranks that wait. A rank that
// stays silent longer than the timeout (or reports an error) ends the job: rank 0 names it on stderr
// and aborts the job (MPI_Abort, exit 1) before any picture is written. Ranks whose executables
// differ (version or build) are refused at start.
#pragma once

#include <functional>
#include <string>

#include "core/base/progress.h"
#include "core/render/render_scene.h"
#include "pipeline/render/render_job.h"

namespace sylva::mpi {

// Whether this process was started by an MPI launcher (mpirun, mpiexec, srun): its environment
// names the process's rank.
bool launchedByMpi();
// This process's rank as the launcher's environment gives it before MPI starts (0 when unknown).
int launchRank();

struct RenderJob {
    // The LB solves of the species the rank shares out (species s on rank s mod N) into the shared grid
    // cache, so that loading them afterwards is a cache hit everywhere; returns the number of LB solves it
    // ran (0 for species the cache held). When set, it runs only when rank 0's render misses in the cache
    // (through `lead`'s beforeCompute): rank 0 asks the others, runs its own and waits for theirs. (With
    // broadcastScene false the other ranks run it first, before their own preparation.)
    std::function<int(int rank, int ranks, Progress* progress)> lightShare;
    // Ranks other than 0: the frame's scene (prepareRenderScene), the same call as rank 0's.
    std::function<RenderScene(Progress* progress)> prepare;
    // Rank 0: the whole render and its output, with the tracing through `tracer`; `hosts`: the hosts the
    // ranks run on, each holding one copy of the frame (0 when every rank builds its own); beforeCompute
    // (set with lightShare): for GridCache::setBeforeCompute, the species' lighting shared out. Returns the
    // exit code; an exception is reported as "sylva render: error: ..." and ends the job with 1.
    std::function<int(const FilmRowsTracer& tracer, int ranks, int hosts, const std::function<void()>& beforeCompute)> lead;
    // Seconds a rank may stay silent before the job ends.
    double timeoutSeconds = 10.0;
    // Tile edge in pixels (halved down to 8 while the frame has fewer than 4 tiles per rank).
    int tile = 32;
    // How the other ranks get the frame's scene: rank 0 builds it once and hands its arrays out when it
    // starts tracing, one copy per host (true; `prepare` is not called), or every rank builds its own
    // through `prepare`.
    bool broadcastScene = true;
    // Threads per rank (--threads; 0: no limit). With broadcastScene, rank 0 builds the scene with the
    // threads of every rank on its node, which wait for the scene meanwhile, then traces with these.
    int threads = 0;
};

// Runs this rank's part: MPI_Init, the build check, then the work queue (rank 0) or a worker.
// Returns the process's exit code: 0, 1 (an error, reported on rank 0), or 128 + signal when the job
// was stopped by a signal (mpirun sends SIGTERM to every rank when one dies).
int runRender(const RenderJob& job);

} // namespace sylva::mpi
