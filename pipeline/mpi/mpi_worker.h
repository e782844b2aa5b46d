// The ranks other than 0 of `sylva render --mpi` (mpi_worker.cpp). Internal to pipeline/mpi: it includes the
// MPI header.
#pragma once

#include "pipeline/mpi/mpi_frame.h"
#include "pipeline/mpi/mpi_render.h"

namespace sylva::mpi {

// A worker: its share of the species' lighting (when asked), the frame's scene (received from rank 0, or
// built here with job.prepare), then the tiles rank 0 hands out until it says done. Returns 0; an error is
// reported to rank 0, which ends the job.
int runWorker(const RenderJob& job, int rank, int size, const Hosts& hosts);

} // namespace sylva::mpi
