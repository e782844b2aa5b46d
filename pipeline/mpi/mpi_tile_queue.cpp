// Rank 0's work queue of tiles (mpi_tile_queue.h).
#include "pipeline/mpi/mpi_tile_queue.h"

#include <chrono>
#include <cstdio>
#include <cstring>
#include <string>

#include "core/base/error.h"
#include "pipeline/mpi/mpi_tiles.h"

namespace sylva::mpi {

Film TileQueue::trace(const RenderScene& rs, int y0, int y1, Progress* progress)
{
    // The scene goes out while this thread traces (the other ranks start on it when it has come);
    // trace returns only after it went, so `rs` outlives the broadcast (which ends the job itself
    // when it cannot finish within the timeout).
    {
        std::lock_guard<std::mutex> lock(m_mutex);
        if (!m_sceneSent) m_scene = &rs;
    }
    // The host's copy first, with every thread the build had (the host's other ranks wait for it), then
    // the tracing with this rank's own.
    if (m_pack) packForHost(rs, progress);
    if (m_beforeTrace) {
        m_beforeTrace();
        m_beforeTrace = nullptr;
    }
    struct AwaitSent {
        TileQueue* q;
        ~AwaitSent()
        {
            std::unique_lock<std::mutex> lock(q->m_mutex);
            while (!q->m_sceneSent) q->m_changed.wait_for(lock, std::chrono::milliseconds(100));
        }
    } awaitSent{this};
    const RenderView v = rs.view();
    if (y0 < 0 || y1 > v.height || y0 > y1) throw Error("render --mpi: rows outside the frame");
    Film film;
    film.width = v.width;
    film.height = y1 - y0;
    film.pixels.resize(size_t(film.width) * size_t(film.height));
    {
        std::lock_guard<std::mutex> lock(m_mutex);
        m_film = &film;
        m_y0 = y0;
        m_base = m_next;
        m_tiles.clear();
        for (const TileRect& t : frameTiles(film.width, y0, y1, m_ranks, m_edge)) m_tiles.push_back({m_next++, t.x0, t.y0, t.x1, t.y1});
        m_pending.assign(m_tiles.begin(), m_tiles.end());
        m_done = 0;
    }
    // However this ends, the workers' late tiles must not land in a film that is gone.
    struct Detach {
        TileQueue* q;
        ~Detach()
        {
            std::lock_guard<std::mutex> lock(q->m_mutex);
            q->m_film = nullptr;
            q->m_pending.clear();
        }
    } detach{this};
    const int total = int(m_tiles.size());
    std::vector<SampleParts> buf;
    int reported = -1;
    for (;;) {
        if (Progress::cancelAllRequested() || (progress && progress->isCancelled())) throw Cancelled();
        TileMsg t{};
        bool mine = false;
        int done = 0;
        {
            std::unique_lock<std::mutex> lock(m_mutex);
            if (!m_pending.empty()) {
                t = m_pending.front();
                m_pending.pop_front();
                mine = true;
            } else if (m_done < total) {
                m_changed.wait_for(lock, std::chrono::milliseconds(100));
            }
            done = m_done;
        }
        if (mine) {
            buf.resize(size_t(t.x1 - t.x0) * size_t(t.y1 - t.y0));
            renderFilmRect(v, t.x0, t.y0, t.x1, t.y1, buf.data());
            store(t.id, buf.data(), buf.size());
            done = doneCount();
        }
        if (progress && done != reported) {
            progress->report(total ? double(done) / double(total) : 1.0, "tracing");
            reported = done;
        }
        if (done == total) break;
    }
    if (y1 == v.height) {   // the frame's last rows (FilmRowsTracer): no tile is left for anyone
        std::lock_guard<std::mutex> lock(m_mutex);
        m_traced = true;
    }
    return film;
}

void TileQueue::store(int id, const SampleParts* parts, size_t count)
{
    {
        std::lock_guard<std::mutex> lock(m_mutex);
        if (!m_film) return;   // the band was abandoned (cancelled)
        if (id < m_base || id >= m_base + int(m_tiles.size()))
            throw Error(std::string("a rank sent back a tile that is not one of the frame's tiles now: ") + std::to_string(id));
        const TileMsg& t = m_tiles[size_t(id - m_base)];
        const size_t w = size_t(t.x1 - t.x0);
        if (count != w * size_t(t.y1 - t.y0)) {
            char msg[160];
            std::snprintf(msg, sizeof msg, "a rank sent back tile %d with %zu pixels, not %zu", id, count, w * size_t(t.y1 - t.y0));
            throw Error(msg);
        }
        for (int y = t.y0; y < t.y1; ++y)
            std::memcpy(&m_film->pixels[size_t(y - m_y0) * size_t(m_film->width) + size_t(t.x0)], parts + size_t(y - t.y0) * w,
                        w * sizeof(SampleParts));
        ++m_done;
    }
    m_changed.notify_all();
}

void TileQueue::packForHost(const RenderScene& rs, Progress* progress)
{
    std::unique_lock<std::mutex> lock(m_mutex);
    while (!m_block) {
        if (Progress::cancelAllRequested() || (progress && progress->isCancelled())) throw Cancelled();
        m_changed.wait_for(lock, std::chrono::milliseconds(20));
    }
    void* const block = m_block;
    const RenderSceneHeader header = m_header;
    const PackedFrame layout = m_layout;
    lock.unlock();
    packRenderScene(rs, header, layout, block);
    lock.lock();
    m_packed = true;
    m_pack = false;
}

} // namespace sylva::mpi
