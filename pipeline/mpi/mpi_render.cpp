// sylva render --mpi: the build check, rank 0's work queue of tiles and its watch over the ranks, the workers.
//
// Threads: every MPI call is made by the process's main thread (MPI_THREAD_FUNNELED). The long work
// (loading the scene, rank 0's render, a worker's tile) runs in a second thread while the main thread
// sends and receives heartbeats, so a rank busy for minutes is still heard from twice a second.
#include "pipeline/mpi/mpi_render.h"

#include <mpi.h>
#include <unistd.h>
#include <xxhash.h>

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <deque>
#include <fstream>
#include <future>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "core/base/error.h"
#include "core/base/version.h"
#include "core/render/render_cpu.h"
#include "pipeline/mpi/mpi_session.h"
#include "pipeline/mpi/mpi_tiles.h"

namespace sylva::mpi {
namespace {

using Clock = std::chrono::steady_clock;

// Message tags. Workers send kHeartbeat, kRequest (the tile they finished, if any, and a request for
// the next) and kFailed (an error text); rank 0 sends kTile, kDone and kHeartbeat (to waiting ranks).
enum Tag : int { kFailed = 11, kHeartbeat = 12, kRequest = 13, kTile = 14, kDone = 15, kLit = 16 };

constexpr double kHeartbeatSeconds = 0.5;

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

// ---- rank 0: the work queue ----

struct TileMsg {
    int32_t id, x0, y0, x1, y1;
};

// Shared by rank 0's two threads: the render thread publishes a band's tiles and traces some itself;
// the main thread hands the others to the workers and stores what they send back.
class TileQueue {
public:
    TileQueue(int ranks, int tileEdge) : m_ranks(ranks), m_edge(tileEdge) {}

    // Render thread: rows [y0, y1) of the view as a film, every tile traced here or by a worker.
    Film trace(const RenderView& v, int y0, int y1, Progress* progress)
    {
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
        return film;
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

    const int m_ranks, m_edge;
    std::mutex m_mutex;
    std::condition_variable m_changed;
    Film* m_film = nullptr;
    int m_y0 = 0, m_base = 0, m_next = 0, m_done = 0;
    std::vector<TileMsg> m_tiles;
    std::deque<TileMsg> m_pending;
};

// Rank 0's main thread: runs the lead's render in a thread and serves the workers until it is done.
int lead(const RenderJob& job, int size, const std::vector<std::string>& hosts)
{
    TileQueue queue(size, job.tile);
    const FilmRowsTracer tracer = [&queue](const RenderView& v, int y0, int y1, Progress* p) { return queue.trace(v, y0, y1, p); };
    // The species' lighting shared out (when asked): rank 0's share, then a wait for every rank's.
    std::mutex litMutex;
    int lit = 0;
    std::vector<int> solves(static_cast<size_t>(size), 0);
    std::future<int> render = std::async(std::launch::async, [&] {
        if (job.lightShare) {
            const int mine = job.lightShare(0, size, nullptr);
            for (;;) {
                {
                    std::lock_guard<std::mutex> lock(litMutex);
                    if (lit == size - 1) {
                        solves[0] = mine;
                        std::string line;
                        int total = 0;
                        for (int r = 0; r < size; ++r) {
                            total += solves[size_t(r)];
                            line += r ? " + " : "";
                            line += std::to_string(solves[size_t(r)]);
                        }
                        std::printf("species lighting on %d %s: %d LB %s (%s by rank), the rest from the cache\n", size,
                                    size == 1 ? "rank" : "ranks", total, total == 1 ? "solve" : "solves", line.c_str());
                        std::fflush(stdout);
                        break;
                    }
                }
                if (Progress::cancelAllRequested()) throw Cancelled();
                std::this_thread::sleep_for(std::chrono::milliseconds(5));
            }
        }
        return job.lead(tracer, size);
    });

    struct Peer {
        Clock::time_point seen, pinged;
        bool waiting = false, done = false;
    };
    std::vector<Peer> peers(static_cast<size_t>(size));
    for (Peer& p : peers) p.seen = p.pinged = Clock::now();
    bool rendered = false;
    int code = 0;
    std::vector<char> buf;
    for (;;) {
        bool busy = false;
        try {
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
                if (st.MPI_TAG == kLit) {
                    int32_t count = 0;
                    if (n == int(sizeof count)) std::memcpy(&count, buf.data(), sizeof count);
                    std::lock_guard<std::mutex> lock(litMutex);
                    solves[size_t(src)] = count;
                    ++lit;
                    continue;
                }
                if (st.MPI_TAG != kRequest) continue;
                if (n < int(sizeof(int32_t))) throw Error(rankName(src) + " sent a malformed request");
                int32_t id = -1;
                std::memcpy(&id, buf.data(), sizeof id);
                if (id >= 0)
                    queue.store(id, reinterpret_cast<const SampleParts*>(buf.data() + sizeof id),
                                (size_t(n) - sizeof id) / sizeof(SampleParts));
                p.waiting = true;
            }
        } catch (const Error& e) {
            abortJob(e.what());
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
        for (int r = 1; r < size; ++r) {
            Peer& p = peers[size_t(r)];
            if (!p.waiting) continue;
            TileMsg t{};
            if (queue.take(&t)) {
                check(MPI_Send(&t, int(sizeof t), MPI_BYTE, r, kTile, MPI_COMM_WORLD), "Send");
                p.waiting = false;
                busy = true;
            } else if (rendered) {
                check(MPI_Send(nullptr, 0, MPI_BYTE, r, kDone, MPI_COMM_WORLD), "Send");
                p.waiting = false;
                p.done = true;
            } else if (since(p.pinged) > kHeartbeatSeconds) {
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
        if (rendered && allDone) break;
        if (Progress::cancelAllRequested()) {
            // mpirun sends SIGTERM to every rank when one dies or fails (and on Ctrl-C); the render may be
            // in a step that does not look at the cancel flag, so say it here and leave at once.
            std::fprintf(stderr, "sylva render: stopped by a signal (mpirun ends the job when a rank dies or fails); no picture was written\n");
            std::fflush(stderr);
            std::_Exit(128 + 15);
        }
        if (!busy) std::this_thread::sleep_for(std::chrono::microseconds(200));
    }
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

    // The next message of rank 0 other than a heartbeat: kTile (t filled) or kDone.
    int await(TileMsg* t)
    {
        m_heard = Clock::now();   // the wait starts now (rank 0 owes nothing while this rank works)
        for (;;) {
            int flag = 0;
            MPI_Status st;
            check(MPI_Iprobe(0, MPI_ANY_TAG, MPI_COMM_WORLD, &flag, &st), "Iprobe");
            if (flag) {
                m_heard = Clock::now();
                if (st.MPI_TAG == kTile) {
                    check(MPI_Recv(t, int(sizeof *t), MPI_BYTE, 0, kTile, MPI_COMM_WORLD, MPI_STATUS_IGNORE), "Recv");
                    return kTile;
                }
                check(MPI_Recv(nullptr, 0, MPI_BYTE, 0, st.MPI_TAG, MPI_COMM_WORLD, MPI_STATUS_IGNORE), "Recv");
                if (st.MPI_TAG == kDone) return kDone;
                continue;
            }
            if (since(m_heard) > m_timeout) giveUp();
            beat();
            std::this_thread::sleep_for(std::chrono::microseconds(200));
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

int work(const RenderJob& job, int rank, int size)
{
    Worker w(rank, job.timeoutSeconds);
    try {
        Progress quiet([](double, const std::string&) {});
        if (job.lightShare) {
            const int32_t solved = w.busy([&] { return job.lightShare(rank, size, &quiet); });
            w.send(&solved, sizeof solved, kLit);
        }
        const RenderScene rs = w.busy([&] { return job.prepare(&quiet); });
        const RenderView view = rs.view();
        std::vector<char> msg(sizeof(int32_t));
        int32_t finished = -1;
        std::memcpy(msg.data(), &finished, sizeof finished);
        for (;;) {
            w.send(msg.data(), msg.size(), kRequest);
            TileMsg t{};
            if (w.await(&t) == kDone) break;
            if (t.x0 < 0 || t.y0 < 0 || t.x1 > view.width || t.y1 > view.height || t.x0 >= t.x1 || t.y0 >= t.y1)
                w.fail("rank 0 sent a tile outside the frame (do the ranks render the same scene?)");
            const size_t pixels = size_t(t.x1 - t.x0) * size_t(t.y1 - t.y0);
            msg.resize(sizeof(int32_t) + pixels * sizeof(SampleParts));
            std::memcpy(msg.data(), &t.id, sizeof t.id);
            w.busy([&] {
                renderFilmRect(view, t.x0, t.y0, t.x1, t.y1, reinterpret_cast<SampleParts*>(msg.data() + sizeof(int32_t)));
                return 0;
            });
        }
    } catch (const Cancelled&) {
        throw;
    } catch (const Error& e) {
        abortJob(rankName(rank) + " on " + hostName() + ": " + e.what());
    }
    return 0;
}

int envInt(const char* name, int fallback)
{
    const char* v = std::getenv(name);
    return v && *v ? std::atoi(v) : fallback;
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
               const std::function<int(int rank, int size, const std::vector<std::string>& hosts)>& body)
{
    g_command = command;
    g_notWritten = notWritten;
    if (!launchedByMpi())
        throw Error(std::string("--mpi: this process was not started by mpirun; run it as: mpirun -np N sylva ") + command +
                    " --mpi ... (docs/DISTRIBUTED.md), or drop --mpi");
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
        return rank == 0 ? lead(job, size, hosts) : work(job, rank, size);
    });
}

} // namespace sylva::mpi
