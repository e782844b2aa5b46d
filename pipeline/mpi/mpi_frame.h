// The frame's scene, from rank 0 to the other ranks of `sylva render --mpi` (mpi_frame.cpp): what the other
// ranks need to trace the frame (RenderScene::view()) is the header of core/render/scene_bytes.h, then the
// arrays. The ranks of one host share one copy of them (SharedFrame); rank 0 broadcasts them to the first
// rank of every other host (Hosts::leaders). Internal to pipeline/mpi: it includes the MPI header.
#pragma once

#include <mpi.h>

#include <cstddef>
#include <cstdint>

#include "core/render/render_scene.h"
#include "core/render/scene_bytes.h"

namespace sylva::mpi {

using SceneHeader = RenderSceneHeader;

// Waits for req, calling MPI without a pause (a broadcast moves only while its ranks call MPI, and
// every rank waits for it); Error after `timeout` seconds.
void finish(MPI_Request& req, double timeout, const char* what);

// Broadcasts `bytes` bytes from rank 0 of `comm` in pieces MPI's int counts can hold.
void broadcastBytes(void* data, size_t bytes, double timeout, MPI_Comm comm);

// Rank 0's arrays to the first rank of every other host, array by array as forEachPackedArray receives them
// (MPI_Ibcast takes a non-const buffer; rank 0's is only read).
void broadcastArrays(const RenderScene& rs, const SceneHeader& h, double timeout, MPI_Comm leaders);

// The ranks of this rank's host and the first rank of every host. `node`: the ranks that share this host's
// memory (MPI_COMM_TYPE_SHARED), or with SYLVA_MPI_NODE_SIZE=N every N consecutive ranks (N = 1: a copy of the
// frame per rank; N > 1 tries the several-host path on one machine). `leaders`: node rank 0 of every host
// (MPI_COMM_NULL on the others), rank 0 first.
struct Hosts {
    MPI_Comm node = MPI_COMM_NULL, leaders = MPI_COMM_NULL;
    int nodeRank = 0, nodeSize = 1, leaderCount = 1;

    // Collective over MPI_COMM_WORLD.
    void split(int rank, double timeout);
    ~Hosts();
};

// A host's copy of the frame's arrays (scene_bytes.h's packed block): an MPI shared-memory window that the
// host's first rank allocates and every rank of the host maps, so a host holds the frame once whatever its
// rank count (the second rank of a 2-core machine used to spend 0.2-0.6 s making room for its own copy).
class SharedFrame {
public:
    SharedFrame() = default;
    SharedFrame(const SharedFrame&) = delete;
    SharedFrame& operator=(const SharedFrame&) = delete;
    ~SharedFrame() = default;   // a job that ends early exits without the collective release

    // Collective over hosts.node. Throws Error when the host's shared memory (/dev/shm, where OpenMPI keeps
    // the window) has no room for `bytes`.
    void allocate(const Hosts& hosts, uint64_t bytes, double timeout);

    void* block() const { return m_block; }
    void sync() const;

    // Collective over the host's ranks (each calls it when its tracing is done).
    void release(double timeout);

private:
    static void checkRoom(uint64_t bytes, int ranks);

    static constexpr uint64_t kBlockAlign = 64;   // packedFrameLayout's boundary
    MPI_Comm m_node = MPI_COMM_NULL;
    MPI_Win m_win = MPI_WIN_NULL;
    void* m_block = nullptr;   // the window's segment, rounded up to kBlockAlign
};

} // namespace sylva::mpi
