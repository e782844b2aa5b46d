// A process's place on its node in a parallel job, as the launcher's environment gives it: read without
// MPI, so code that never links MPI (the CUDA backend's device choice) and code that runs before
// MPI_Init can use it.
#pragma once

#include <cstdlib>

namespace sylva {

// The rank among the job's processes on this node: OMPI_COMM_WORLD_LOCAL_RANK (OpenMPI's mpirun),
// MPI_LOCALRANKID (MPICH, Intel MPI), SLURM_LOCALID (srun); -1 when the process was not started by
// one of them.
inline int launcherLocalRank()
{
    for (const char* name : {"OMPI_COMM_WORLD_LOCAL_RANK", "MPI_LOCALRANKID", "SLURM_LOCALID"}) {
        const char* v = std::getenv(name);
        if (!v || !*v) continue;
        char* end = nullptr;
        const long r = std::strtol(v, &end, 10);
        if (end && *end == '\0' && r >= 0 && r < 1 << 20) return int(r);
    }
    return -1;
}

} // namespace sylva
