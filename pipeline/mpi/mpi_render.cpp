// sylva render --mpi: the build check, rank 0's work queue of tiles and its watch over the ranks, the workers.
//
// Threads: every MPI call is made by the process's main thread (MPI_THREAD_FUNNELED). The long work
// (loading the scene, rank 0's render, a worker's tile) runs in a second thread while the main thread
// sends and receives heartbeats, so a rank busy for minutes is still heard from twice a second.
#include "pipeline/mpi/mpi_render.h"

#include <mpi.h>
#include <sys/statvfs.h>
#include <unistd.h>
#include <xxhash.h>

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <algorithm>
#include <cstring>
#include <deque>
#include <fstream>
#include <future>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <type_traits>
#include <vector>

#include <tbb/global_control.h>

#include "core/base/error.h"
#include "core/base/version.h"
#include "core/render/render_cpu.h"
#include "core/render/scene_bytes.h"
#include "pipeline/mpi/mpi_session.h"
#include "pipeline/mpi/mpi_tiles.h"

namespace sylva::mpi {
namespace {

using Clock = std::chrono::steady_clock;

// Message tags. Workers send kHeartbeat, kRequest (the tile they finished, if any, and a request for
// the next), kFailed (an error text), kLit (its species' lighting is done) and kReady (it holds the
// memory for the scene's arrays); rank 0 sends kTile, kDone, kHeartbeat (to waiting ranks) and kShare (light
// your share of the species: rank 0's render missed in the cache).
enum Tag : int { kFailed = 11, kHeartbeat = 12, kRequest = 13, kTile = 14, kDone = 15, kLit = 16, kReady = 17, kShare = 18 };

constexpr double kHeartbeatSeconds = 0.5;

// Tiles a worker asks for ahead: it traces one while the result of the last one travels and the
// answer to its next request comes back, so its render thread never waits on a round trip (one
// ahead left a worker idle about half of a frame: 2.5-4 ms a tile measured, against 3-4 ms of
// tracing, on the 2-core VM whose cores both trace).
constexpr int kAhead = 2;

// The pause between two looks for messages of rank 0's main thread and of a worker's while it traces
// (a worker's finished tile wakes it at once). With kAhead tiles asked for, an answer may take this
// long; looking every 200 us instead made the frame no faster (medians of 4 interleaved runs: 0.75 s
// against 0.66 s), its wake-ups taking time from the two tracing threads on the 2-core VM.
constexpr auto kPollPause = std::chrono::milliseconds(1);

double since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

void check(int rc, const char* what)
{
    if (rc == MPI_SUCCESS) return;
    char text[MPI_MAX_ERROR_STRING];
    int n = 0;
    MPI_Error_string(rc, text, &n);
    throw Error(std::string("MPI ") + what + " failed: " + std::string(text, size_t(n)));
}

// "rank N" (built without string concatenation, which GCC 12 warns about falsely).
std::string rankName(int r)
{
    char t[32];
    std::snprintf(t, sizeof t, "rank %d", r);
    return t;
}

std::string hostName()
{
    char h[256] = {};
    if (gethostname(h, sizeof h - 1) != 0) return "?";
    return h;
}

// The command of this process's job ("render", "light") and what a failed job did not write.
const char* g_command = "render";
const char* g_notWritten = "no picture was written";

// Reports an error on this rank's stderr and ends the whole job (every rank, exit 1).
[[noreturn]] void abortJob(const std::string& message)
{
    std::fprintf(stderr, "sylva %s: error: %s; %s\n", g_command, message.c_str(), g_notWritten);
    std::fflush(stderr);
    MPI_Abort(MPI_COMM_WORLD, 1);
    std::_Exit(1);
}

// Ends this process (exit 1, `message` on stderr) unless disarmed within `seconds`: bounds MPI's blocking
// calls (the start, collectives over the ranks of a host), which a rank that died or hung before reaching
// them would hold forever. mpirun then stops the other ranks.
class Deadline {
public:
    Deadline(double seconds, std::string message)
        : m_thread([this, seconds, message = std::move(message)] {
              std::unique_lock<std::mutex> lock(m_mutex);
              if (m_cv.wait_for(lock, std::chrono::duration<double>(seconds), [&] { return m_disarmed; })) return;
              std::fprintf(stderr, "%s\n", message.c_str());
              std::fflush(stderr);
              std::_Exit(1);
          })
    {
    }
    Deadline(const Deadline&) = delete;
    Deadline& operator=(const Deadline&) = delete;
    ~Deadline() { disarm(); }

    void disarm()
    {
        if (!m_thread.joinable()) return;
        {
            std::lock_guard<std::mutex> lock(m_mutex);
            m_disarmed = true;
        }
        m_cv.notify_all();
        m_thread.join();
    }

private:
    std::mutex m_mutex;
    std::condition_variable m_cv;
    bool m_disarmed = false;
    std::thread m_thread;   // last: it starts once the members above exist
};

// "sylva render: error: ...; no picture was written" for a Deadline's message.
std::string jobError(const std::string& what) { return std::string("sylva ") + g_command + ": error: " + what + "; " + g_notWritten; }

int envInt(const char* name, int fallback)
{
    const char* v = std::getenv(name);
    return v && *v ? std::atoi(v) : fallback;
}

// ---- the build check ----

// XXH3-64 of this process's executable: ranks run the same build only when their files are equal
// (a -march=native build of another machine may round differently, and the picture must not).
uint64_t executableHash()
{
    std::ifstream in("/proc/self/exe", std::ios::binary);
    if (!in) return 0;
    XXH3_state_t* state = XXH3_createState();
    XXH3_64bits_reset(state);
    std::vector<char> buf(1 << 20);
    while (in) {
        in.read(buf.data(), std::streamsize(buf.size()));
        if (in.gcount() > 0) XXH3_64bits_update(state, buf.data(), size_t(in.gcount()));
    }
    const uint64_t h = XXH3_64bits_digest(state);
    XXH3_freeState(state);
    return h;
}

struct BuildId {
    char version[32];
    char host[64];
    uint64_t exeHash;
    uint32_t partsBytes;   // sizeof(SampleParts): the tiles' wire format
    uint32_t reserved;
};

// "" when every rank runs rank 0's build, else the ranks that do not (the same text on every rank).
std::string checkBuilds(int size, std::vector<std::string>* hosts)
{
    BuildId me{};
    std::snprintf(me.version, sizeof me.version, "%s", versionString());
    std::snprintf(me.host, sizeof me.host, "%s", hostName().c_str());
    me.exeHash = executableHash();
    me.partsBytes = uint32_t(sizeof(SampleParts));
    std::vector<BuildId> all(static_cast<size_t>(size));
    check(MPI_Allgather(&me, int(sizeof me), MPI_BYTE, all.data(), int(sizeof me), MPI_BYTE, MPI_COMM_WORLD), "Allgather");
    std::string msg;
    for (const BuildId& b : all) hosts->push_back(std::string(b.host, strnlen(b.host, sizeof b.host)));
    const BuildId& lead = all[0];
    for (int r = 1; r < size; ++r) {
        const BuildId& b = all[size_t(r)];
        if (std::strncmp(b.version, lead.version, sizeof b.version) == 0 && b.exeHash == lead.exeHash && b.partsBytes == lead.partsBytes)
            continue;
        char line[400];
        std::snprintf(line, sizeof line, "%srank %d on %.64s runs sylva %.32s (executable %016llx), rank 0 on %.64s runs sylva %.32s (executable %016llx)",
                      msg.empty() ? "" : "; ", r, b.host, b.version, static_cast<unsigned long long>(b.exeHash), lead.host, lead.version,
                      static_cast<unsigned long long>(lead.exeHash));
        msg += line;
    }
    return msg;
}

// ---- the frame's scene, from rank 0 to the others ----

// Waits for req, calling MPI without a pause (a broadcast moves only while its ranks call MPI, and
// every rank waits for it); Error after `timeout` seconds.
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

// Broadcasts `bytes` bytes from rank 0 of `comm` in pieces MPI's int counts can hold.
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

// What the other ranks need to trace the frame (RenderScene::view()): the header of core/render/scene_bytes.h,
// then the arrays. The ranks of one host share one copy of them (SharedFrame); rank 0 broadcasts them to the
// first rank of every other host (Hosts::leaders).
using SceneHeader = RenderSceneHeader;

// The ranks of this rank's host and the first rank of every host. `node`: the ranks that share this host's
// memory (MPI_COMM_TYPE_SHARED), or with SYLVA_MPI_NODE_SIZE=N every N consecutive ranks (N = 1: a copy of the
// frame per rank; N > 1 tries the several-host path on one machine). `leaders`: node rank 0 of every host
// (MPI_COMM_NULL on the others), rank 0 first.
struct Hosts {
    MPI_Comm node = MPI_COMM_NULL, leaders = MPI_COMM_NULL;
    int nodeRank = 0, nodeSize = 1, leaderCount = 1;

    // Collective over MPI_COMM_WORLD.
    void split(int rank, double timeout)
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
    ~Hosts()
    {
        if (leaders != MPI_COMM_NULL) MPI_Comm_free(&leaders);
        if (node != MPI_COMM_NULL) MPI_Comm_free(&node);
    }
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
    void allocate(const Hosts& hosts, uint64_t bytes, double timeout)
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

    void* block() const { return m_block; }
    void sync() const { check(MPI_Win_sync(m_win), "Win_sync"); }

    // Collective over the host's ranks (each calls it when its tracing is done).
    void release(double timeout)
    {
        if (m_win == MPI_WIN_NULL) return;
        const Deadline deadline(timeout, jobError("--mpi: the ranks of a host did not all finish with the frame within the timeout (a rank hung or died)"));
        MPI_Win_unlock_all(m_win);
        MPI_Win_free(&m_win);
        m_block = nullptr;
    }

private:
    static void checkRoom(uint64_t bytes, int ranks)
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

    static constexpr uint64_t kBlockAlign = 64;   // packedFrameLayout's boundary
    MPI_Comm m_node = MPI_COMM_NULL;
    MPI_Win m_win = MPI_WIN_NULL;
    void* m_block = nullptr;   // the window's segment, rounded up to kBlockAlign
};

// Rank 0's arrays to the first rank of every other host, array by array as forEachPackedArray receives them
// (MPI_Ibcast takes a non-const buffer; rank 0's is only read).
void broadcastArrays(const RenderScene& rs, const SceneHeader& h, double timeout, MPI_Comm leaders)
{
    forEachHeaderArray(rs, h, [&](const void* data, size_t bytes) { broadcastBytes(const_cast<void*>(data), bytes, timeout, leaders); });
}

std::unique_ptr<tbb::global_control> threadLimit(int threads)
{
    if (threads <= 0) return nullptr;
    return std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism, size_t(threads));
}

// ---- rank 0: the work queue ----

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
    Film trace(const RenderScene& rs, int y0, int y1, Progress* progress)
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

    // Main thread: the host's shared window for the frame (layout: the packed block's), for the render thread to fill.
    void setBlock(void* block, const SceneHeader& header, const PackedFrame& layout)
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
    void store(int id, const SampleParts* parts, size_t count)
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

private:
    int doneCount()
    {
        std::lock_guard<std::mutex> lock(m_mutex);
        return m_done;
    }

    // Waits for the window (setBlock) and packs the scene into it.
    void packForHost(const RenderScene& rs, Progress* progress)
    {
        std::unique_lock<std::mutex> lock(m_mutex);
        while (!m_block) {
            if (Progress::cancelAllRequested() || (progress && progress->isCancelled())) throw Cancelled();
            m_changed.wait_for(lock, std::chrono::milliseconds(20));
        }
        void* const block = m_block;
        const SceneHeader header = m_header;
        const PackedFrame layout = m_layout;
        lock.unlock();
        packRenderScene(rs, header, layout, block);
        lock.lock();
        m_packed = true;
        m_pack = false;
    }

    const int m_ranks, m_edge;
    bool m_sceneSent;
    bool m_pack;
    void* m_block = nullptr;
    SceneHeader m_header{};
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

// Rank 0's main thread: runs the lead's render in a thread and serves the workers until it is done.
int lead(const RenderJob& job, int size, int localRanks, const std::vector<std::string>& hosts, const Hosts& topology)
{
    const int hostCount = topology.leaderCount;
    // Threads (the render thread's limit): the threads of every rank on this node for the preparation while
    // they wait for the broadcast scene, then job.threads for the tracing.
    std::unique_ptr<tbb::global_control> limit;
    const bool wideBuild = job.broadcastScene && size > 1 && job.threads > 0 && localRanks > 1;
    // The species' lighting shared out (when asked): every rank solves its share into the cache, only when
    // rank 0's render misses in the cache (before its first solve), so a warm cache is read once, by rank 0.
    // Rank 0 then asks the others (kShare; they wait for the scene meanwhile, or with every rank building its
    // own they light their share first anyway), runs its own and waits for theirs. The count of solves is
    // said before the tracing.
    const bool askToShare = job.broadcastScene;
    std::mutex litMutex;
    int lit = 0;
    bool shareAsked = false, shareSent = false;
    std::vector<int> solves(static_cast<size_t>(size), 0);
    auto awaitLit = [&] {
        for (;;) {
            {
                std::lock_guard<std::mutex> lock(litMutex);
                if (lit == size - 1) return;
            }
            if (Progress::cancelAllRequested()) throw Cancelled();
            std::this_thread::sleep_for(std::chrono::milliseconds(5));
        }
    };
    std::function<void()> shareLighting;
    if (job.lightShare)
        shareLighting = [&] {
            {
                std::lock_guard<std::mutex> lock(litMutex);
                shareAsked = true;   // the main thread sends kShare
            }
            int mine = 0;
            {
                // This rank's own threads, as every other rank solves with (the preparation has its node's).
                const auto own = threadLimit(job.threads);
                mine = job.lightShare(0, size, nullptr);
            }
            awaitLit();
            std::lock_guard<std::mutex> lock(litMutex);
            solves[0] = mine;
        };
    auto sayLit = [&] {
        if (!job.lightShare) return;
        bool asked = true;
        {
            std::lock_guard<std::mutex> lock(litMutex);
            asked = shareAsked || !askToShare;
        }
        if (asked) awaitLit();   // else no rank solved (the cache held every grid)
        std::lock_guard<std::mutex> lock(litMutex);
        std::string line;
        int total = 0;
        for (int r = 0; r < size; ++r) {
            total += solves[size_t(r)];
            line += r ? " + " : "";
            line += std::to_string(solves[size_t(r)]);
        }
        std::printf("species lighting on %d %s: %d LB %s (%s by rank), the rest from the cache\n", size, size == 1 ? "rank" : "ranks",
                    total, total == 1 ? "solve" : "solves", line.c_str());
        std::fflush(stdout);
    };
    TileQueue queue(size, job.tile, job.broadcastScene, topology.nodeSize > 1, [&] {
        sayLit();
        if (wideBuild) limit = threadLimit(job.threads);
    });
    const FilmRowsTracer tracer = [&queue](const RenderScene& rs, int y0, int y1, Progress* p) { return queue.trace(rs, y0, y1, p); };
    std::future<int> render = std::async(std::launch::async, [&] {
        limit = threadLimit(wideBuild ? job.threads * localRanks : job.threads);
        return job.lead(tracer, size, job.broadcastScene && size > 1 ? hostCount : 0, shareLighting);
    });

    struct Peer {
        Clock::time_point seen, pinged;
        int wanted = 0;   // requests not answered yet
        bool done = false;
    };
    std::vector<Peer> peers(static_cast<size_t>(size));
    for (Peer& p : peers) p.seen = p.pinged = Clock::now();
    // A worker's request: the tile it finished (id < 0: none) and its pixels' parts.
    auto onRequest = [&](int src, const char* data, int n) {
        if (n < int(sizeof(int32_t))) throw Error(rankName(src) + " sent a malformed request");
        int32_t id = -1;
        std::memcpy(&id, data, sizeof id);
        if (id >= 0) queue.store(id, reinterpret_cast<const SampleParts*>(data + sizeof id), (size_t(n) - sizeof id) / sizeof(SampleParts));
        ++peers[size_t(src)].wanted;
    };
    // Receives posted ahead for every worker's requests, so a tile's result moves into place while this
    // thread polls (MPI_Test) instead of in a blocking receive that spins until the sender's MPI has
    // moved every fragment (a large message needs both ends' calls).
    struct Posted {
        std::vector<char> buf;
        MPI_Request req = MPI_REQUEST_NULL;
    };
    const size_t edge = size_t(std::max(1, job.tile));
    const size_t requestBytes = sizeof(int32_t) + edge * edge * sizeof(SampleParts);
    std::vector<Posted> posted(size_t(std::max(0, size - 1)) * kAhead);
    auto postRequest = [&](size_t i) {
        Posted& q = posted[i];
        q.buf.resize(requestBytes);
        check(MPI_Irecv(q.buf.data(), int(requestBytes), MPI_BYTE, int(i / kAhead) + 1, kRequest, MPI_COMM_WORLD, &q.req), "Irecv");
    };
    try {
        for (size_t i = 0; i < posted.size(); ++i) postRequest(i);
    } catch (const Error& e) {
        abortJob(e.what());
    }
    bool rendered = false;
    int code = 0;
    std::vector<char> buf;
    // The scene's way to the other ranks (with job.broadcastScene): the header to every rank; the arrays packed
    // into the shared window of this host's ranks (its render thread packs them), then the host's barrier lets
    // them start; the arrays broadcast to the first rank of every other host once each has made room (kReady).
    SceneHeader header{};
    PackedFrame layout{};
    SharedFrame frame;
    MPI_Request headerReq = MPI_REQUEST_NULL, hostReq = MPI_REQUEST_NULL;
    bool headerPosted = false, windowMade = false, hostReleased = false, frameReleased = false;
    int ready = 0;
    for (;;) {
        bool busy = false;
        try {
            for (size_t i = 0; i < posted.size(); ++i) {
                int flag = 0;
                MPI_Status st;
                check(MPI_Test(&posted[i].req, &flag, &st), "Test");
                if (!flag) continue;
                busy = true;
                int n = 0;
                check(MPI_Get_count(&st, MPI_BYTE, &n), "Get_count");
                peers[size_t(st.MPI_SOURCE)].seen = Clock::now();
                onRequest(st.MPI_SOURCE, posted[i].buf.data(), n);
                postRequest(i);
            }
            for (;;) {
                int flag = 0;
                MPI_Status st;
                check(MPI_Iprobe(MPI_ANY_SOURCE, MPI_ANY_TAG, MPI_COMM_WORLD, &flag, &st), "Iprobe");
                if (!flag) break;
                busy = true;
                int n = 0;
                check(MPI_Get_count(&st, MPI_BYTE, &n), "Get_count");
                buf.resize(size_t(std::max(n, 1)));
                check(MPI_Recv(buf.data(), n, MPI_BYTE, st.MPI_SOURCE, st.MPI_TAG, MPI_COMM_WORLD, MPI_STATUS_IGNORE), "Recv");
                const int src = st.MPI_SOURCE;
                Peer& p = peers[size_t(src)];
                p.seen = Clock::now();
                if (st.MPI_TAG == kFailed) abortJob(rankName(src) + " on " + std::string(buf.data(), size_t(n)));
                if (st.MPI_TAG == kReady) {
                    ++ready;
                    continue;
                }
                if (st.MPI_TAG == kLit) {
                    int32_t count = 0;
                    if (n == int(sizeof count)) std::memcpy(&count, buf.data(), sizeof count);
                    std::lock_guard<std::mutex> lock(litMutex);
                    solves[size_t(src)] = count;
                    ++lit;
                    continue;
                }
                if (st.MPI_TAG == kRequest) onRequest(src, buf.data(), n);
            }
        } catch (const Error& e) {
            abortJob(e.what());
        }
        if (askToShare) {
            bool send = false;
            {
                std::lock_guard<std::mutex> lock(litMutex);
                send = shareAsked && !shareSent;
                shareSent = shareSent || send;
            }
            for (int r = 1; send && r < size; ++r) check(MPI_Send(nullptr, 0, MPI_BYTE, r, kShare, MPI_COMM_WORLD), "Send");
        }
        if (const RenderScene* rs = queue.sceneToSend()) {
            try {
                if (!headerPosted) {
                    header = hostTracedHeader(*rs);
                    layout = packedFrameLayout(header);
                    check(MPI_Ibcast(&header, int(sizeof header), MPI_BYTE, 0, MPI_COMM_WORLD, &headerReq), "Ibcast");
                    headerPosted = true;
                }
                int flag = headerReq == MPI_REQUEST_NULL;
                if (!flag) check(MPI_Test(&headerReq, &flag, MPI_STATUS_IGNORE), "Test");
                const bool host = topology.nodeSize > 1;
                if (flag && host && !windowMade) {
                    frame.allocate(topology, layout.bytes, job.timeoutSeconds);
                    queue.setBlock(frame.block(), header, layout);
                    windowMade = busy = true;
                }
                if (flag && host && !hostReleased && queue.packed()) {
                    frame.sync();
                    check(MPI_Ibarrier(topology.node, &hostReq), "Ibarrier");
                    hostReleased = busy = true;
                }
                if (flag && (!host || hostReleased) && ready == topology.leaderCount - 1) {
                    if (topology.leaderCount > 1) broadcastArrays(*rs, header, job.timeoutSeconds, topology.leaders);
                    if (hostReq != MPI_REQUEST_NULL) finish(hostReq, job.timeoutSeconds, "the start of this host's ranks on the frame");
                    queue.markSceneSent();
                    busy = true;
                }
            } catch (const Error& e) {
                abortJob(e.what());
            }
        }
        if (!rendered && render.wait_for(std::chrono::seconds(0)) == std::future_status::ready) {
            rendered = true;
            try {
                code = render.get();
            } catch (const Cancelled&) {
                // mpirun stops every rank with SIGTERM when one dies; the CLI reports the signal.
                throw;
            } catch (const std::exception& e) {
                abortJob(e.what());
            }
        }
        // Once the frame's tiles are all in, the workers are let go and the host's window freed (the ranks
        // free it together) while the render thread still composes and writes the picture.
        const bool traced = rendered || queue.traced();
        for (int r = 1; r < size; ++r) {
            Peer& p = peers[size_t(r)];
            TileMsg t{};
            while (p.wanted > 0 && queue.take(&t)) {
                check(MPI_Send(&t, int(sizeof t), MPI_BYTE, r, kTile, MPI_COMM_WORLD), "Send");
                --p.wanted;
                busy = true;
            }
            if (p.done) continue;
            if (p.wanted > 0 && traced) {
                check(MPI_Send(nullptr, 0, MPI_BYTE, r, kDone, MPI_COMM_WORLD), "Send");
                p.wanted = 0;
                p.done = true;
                continue;
            }
            // A rank waiting on rank 0 (for a tile, or for the scene while rank 0 builds it) hears from it.
            const bool waiting = p.wanted > 0 || !queue.sceneSent();
            if (waiting && since(p.pinged) > kHeartbeatSeconds) {
                check(MPI_Send(nullptr, 0, MPI_BYTE, r, kHeartbeat, MPI_COMM_WORLD), "Send");
                p.pinged = Clock::now();
            }
        }
        bool allDone = true;
        for (int r = 1; r < size; ++r) {
            const Peer& p = peers[size_t(r)];
            if (p.done) continue;
            allDone = false;
            if (since(p.seen) > job.timeoutSeconds) {
                char msg[200];
                std::snprintf(msg, sizeof msg, "rank %d on %s sent nothing for %.0f s (it hung, died or lost its connection)", r,
                              hosts[size_t(r)].c_str(), job.timeoutSeconds);
                abortJob(msg);
            }
        }
        if (traced && allDone && !frameReleased) {
            frame.release(job.timeoutSeconds);
            frameReleased = true;
        }
        if (rendered && allDone) break;
        if (Progress::cancelAllRequested()) {
            // mpirun sends SIGTERM to every rank when one dies or fails (and on Ctrl-C); the render may be
            // in a step that does not look at the cancel flag, so say it here and leave at once.
            std::fprintf(stderr, "sylva render: stopped by a signal (mpirun ends the job when a rank dies or fails); no picture was written\n");
            std::fflush(stderr);
            std::_Exit(128 + 15);
        }
        if (!busy) std::this_thread::sleep_for(kPollPause);
    }
    for (Posted& q : posted) {
        if (q.req == MPI_REQUEST_NULL) continue;
        MPI_Cancel(&q.req);
        MPI_Wait(&q.req, MPI_STATUS_IGNORE);
    }
    frame.release(job.timeoutSeconds);
    return code;
}

// ---- the other ranks ----

class Worker {
public:
    Worker(int rank, double timeout) : m_rank(rank), m_timeout(timeout) { m_beat = m_heard = Clock::now(); }

    // Waits for f (run in another thread), sending heartbeats meanwhile; returns its result. An
    // exception of f is reported to rank 0, which ends the job.
    template <class F>
    auto busy(F&& f)
    {
        auto fut = std::async(std::launch::async, std::forward<F>(f));
        while (fut.wait_for(std::chrono::milliseconds(20)) != std::future_status::ready) beat();
        try {
            return fut.get();
        } catch (const Cancelled&) {
            throw;
        } catch (const std::exception& e) {
            fail(e.what());
        }
    }

    // Sends bytes to rank 0 and waits for the send to complete, with heartbeats.
    void send(const void* data, size_t bytes, int tag)
    {
        MPI_Request req;
        check(MPI_Isend(data, int(bytes), MPI_BYTE, 0, tag, MPI_COMM_WORLD, &req), "Isend");
        const Clock::time_point t0 = Clock::now();
        for (;;) {
            int flag = 0;
            check(MPI_Test(&req, &flag, MPI_STATUS_IGNORE), "Test");
            if (flag) return;
            if (since(t0) > m_timeout) giveUp();
            std::this_thread::sleep_for(std::chrono::microseconds(200));
        }
    }

    // The frame's scene as rank 0 sends it: waits for its header (rank 0 pings meanwhile; this rank's
    // heartbeats go on), makes room for its arrays in this host's shared window, and when this rank is the
    // first of a host other than rank 0's, receives them there from rank 0's broadcast; then waits at the
    // host's barrier until the host's copy is whole. Returns the view of that copy. onShare: run when rank 0
    // asks for this rank's share of the species' lighting (kShare) while it prepares the scene.
    RenderView receiveScene(const Hosts& hosts, SharedFrame& frame, const std::function<void()>& onShare)
    {
        SceneHeader h{};
        MPI_Request req;
        check(MPI_Ibcast(&h, int(sizeof h), MPI_BYTE, 0, MPI_COMM_WORLD, &req), "Ibcast");
        await(req, onShare);
        const PackedFrame layout = packedFrameLayout(h);
        try {
            frame.allocate(hosts, layout.bytes, m_timeout);
            if (hosts.nodeRank == 0) {
                send(nullptr, 0, kReady);
                forEachPackedArray(h, layout, frame.block(), [&](void* data, size_t bytes) { broadcastBytes(data, bytes, m_timeout, hosts.leaders); });
                frame.sync();
            }
        } catch (const Error& e) {
            fail(e.what());
        }
        if (hosts.nodeSize > 1) {
            check(MPI_Ibarrier(hosts.node, &req), "Ibarrier");
            await(req);
            frame.sync();
        }
        return packedFrameView(h, layout, frame.block());
    }

    // Waits for req with heartbeats both ways (rank 0 pings a rank that waits on it); onShare (when given)
    // runs when rank 0 sends kShare.
    void await(MPI_Request& req, const std::function<void()>& onShare = {})
    {
        m_heard = Clock::now();
        for (;;) {
            int flag = 0;
            check(MPI_Test(&req, &flag, MPI_STATUS_IGNORE), "Test");
            if (flag) return;
            if (onShare) {
                check(MPI_Iprobe(0, kShare, MPI_COMM_WORLD, &flag, MPI_STATUS_IGNORE), "Iprobe");
                if (flag) {
                    check(MPI_Recv(nullptr, 0, MPI_BYTE, 0, kShare, MPI_COMM_WORLD, MPI_STATUS_IGNORE), "Recv");
                    onShare();
                    m_heard = Clock::now();
                    continue;
                }
            }
            for (;;) {
                MPI_Status st;
                check(MPI_Iprobe(0, kHeartbeat, MPI_COMM_WORLD, &flag, &st), "Iprobe");
                if (!flag) break;
                check(MPI_Recv(nullptr, 0, MPI_BYTE, 0, kHeartbeat, MPI_COMM_WORLD, MPI_STATUS_IGNORE), "Recv");
                m_heard = Clock::now();
            }
            if (since(m_heard) > m_timeout) giveUp();
            beat();
            std::this_thread::sleep_for(std::chrono::microseconds(200));
        }
    }

    // Traces the tiles rank 0 hands out until it says done. A render thread traces them in turn
    // while this (main) thread keeps kAhead requests out, sends each result as the next request
    // without waiting for it to arrive, and takes the tiles and heartbeats rank 0 sends.
    void traceTiles(const RenderView& view)
    {
        struct Result {
            std::vector<char> msg;   // int32 tile id, then the tile's SampleParts
            MPI_Request req = MPI_REQUEST_NULL;
            Clock::time_point sent;
        };
        std::mutex m;
        std::condition_variable cv;
        std::deque<TileMsg> todo;
        std::deque<std::unique_ptr<Result>> finished, spare;
        bool quit = false, tracing = false;
        std::string error;
        std::thread render([&] {
            for (;;) {
                TileMsg t{};
                std::unique_ptr<Result> r;
                {
                    std::unique_lock<std::mutex> lock(m);
                    cv.wait(lock, [&] { return quit || !todo.empty(); });
                    if (quit) return;
                    t = todo.front();
                    todo.pop_front();
                    tracing = true;
                    if (!spare.empty()) {
                        r = std::move(spare.back());
                        spare.pop_back();
                    }
                }
                if (!r) r = std::make_unique<Result>();
                const size_t pixels = size_t(t.x1 - t.x0) * size_t(t.y1 - t.y0);
                r->msg.resize(sizeof(int32_t) + pixels * sizeof(SampleParts));
                std::memcpy(r->msg.data(), &t.id, sizeof t.id);
                std::string failure;
                try {
                    renderFilmRect(view, t.x0, t.y0, t.x1, t.y1, reinterpret_cast<SampleParts*>(r->msg.data() + sizeof(int32_t)));
                } catch (const std::exception& e) {
                    failure = e.what();
                }
                {
                    std::lock_guard<std::mutex> lock(m);
                    tracing = false;
                    if (!failure.empty()) error = failure;
                    else finished.push_back(std::move(r));
                }
                cv.notify_all();
                if (!failure.empty()) return;
            }
        });
        struct Join {
            std::mutex& m;
            std::condition_variable& cv;
            bool& quit;
            std::thread& t;
            ~Join()
            {
                {
                    std::lock_guard<std::mutex> lock(m);
                    quit = true;
                }
                cv.notify_all();
                t.join();
            }
        } join{m, cv, quit, render};

        std::vector<std::unique_ptr<Result>> sending;
        auto post = [&](std::unique_ptr<Result> r) {
            check(MPI_Isend(r->msg.data(), int(r->msg.size()), MPI_BYTE, 0, kRequest, MPI_COMM_WORLD, &r->req), "Isend");
            r->sent = Clock::now();
            sending.push_back(std::move(r));
        };
        for (int i = 0; i < kAhead; ++i) {
            auto r = std::make_unique<Result>();
            const int32_t none = -1;
            r->msg.resize(sizeof none);
            std::memcpy(r->msg.data(), &none, sizeof none);
            post(std::move(r));
        }
        bool done = false, wasIdle = false;
        for (;;) {
            std::deque<std::unique_ptr<Result>> ready;
            bool idle = false;
            {
                std::unique_lock<std::mutex> lock(m);
                if (finished.empty() && error.empty())
                    cv.wait_for(lock, kPollPause, [&] { return !finished.empty() || !error.empty(); });
                if (!error.empty()) {
                    const std::string what = error;
                    lock.unlock();
                    fail(what);
                }
                ready.swap(finished);
                idle = todo.empty() && !tracing;
            }
            for (auto& r : ready) post(std::move(r));
            // Sends that arrived: their buffers serve the next tiles.
            for (size_t i = 0; i < sending.size();) {
                int flag = 0;
                check(MPI_Test(&sending[i]->req, &flag, MPI_STATUS_IGNORE), "Test");
                if (flag) {
                    std::lock_guard<std::mutex> lock(m);
                    spare.push_back(std::move(sending[i]));
                    sending.erase(sending.begin() + std::ptrdiff_t(i));
                } else {
                    if (since(sending[i]->sent) > m_timeout) giveUp();
                    ++i;
                }
            }
            for (;;) {
                int flag = 0;
                MPI_Status st;
                check(MPI_Iprobe(0, MPI_ANY_TAG, MPI_COMM_WORLD, &flag, &st), "Iprobe");
                if (!flag) break;
                m_heard = Clock::now();
                if (st.MPI_TAG == kTile) {
                    TileMsg t{};
                    check(MPI_Recv(&t, int(sizeof t), MPI_BYTE, 0, kTile, MPI_COMM_WORLD, MPI_STATUS_IGNORE), "Recv");
                    if (t.x0 < 0 || t.y0 < 0 || t.x1 > view.width || t.y1 > view.height || t.x0 >= t.x1 || t.y0 >= t.y1)
                        fail("rank 0 sent a tile outside the frame (do the ranks render the same scene?)");
                    {
                        std::lock_guard<std::mutex> lock(m);
                        todo.push_back(t);
                    }
                    cv.notify_all();
                    idle = false;
                    continue;
                }
                check(MPI_Recv(nullptr, 0, MPI_BYTE, 0, st.MPI_TAG, MPI_COMM_WORLD, MPI_STATUS_IGNORE), "Recv");
                if (st.MPI_TAG == kDone) done = true;
            }
            if (done && idle && ready.empty() && sending.empty()) return;
            // Rank 0 owes an answer only while this rank has nothing to trace: the wait starts then.
            if (idle && !wasIdle) m_heard = Clock::now();
            wasIdle = idle;
            if (idle && !done && since(m_heard) > m_timeout) giveUp();
            beat();
        }
    }

    [[noreturn]] void fail(const std::string& what)
    {
        const std::string text = hostName() + ": " + what;
        try {
            send(text.data(), text.size(), kFailed);
        } catch (const Error&) {
        }
        // Rank 0 aborts the job on this message; should it not, stop after the timeout.
        const Clock::time_point t0 = Clock::now();
        while (since(t0) < m_timeout) std::this_thread::sleep_for(std::chrono::milliseconds(50));
        abortJob(rankName(m_rank) + " on " + text);
    }

private:
    void beat()
    {
        if (Progress::cancelAllRequested()) std::_Exit(128 + 15);   // SIGTERM from mpirun: rank 0 says why
        if (since(m_beat) < kHeartbeatSeconds) return;
        check(MPI_Send(nullptr, 0, MPI_BYTE, 0, kHeartbeat, MPI_COMM_WORLD), "Send");
        m_beat = Clock::now();
    }

    [[noreturn]] void giveUp()
    {
        char msg[200];
        std::snprintf(msg, sizeof msg, "rank %d: rank 0 sent nothing for %.0f s", m_rank, m_timeout);
        abortJob(msg);
    }

    const int m_rank;
    const double m_timeout;
    Clock::time_point m_beat, m_heard;
};

int work(const RenderJob& job, int rank, int size, const Hosts& hosts)
{
    const auto limit = threadLimit(job.threads);
    Worker w(rank, job.timeoutSeconds);
    try {
        Progress quiet([](double, const std::string&) {});
        // The species' lighting share: when rank 0 asks (its render missed in the cache) while it prepares the
        // scene to broadcast, or first when this rank builds its own scene from the cache.
        auto share = [&] {
            const int32_t solved = w.busy([&] { return job.lightShare(rank, size, &quiet); });
            w.send(&solved, sizeof solved, kLit);
        };
        if (job.lightShare && !job.broadcastScene) share();
        SharedFrame frame;
        RenderScene own;
        const RenderView view = job.broadcastScene ? w.receiveScene(hosts, frame, job.lightShare ? std::function<void()>(share) : nullptr)
                                                   : (own = w.busy([&] { return job.prepare(&quiet); })).view();
        w.traceTiles(view);
        frame.release(job.timeoutSeconds);
    } catch (const Cancelled&) {
        throw;
    } catch (const Error& e) {
        abortJob(rankName(rank) + " on " + hostName() + ": " + e.what());
    }
    return 0;
}

} // namespace

bool launchedByMpi()
{
    for (const char* name : {"OMPI_COMM_WORLD_SIZE", "PMIX_RANK", "PMI_RANK", "PMI_SIZE"})
        if (std::getenv(name)) return true;
    return false;
}

int launchRank()
{
    for (const char* name : {"OMPI_COMM_WORLD_RANK", "PMIX_RANK", "PMI_RANK"}) {
        const int r = envInt(name, -1);
        if (r >= 0) return r;
    }
    return 0;
}

int runSession(const char* command, const char* notWritten,
               const std::function<int(int rank, int size, const std::vector<std::string>& hosts)>& body, double timeoutSeconds)
{
    g_command = command;
    g_notWritten = notWritten;
    if (!launchedByMpi())
        throw Error(std::string("--mpi: this process was not started by mpirun; run it as: mpirun -np N sylva ") + command +
                    " --mpi ... (docs/DISTRIBUTED.md), or drop --mpi");
    // The start (MPI_Init and the build check) waits for every rank: one that hangs there, or never
    // starts, ends the job after the start bound (this process exits; mpirun then stops the others).
    const double startBound = 2.0 * timeoutSeconds + 5.0;
    char startMessage[160];
    std::snprintf(startMessage, sizeof startMessage, "--mpi: the ranks did not all start within %.0f s (a rank hung or could not start)", startBound);
    Deadline start(startBound, jobError(startMessage));
    int provided = 0;
    if (MPI_Init_thread(nullptr, nullptr, MPI_THREAD_FUNNELED, &provided) != MPI_SUCCESS) throw Error("--mpi: MPI_Init failed");
    MPI_Comm_set_errhandler(MPI_COMM_WORLD, MPI_ERRORS_RETURN);
    int rank = 0, size = 1;
    MPI_Comm_rank(MPI_COMM_WORLD, &rank);
    MPI_Comm_size(MPI_COMM_WORLD, &size);
    if (provided < MPI_THREAD_FUNNELED) {
        if (rank == 0) std::fprintf(stderr, "sylva %s: error: --mpi: this MPI library does not allow threads (MPI_THREAD_FUNNELED)\n", command);
        MPI_Finalize();
        return 1;
    }
    std::string mismatch;
    std::vector<std::string> hosts;
    try {
        mismatch = checkBuilds(size, &hosts);
    } catch (const Error& e) {
        abortJob(e.what());
    }
    if (!mismatch.empty()) {
        if (rank == 0)
            std::fprintf(stderr, "sylva %s: error: --mpi: the ranks run different builds of sylva (%s); install one build on every node\n",
                         command, mismatch.c_str());
        MPI_Finalize();
        return 1;
    }
    start.disarm();
    const int code = body(rank, size, hosts);
    MPI_Finalize();
    return code;
}

[[noreturn]] void endJob(const std::string& message) { abortJob(message); }

void checkMpi(int rc, const char* what) { check(rc, what); }

std::string thisHost() { return hostName(); }

int runRender(const RenderJob& job)
{
    return runSession("render", "no picture was written", [&](int rank, int size, const std::vector<std::string>& hosts) {
        // The ranks on rank 0's host (they share its cores).
        const int leadNode = int(std::count(hosts.begin(), hosts.end(), hosts.front()));
        Hosts topology;
        if (job.broadcastScene && size > 1) topology.split(rank, 2.0 * job.timeoutSeconds + 5.0);
        return rank == 0 ? lead(job, size, leadNode, hosts, topology) : work(job, rank, size, topology);
    }, job.timeoutSeconds);
}

} // namespace sylva::mpi
