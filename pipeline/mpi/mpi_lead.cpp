// Rank 0 of `sylva render --mpi` (mpi_lead.h): the render in a second thread, tracing through the work queue
// of tiles (mpi_tile_queue.h), while the main thread hands the frame's scene and the tiles to the other ranks,
// takes their results and watches that each is heard from.
#include "pipeline/mpi/mpi_lead.h"

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
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

int runLead(const RenderJob& job, int size, int localRanks, const std::vector<std::string>& hosts, const Hosts& topology)
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
    // With every rank building its own scene, every rank lights its share first, rank 0 too, and rank 0 tells
    // the others (kShare) when every share is in the cache: a rank that built before would solve another's
    // species again (and that rank would find it cached and count one solve fewer).
    const bool eachShares = !job.broadcastScene && job.lightShare && size > 1;
    bool ownLit = false;
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
        if (eachShares) {
            shareLighting();
            std::lock_guard<std::mutex> lock(litMutex);
            ownLit = true;
        }
        return job.lead(tracer, size, job.broadcastScene && size > 1 ? hostCount : 0, eachShares ? std::function<void()>() : shareLighting);
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
        if (eachShares) {   // every share lit: the ranks build their scenes
            bool send = false;
            {
                std::lock_guard<std::mutex> lock(litMutex);
                send = ownLit && !shareSent;
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
            bool goPending = false;
            if (eachShares) {
                std::lock_guard<std::mutex> lock(litMutex);
                goPending = !shareSent;
            }
            const bool waiting = p.wanted > 0 || !queue.sceneSent() || goPending;
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

} // namespace sylva::mpi
