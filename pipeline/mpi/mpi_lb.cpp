// The distributed LB grid over MPI (mpi_lb.h): slabs of lb_slab.h, halo planes by Isend/Irecv overlapped
// with the planes that need none, the totals gathered on rank 0.
#include "pipeline/mpi/mpi_lb.h"

#include <mpi.h>

#include <algorithm>
#include <chrono>
#include <climits>
#include <cstdio>
#include <string>
#include <thread>
#include <vector>

#include "core/base/error.h"
#include "core/lb/lb_slab.h"
#include "pipeline/mpi/mpi_session.h"

namespace sylva::mpi {
namespace {

using Clock = std::chrono::steady_clock;

double g_timeout = 10.0;   // runLightSession's
constexpr int kTestsBetweenPlanes = 256;

// Halo tags: a plane travelling toward lower ranks, or toward higher ranks.
enum Tag : int { kToLower = 21, kToHigher = 22, kTotals = 23 };

double since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

std::string rankText(int r)
{
    char t[32];
    std::snprintf(t, sizeof t, "rank %d", r);
    return t;
}

// Completes every request, testing them (which also moves a large message along) and sleeping briefly
// between tests once the first millisecond has passed, so a rank waiting on an oversubscribed machine
// leaves its core to the neighbour it waits for. Past `limit` seconds the job ends naming `what`.
void waitAll(std::vector<MPI_Request>& reqs, double limit, const std::string& what)
{
    if (reqs.empty()) return;
    const Clock::time_point t0 = Clock::now();
    for (;;) {
        int flag = 0;
        checkMpi(MPI_Testall(int(reqs.size()), reqs.data(), &flag, MPI_STATUSES_IGNORE), "Testall");
        if (flag) break;
        if (Progress::cancelAllRequested()) throw Cancelled();   // mpirun's SIGTERM when a rank died
        const double waited = since(t0);
        if (waited > limit) {
            char msg[160];
            std::snprintf(msg, sizeof msg, " for %.0f s (a rank hung, died or lost its connection)", limit);
            endJob(what + msg);
        }
        if (waited > 1e-3) std::this_thread::sleep_for(std::chrono::microseconds(50));
        else std::this_thread::yield();
    }
    reqs.clear();
}

int byteCount(size_t bytes)
{
    if (bytes > size_t(INT_MAX)) throw Error("the grid's y-z planes are too large for one MPI message (" + std::to_string(bytes) + " bytes)");
    return int(bytes);
}

} // namespace

LightingGrid solveDistributed(const DensityGrid& density, const lb::LbParams& params, Progress* progress, DistributedStats* stats)
{
    lb::validate(params);
    lb::validateDensity(density);
    if (params.tolerance > 0.0 || params.coarseStart)
        throw Error("--mpi: the distributed LB grid runs a fixed step count; drop --tol and --coarse-start (or use --steps N)");
    const Clock::time_point t0 = Clock::now();
    int rank = 0, ranks = 1;
    MPI_Comm_rank(MPI_COMM_WORLD, &rank);
    MPI_Comm_size(MPI_COMM_WORLD, &ranks);
    const glm::ivec3 dims = density.geometry.dims;
    const lb::SlabRange owned = lb::slabOwned(dims.x, rank, ranks);
    const DensityGrid local = lb::slabDensity(density, owned);
    int solveOf[3];
    const std::vector<lb::ChannelParams> solves = lb::distinctSolves(params, solveOf);
    const int steps = lb::fixedSteps(params, dims);
    const std::unique_ptr<lb::LbSlab> slab = lb::makeCpuSlab(local, params, progress);
    const int X = slab->planes();
    const int lower = rank > 0 ? rank - 1 : -1, higher = rank + 1 < ranks ? rank + 1 : -1;
    const int planeBytes = byteCount(slab->planeBytes());
    DistributedStats st;
    st.ranks = ranks;
    st.steps = steps;
    st.solves = int(solves.size());
    st.ownedPlanes = owned.end - owned.begin;
    st.planeBytes = slab->planeBytes();

    // The plane totals this rank returns: its own planes, and the grid's x face beside them on the first
    // and the last rank (faces hold the boundary condition: their totals are the single solve's too).
    const size_t planeNodes = size_t(dims.y) * size_t(dims.z);
    const int sendLo = rank == 0 ? 0 : 1, sendHi = higher < 0 ? X : X - 1;   // local planes
    const int globalLo = owned.begin - 1 + sendLo;

    LightingGrid out;
    if (rank == 0) {
        out.geometry = density.geometry;
        out.rgb.assign(density.geometry.nodeCount() * 3, 0.0f);
    }
    std::vector<float> tot, all;
    std::vector<MPI_Request> reqs;
    double slowestStep = 0.0;
    std::string who = rankText(rank) + ": no halo plane from ";
    who += lower >= 0 ? rankText(lower) : std::string();
    who += lower >= 0 && higher >= 0 ? " or " : "";
    who += higher >= 0 ? rankText(higher) : std::string();
    for (size_t s = 0; s < solves.size(); ++s) {
        slab->setSolve(solves[s]);
        for (int t = 0; t < steps; ++t) {
            const Clock::time_point ts = Clock::now();
            // The halos of the current state travel while the planes that need none are stepped.
            if (lower >= 0) {
                reqs.emplace_back();
                checkMpi(MPI_Irecv(slab->plane(0), planeBytes, MPI_BYTE, lower, kToHigher, MPI_COMM_WORLD, &reqs.back()), "Irecv");
                reqs.emplace_back();
                checkMpi(MPI_Isend(slab->plane(1), planeBytes, MPI_BYTE, lower, kToLower, MPI_COMM_WORLD, &reqs.back()), "Isend");
            }
            if (higher >= 0) {
                reqs.emplace_back();
                checkMpi(MPI_Irecv(slab->plane(X - 1), planeBytes, MPI_BYTE, higher, kToLower, MPI_COMM_WORLD, &reqs.back()), "Irecv");
                reqs.emplace_back();
                checkMpi(MPI_Isend(slab->plane(X - 2), planeBytes, MPI_BYTE, higher, kToHigher, MPI_COMM_WORLD, &reqs.back()), "Isend");
            }
            // A large message over shared memory moves a bounded number of fragments per progress call, so
            // between planes the requests are tested repeatedly (each test is cheap) for the transfer to
            // keep pace with the planes instead of waiting for the end of the step.
            int flag = 0;
            for (int x = 1; x < X - 1; ++x) {
                slab->stepPlanes(x, x + 1);
                for (int i = 0; i < kTestsBetweenPlanes && !flag && !reqs.empty(); ++i)
                    checkMpi(MPI_Testall(int(reqs.size()), reqs.data(), &flag, MPI_STATUSES_IGNORE), "Testall");
            }
            if (flag) reqs.clear();
            const Clock::time_point ti = Clock::now();
            // The first exchange of a solve also waits for the neighbours to have built their slabs.
            waitAll(reqs, g_timeout + 3.0 * std::max(slowestStep, since(t0)), who);
            const Clock::time_point tw = Clock::now();
            slab->stepPlanes(0, 1);
            slab->stepPlanes(X - 1, X);
            slab->finishStep();
            const Clock::time_point te = Clock::now();
            st.interiorSeconds += std::chrono::duration<double>(ti - ts).count();
            st.waitSeconds += std::chrono::duration<double>(tw - ti).count();
            st.edgeSeconds += std::chrono::duration<double>(te - tw).count();
            slowestStep = std::max(slowestStep, std::chrono::duration<double>(te - ts).count());
            if (progress && rank == 0)
                progress->report((double(s) + double(t + 1) / double(steps)) / double(solves.size()),
                                 "LB step " + std::to_string(t + 1) + "/" + std::to_string(steps) + " on " + std::to_string(ranks) +
                                     " ranks" + (solves.size() > 1 ? " (channel solve " + std::to_string(s + 1) + "/" + std::to_string(solves.size()) + ")" : ""));
        }
        // The totals to rank 0, which places every rank's planes in the grid.
        const Clock::time_point tg = Clock::now();
        slab->totals(tot);
        const size_t count = size_t(sendHi - sendLo) * planeNodes;
        if (count > size_t(INT_MAX)) throw Error("a slab's totals are too large for one MPI message");
        if (rank != 0) {
            reqs.emplace_back();
            checkMpi(MPI_Isend(tot.data() + size_t(sendLo) * planeNodes, int(count), MPI_FLOAT, 0, kTotals, MPI_COMM_WORLD, &reqs.back()), "Isend");
            waitAll(reqs, g_timeout + 3.0 * since(t0), rankText(rank) + ": rank 0 took no lighting totals");
        } else {
            all.assign(density.geometry.nodeCount(), 0.0f);
            std::copy(tot.begin() + long(size_t(sendLo) * planeNodes), tot.begin() + long(size_t(sendHi) * planeNodes),
                      all.begin() + long(size_t(globalLo) * planeNodes));
            for (int r = 1; r < ranks; ++r) {
                const lb::SlabRange o = lb::slabOwned(dims.x, r, ranks);
                const int g0 = o.begin, g1 = r + 1 < ranks ? o.end : dims.x;
                reqs.emplace_back();
                checkMpi(MPI_Irecv(all.data() + size_t(g0) * planeNodes, int(size_t(g1 - g0) * planeNodes), MPI_FLOAT, r, kTotals,
                                   MPI_COMM_WORLD, &reqs.back()),
                         "Irecv");
            }
            waitAll(reqs, g_timeout + 3.0 * since(t0), "rank 0: the lighting totals did not arrive from every rank");
            for (int c = 0; c < 3; ++c) {
                if (solveOf[c] != int(s)) continue;
                const float intensity = params.intensity[c];
                for (size_t n = 0; n < all.size(); ++n) out.rgb[n * 3 + size_t(c)] = all[n] * intensity;
            }
        }
        st.gatherSeconds += since(tg);
    }
    st.seconds = since(t0);
    if (stats) *stats = st;
    return out;
}

int runLightSession(const std::function<int(int rank, int ranks)>& body, double timeoutSeconds)
{
    g_timeout = timeoutSeconds;
    return runSession("light", "no lighting grid was written", [&](int rank, int size, const std::vector<std::string>&) {
        try {
            return body(rank, size);
        } catch (const Cancelled&) {
            throw;
        } catch (const std::exception& e) {
            // An error on any rank ends every rank: the others would wait for its halos.
            endJob(rankText(rank) + " on " + thisHost() + ": " + e.what());
        }
    }, timeoutSeconds);
}

} // namespace sylva::mpi
