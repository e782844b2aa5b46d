// The distributed LB grid (sylva light --mpi): run under mpirun -np 2. In one run it measures, per step,
// the planes that need no halo (the halo messages in flight), the wait for the halos after them and
// the two planes beside them, on a slab of PLANES planes per rank of a Y x Z cross-section filled with
// medium (every row collides: the dearest plane); then, alone, the halo exchange of the same planes
// (both ranks send one plane and receive one, as a step does, no update beside it). From the measured
// cost of a plane and of a halo exchange it simulates one step of an X x Y x Z grid (default the
// target size, 1024 x 512 x 512) on 2 to 16 ranks:
//   T(N) = (P + 2) t_plane + max(0, t_halo(N) - P t_plane)   (overlapped: the halos travel while the
//          P = ceil((X - 2) / N) owned planes are stepped; the two halo planes are stepped after)
//   t_halo(N) = t_halo at N = 2 (one neighbour), 2 t_halo beyond (two neighbours, the same link)
// beside the same without overlap ((P + 2) t_plane + t_halo(N)) and with t_single for t_plane, against the single process's step,
// X t_single (its cost a plane measured on the same grid in the same run, both ranks solving it at
// once, setup excluded: whole-grid
// solves step in cache-blocked wavefronts, slabs one plane at a time; at 512 x 512 a wavefront is one
// plane deep, so the two should agree).
// Each rank runs 1 thread (the 2-core machine); ends with name=value lines.
//
//   mpirun --oversubscribe --bind-to none -np 2 bench_mpi_lb [--yz 512] [--planes 8] [--steps 8] [--fp32] [--x 1024]
#include <mpi.h>

#include <tbb/global_control.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <thread>
#include <vector>

#include "core/lb/lb_params.h"
#include "core/lb/lb_solver.h"
#include "pipeline/mpi/mpi_lb.h"

using namespace sylva;
using Clock = std::chrono::steady_clock;

namespace {

double median(std::vector<double> v)
{
    std::sort(v.begin(), v.end());
    return v.empty() ? 0.0 : v[v.size() / 2];
}

int argInt(int argc, char** argv, const char* name, int fallback)
{
    for (int i = 1; i + 1 < argc; ++i)
        if (std::strcmp(argv[i], name) == 0) return std::atoi(argv[i + 1]);
    return fallback;
}

bool argFlag(int argc, char** argv, const char* name)
{
    for (int i = 1; i < argc; ++i)
        if (std::strcmp(argv[i], name) == 0) return true;
    return false;
}

} // namespace

int main(int argc, char** argv)
{
    const int yz = argInt(argc, argv, "--yz", 512), planes = argInt(argc, argv, "--planes", 8), steps = argInt(argc, argv, "--steps", 8);
    const int bigX = argInt(argc, argv, "--x", 1024);
    const bool fp32 = argFlag(argc, argv, "--fp32");
    tbb::global_control one(tbb::global_control::max_allowed_parallelism, 1);
    return mpi::runLightSession([&](int rank, int ranks) {
        if (ranks != 2) throw std::runtime_error("bench_mpi_lb runs on 2 ranks (mpirun -np 2)");
        // Medium everywhere inside: every row of a plane collides.
        DensityGrid d;
        d.geometry.dims = {2 * planes + 2, yz, yz};
        d.density.assign(d.geometry.nodeCount(), 0.0f);
        for (int i = 1; i < d.geometry.dims.x - 1; ++i)
            for (int j = 1; j < yz - 1; ++j)
                for (int k = 1; k < yz - 1; ++k) d.density[d.geometry.index(i, j, k)] = 0.3f + 0.4f * float((i + j + k) % 7) / 7.0f;
        lb::LbParams p = lb::paramsFromPreset(*lb::findPreset("cloud"));
        p.storage = fp32 ? lb::Storage::Fp32 : lb::Storage::Fp16;
        p.steps = steps;
        mpi::DistributedStats st;
        (void)mpi::solveDistributed(d, p, nullptr, &st);
        // Per step and per channel solve (the cloud's three channels share one solve).
        const double perStep = double(st.steps) * double(st.solves);
        const double interior = st.interiorSeconds / perStep, wait = st.waitSeconds / perStep, edge = st.edgeSeconds / perStep;
        const double tPlane = interior / double(st.ownedPlanes);

        // The halo exchange alone: one plane each way, as a step posts it, repeated.
        std::vector<char> out(st.planeBytes, 1), in(st.planeBytes, 0);
        const int peer = 1 - rank;
        std::vector<double> ex;
        for (int r = 0; r < 15; ++r) {
            MPI_Barrier(MPI_COMM_WORLD);
            const Clock::time_point t0 = Clock::now();
            MPI_Request req[2];
            MPI_Irecv(in.data(), int(in.size()), MPI_BYTE, peer, 7, MPI_COMM_WORLD, &req[0]);
            MPI_Isend(out.data(), int(out.size()), MPI_BYTE, peer, 7, MPI_COMM_WORLD, &req[1]);
            MPI_Waitall(2, req, MPI_STATUSES_IGNORE);
            ex.push_back(std::chrono::duration<double>(Clock::now() - t0).count());
        }
        const double tHalo = median(ex);
        // The single process on the same grid (its cache-blocked wavefront), rank 0 alone: its cost a plane
        // is the simulation's one-process step.
        // Its setup (allocation, first touch, boundary fill) is left out: the median time between its
        // progress reports, one after each step (a 512 x 512 wavefront is one plane deep). Both ranks solve
        // at once, so the memory bandwidth is shared as in the distributed run (ranks on nodes of their
        // own would each have all of it).
        double tSinglePlane = 0.0;
        {
            std::vector<Clock::time_point> marks;
            Progress prog([&](double, const std::string&) { marks.push_back(Clock::now()); });
            lb::LbParams more = p;
            more.steps = 2 * steps;
            MPI_Barrier(MPI_COMM_WORLD);
            lb::SolveStats ss;
            (void)lb::solveLighting(d, more, &prog, &ss);
            std::vector<double> dt;
            for (size_t i = 1; i < marks.size(); ++i) dt.push_back(std::chrono::duration<double>(marks[i] - marks[i - 1]).count());
            if (ss.blockSteps != 1) throw std::runtime_error("the single solve's wavefront is deeper than one step: use a larger --yz");
            tSinglePlane = median(dt) / double(ss.channelSolves) / double(d.geometry.dims.x);
        }
        MPI_Request done;
        MPI_Ibarrier(MPI_COMM_WORLD, &done);
        for (int flag = 0; !flag;) {
            MPI_Test(&done, &flag, MPI_STATUS_IGNORE);
            if (!flag) std::this_thread::sleep_for(std::chrono::milliseconds(1));
        }
        // Rank 0 reports; its numbers and rank 1's are close (same slab size), rank 0's are printed.
        if (rank != 0) return 0;
        std::printf("slab: %d planes of %d x %d per rank, %s, %d steps, 1 thread per rank; halo plane %.2f MB\n", st.ownedPlanes, yz, yz,
                    fp32 ? "fp32" : "fp16", st.steps, double(st.planeBytes) / 1e6);
        std::printf("per step on rank 0: interior %.2f ms (%.3f ms a plane), halo wait after it %.3f ms, 2 planes beside the halos %.2f ms\n",
                    interior * 1e3, tPlane * 1e3, wait * 1e3, edge * 1e3);
        std::printf("halo exchange alone (1 plane each way, median of 15): %.3f ms = %.2f GB/s each way\n", tHalo * 1e3,
                    double(st.planeBytes) / tHalo / 1e9);
        const double nodes = double(bigX) * yz * yz;
        std::printf("single process on the same grid: %.3f ms a plane (slab stepping: %.3f ms, ratio %.3f)\n", tSinglePlane * 1e3, tPlane * 1e3,
                    tPlane / tSinglePlane);
        const double single = double(bigX) * tSinglePlane;
        std::printf("\nsimulated step of %d x %d x %d (%s, %.1f GB of distributions), 1 thread a rank: single process %.2f s\n", bigX, yz, yz,
                    fp32 ? "fp32" : "fp16", nodes * 19 * 2 * (fp32 ? 4 : 2) / 1e9, single);
        std::printf("ranks  planes/rank  step_s   speedup  efficiency  speedup_without_overlap  at_single_plane  GB/rank\n");
        struct Row {
            int n, P;
            double t, tNo, tIdeal, gb;
        };
        std::vector<Row> rows;
        for (int n : {2, 4, 8, 16}) {
            const int P = (bigX - 2 + n - 1) / n;
            const double halo = n == 2 ? tHalo : 2.0 * tHalo;
            const double t = double(P + 2) * tPlane + std::max(0.0, halo - double(P) * tPlane);
            const double tNo = double(P + 2) * tPlane + halo;
            // The same with a slab's plane costing what the single process's does.
            const double tIdeal = double(P + 2) * tSinglePlane + std::max(0.0, halo - double(P) * tSinglePlane);
            rows.push_back({n, P, t, tNo, tIdeal, double(P + 2) * yz * yz * 19 * 2 * (fp32 ? 4 : 2) / 1e9});
            std::printf("%5d  %11d  %6.3f  %7.2f  %10.3f  %23.2f  %16.2f  %7.2f\n", n, P, t, single / t, single / t / n, single / tNo,
                        single / tIdeal, rows.back().gb);
        }
        std::printf("halo_plane_mb=%.3f\nhalo_exchange_ms=%.3f\nstep_interior_ms=%.3f\nstep_halo_wait_ms=%.3f\nstep_edge_ms=%.3f\nplane_update_ms=%.4f\n",
                    double(st.planeBytes) / 1e6, tHalo * 1e3, interior * 1e3, wait * 1e3, edge * 1e3, tPlane * 1e3);
        std::printf("halo_vs_interior=%.4f\nsingle_plane_ms=%.4f\n", tHalo / interior, tSinglePlane * 1e3);
        for (const Row& r : rows)
            std::printf("sim_%d_speedup=%.3f\nsim_%d_efficiency=%.4f\nsim_%d_speedup_no_overlap=%.3f\nsim_%d_speedup_at_single_plane=%.3f\n", r.n,
                        single / r.t, r.n, single / r.t / r.n, r.n, single / r.tNo, r.n, single / r.tIdeal);
        return 0;
    });
}
