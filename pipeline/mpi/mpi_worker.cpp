// The ranks other than 0 of `sylva render --mpi` (mpi_worker.h): the long work in a second thread while the
// main thread sends heartbeats to rank 0 and takes its tiles.
#include "pipeline/mpi/mpi_worker.h"

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <deque>
#include <functional>
#include <future>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "core/base/error.h"
#include "core/base/progress.h"
#include "pipeline/mpi/mpi_common.h"
#include "pipeline/mpi/mpi_tile_queue.h"

namespace sylva::mpi {
namespace {

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

} // namespace

int runWorker(const RenderJob& job, int rank, int size, const Hosts& hosts)
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
        if (job.lightShare && !job.broadcastScene) {
            share();
            // Every rank's share in the cache before this rank builds (rank 0 says so with kShare): else it would
            // solve another rank's species again.
            MPI_Request go;
            check(MPI_Irecv(nullptr, 0, MPI_BYTE, 0, kShare, MPI_COMM_WORLD, &go), "Irecv");
            w.await(go);
        }
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

} // namespace sylva::mpi
