// The frame's scene from rank 0 to the other ranks (mpi_frame.h): the broadcast in pieces, the split of the
// ranks into hosts, a host's shared window.
#include "pipeline/mpi/mpi_frame.h"

#include <sys/statvfs.h>

#include <algorithm>
#include <cstdio>

#include "core/base/error.h"
#include "pipeline/mpi/mpi_common.h"

namespace sylva::mpi {

void finish(MPI_Request& req, double timeout, const char* what)
{
    const Clock::time_point t0 = Clock::now();
    for (;;) {
        int flag = 0;
        check(MPI_Test(&req, &flag, MPI_STATUS_IGNORE), "Test");
        if (flag) return;
        if (since(t0) > timeout) {
            char msg[200];
            std::snprintf(msg, sizeof msg, "%s did not finish within %.0f s (a rank hung, died or lost its connection)", what, timeout);
            throw Error(msg);
        }
    }
}

void broadcastBytes(void* data, size_t bytes, double timeout, MPI_Comm comm)
{
    constexpr size_t kPiece = size_t(1) << 28;
    char* p = static_cast<char*>(data);
    for (size_t done = 0; done < bytes; done += kPiece) {
        MPI_Request req;
        check(MPI_Ibcast(p + done, int(std::min(kPiece, bytes - done)), MPI_BYTE, 0, comm, &req), "Ibcast");
        finish(req, timeout, "the broadcast of the frame's scene");
    }
}

void broadcastArrays(const RenderScene& rs, const SceneHeader& h, double timeout, MPI_Comm leaders)
{
    forEachHeaderArray(rs, h, [&](const void* data, size_t bytes) { broadcastBytes(const_cast<void*>(data), bytes, timeout, leaders); });
}

void Hosts::split(int rank, double timeout)
{
    const Deadline deadline(timeout, jobError("--mpi: the ranks did not all reach the split into hosts within the timeout (a rank hung or died)"));
    const int per = envInt("SYLVA_MPI_NODE_SIZE", 0);
    if (per > 0) check(MPI_Comm_split(MPI_COMM_WORLD, rank / per, rank, &node), "Comm_split");
    else check(MPI_Comm_split_type(MPI_COMM_WORLD, MPI_COMM_TYPE_SHARED, rank, MPI_INFO_NULL, &node), "Comm_split_type");
    MPI_Comm_rank(node, &nodeRank);
    MPI_Comm_size(node, &nodeSize);
    check(MPI_Comm_split(MPI_COMM_WORLD, nodeRank == 0 ? 0 : MPI_UNDEFINED, rank, &leaders), "Comm_split");
    if (leaders != MPI_COMM_NULL) MPI_Comm_size(leaders, &leaderCount);
}

Hosts::~Hosts()
{
    if (leaders != MPI_COMM_NULL) MPI_Comm_free(&leaders);
    if (node != MPI_COMM_NULL) MPI_Comm_free(&node);
}

void SharedFrame::allocate(const Hosts& hosts, uint64_t bytes, double timeout)
{
    if (hosts.nodeRank == 0) checkRoom(bytes, hosts.nodeSize);
    const Deadline deadline(timeout, jobError("--mpi: the ranks of a host did not all make room for the frame within the timeout (a rank hung or died)"));
    m_node = hosts.node;
    void* mine = nullptr;
    // 64 bytes more than the frame: OpenMPI's segment starts 8 bytes into a page, and the packed arrays want
    // their 64-byte boundaries (types such as TilePlant are over-aligned). The segment's offset within a page
    // is the same on every rank, so each rounds its mapping's address up to the same place.
    check(MPI_Win_allocate_shared(MPI_Aint(hosts.nodeRank == 0 ? bytes + kBlockAlign : 0), 1, MPI_INFO_NULL, m_node, &mine, &m_win),
          "Win_allocate_shared");
    MPI_Aint size = 0;
    int unit = 0;
    void* base = nullptr;
    check(MPI_Win_shared_query(m_win, 0, &size, &unit, &base), "Win_shared_query");
    m_block = reinterpret_cast<void*>((reinterpret_cast<uintptr_t>(base) + kBlockAlign - 1) & ~uintptr_t(kBlockAlign - 1));
    // One passive epoch for the frame's life: MPI_Win_sync orders the writes before the host's barrier.
    check(MPI_Win_lock_all(MPI_MODE_NOCHECK, m_win), "Win_lock_all");
}

void SharedFrame::sync() const { check(MPI_Win_sync(m_win), "Win_sync"); }

void SharedFrame::release(double timeout)
{
    if (m_win == MPI_WIN_NULL) return;
    const Deadline deadline(timeout, jobError("--mpi: the ranks of a host did not all finish with the frame within the timeout (a rank hung or died)"));
    MPI_Win_unlock_all(m_win);
    MPI_Win_free(&m_win);
    m_block = nullptr;
}

void SharedFrame::checkRoom(uint64_t bytes, int ranks)
{
    struct statvfs fs {};
    if (statvfs("/dev/shm", &fs) != 0) return;   // no /dev/shm: OpenMPI keeps the window elsewhere
    const uint64_t room = uint64_t(fs.f_bavail) * uint64_t(fs.f_frsize);
    if (room >= bytes) return;
    char msg[400];
    std::snprintf(msg, sizeof msg,
                  "--mpi: the frame's %.0f MB do not fit in this host's shared memory (/dev/shm has %.0f MB free) that its %d ranks "
                  "would share; give it more (docker: --shm-size) or set SYLVA_MPI_NODE_SIZE=1 (a copy of the frame per rank)",
                  double(bytes) / 1e6, double(room) / 1e6, ranks);
    throw Error(msg);
}

} // namespace sylva::mpi
