// Rank 0's work queue of tiles for `sylva render --mpi` (mpi_tile_queue.cpp): the tiles of a band of rows, some
// traced by rank 0's render thread, the others handed to the workers by its main thread (mpi_lead.cpp). No
// MPI here.
#pragma once

#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <deque>
#include <functional>
#include <mutex>
#include <utility>
#include <vector>

#include "core/base/progress.h"
#include "core/render/render_cpu.h"
#include "core/render/render_scene.h"
#include "core/render/scene_bytes.h"

namespace sylva::mpi {

// A tile as it travels from rank 0 to a worker: its id in the queue and its pixels [x0, x1) x [y0, y1).
struct TileMsg {
    int32_t id, x0, y0, x1, y1;
};

// Shared by rank 0's two threads: the render thread publishes a band's tiles and traces some itself;
// the main thread hands the others to the workers and stores what they send back.
class TileQueue {
public:
    // sendScene: the other ranks wait for the frame's scene (rank 0's main thread sends it while the first
    // band is traced). packForHost: the ranks on rank 0's host trace from a copy this rank's render thread
    // packs into their shared window first. beforeTrace: called once, in the render thread, before the tracing.
    TileQueue(int ranks, int tileEdge, bool sendScene, bool packForHost, std::function<void()> beforeTrace)
        : m_ranks(ranks), m_edge(tileEdge), m_sceneSent(!sendScene || ranks < 2), m_pack(packForHost && !m_sceneSent),
          m_beforeTrace(std::move(beforeTrace))
    {
    }

    // Render thread: rows [y0, y1) of the scene's view as a film, every tile traced here or by a worker.
    Film trace(const RenderScene& rs, int y0, int y1, Progress* progress);

    // Main thread: the host's shared window for the frame (layout: the packed block's), for the render thread to fill.
    void setBlock(void* block, const RenderSceneHeader& header, const PackedFrame& layout)
    {
        {
            std::lock_guard<std::mutex> lock(m_mutex);
            m_block = block;
            m_header = header;
            m_layout = layout;
        }
        m_changed.notify_all();
    }
    // Main thread: the frame's last tile is in (its picture is being written).
    bool traced()
    {
        std::lock_guard<std::mutex> lock(m_mutex);
        return m_traced;
    }
    bool packed()
    {
        std::lock_guard<std::mutex> lock(m_mutex);
        return m_packed;
    }

    // Main thread: the scene to broadcast, once the render thread has it and until it is sent.
    const RenderScene* sceneToSend()
    {
        std::lock_guard<std::mutex> lock(m_mutex);
        return m_sceneSent ? nullptr : m_scene;
    }
    bool sceneSent()
    {
        std::lock_guard<std::mutex> lock(m_mutex);
        return m_sceneSent;
    }
    void markSceneSent()
    {
        {
            std::lock_guard<std::mutex> lock(m_mutex);
            m_sceneSent = true;
        }
        m_changed.notify_all();
    }

    // Main thread: the next tile for a worker; false when none waits.
    bool take(TileMsg* t)
    {
        std::lock_guard<std::mutex> lock(m_mutex);
        if (m_pending.empty()) return false;
        *t = m_pending.front();
        m_pending.pop_front();
        return true;
    }

    // A finished tile (either thread). Throws Error when the tile is unknown or its size is wrong.
    void store(int id, const SampleParts* parts, size_t count);

private:
    int doneCount()
    {
        std::lock_guard<std::mutex> lock(m_mutex);
        return m_done;
    }

    // Waits for the window (setBlock) and packs the scene into it.
    void packForHost(const RenderScene& rs, Progress* progress);

    const int m_ranks, m_edge;
    bool m_sceneSent;
    bool m_pack;
    void* m_block = nullptr;
    RenderSceneHeader m_header{};
    PackedFrame m_layout{};
    bool m_packed = false, m_traced = false;
    const RenderScene* m_scene = nullptr;
    std::function<void()> m_beforeTrace;
    std::mutex m_mutex;
    std::condition_variable m_changed;
    Film* m_film = nullptr;
    int m_y0 = 0, m_base = 0, m_next = 0, m_done = 0;
    std::vector<TileMsg> m_tiles;
    std::deque<TileMsg> m_pending;
};

} // namespace sylva::mpi
