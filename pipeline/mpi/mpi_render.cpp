// sylva render --mpi (mpi_render.h): the session (mpi_session.cpp) whose rank 0 leads (mpi_lead.cpp) and whose
// other ranks work (mpi_worker.cpp); the frame's scene travels through mpi_frame.cpp, the tiles through
// rank 0's queue (mpi_tile_queue.cpp).
#include "pipeline/mpi/mpi_render.h"

#include <algorithm>
#include <string>
#include <vector>

#include "pipeline/mpi/mpi_frame.h"
#include "pipeline/mpi/mpi_lead.h"
#include "pipeline/mpi/mpi_session.h"
#include "pipeline/mpi/mpi_worker.h"

namespace sylva::mpi {

int runRender(const RenderJob& job)
{
    return runSession("render", "no picture was written", [&](int rank, int size, const std::vector<std::string>& hosts) {
        // The ranks on rank 0's host (they share its cores).
        const int leadNode = int(std::count(hosts.begin(), hosts.end(), hosts.front()));
        Hosts topology;
        if (job.broadcastScene && size > 1) topology.split(rank, 2.0 * job.timeoutSeconds + 5.0);
        return rank == 0 ? runLead(job, size, leadNode, hosts, topology) : runWorker(job, rank, size, topology);
    }, job.timeoutSeconds);
}

} // namespace sylva::mpi
