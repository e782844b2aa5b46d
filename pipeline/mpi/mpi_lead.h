// Rank 0 of `sylva render --mpi` (mpi_lead.cpp). Internal to pipeline/mpi: it includes the MPI header.
#pragma once

#include <string>
#include <vector>

#include "pipeline/mpi/mpi_frame.h"
#include "pipeline/mpi/mpi_render.h"

namespace sylva::mpi {

// Rank 0's main thread: runs the lead's render in a thread and serves the workers until it is done.
// localRanks: the ranks on this host (they share its cores); hosts: each rank's host; topology: the split
// into hosts (Hosts::split, when the frame is broadcast). Returns the render's exit code.
int runLead(const RenderJob& job, int size, int localRanks, const std::vector<std::string>& hosts, const Hosts& topology);

} // namespace sylva::mpi
