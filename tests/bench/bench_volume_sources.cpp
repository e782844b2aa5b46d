// Volume source benchmarks: one smoke simulation step at 128^3 against the memory-streaming floor of
// the bytes it moves, and the LB solve of Geist & Westall's ("Lattice-Boltzmann Lighting Models") cloud (256 x
// 128^2, cloud preset) against the fp32 streaming floor, both floors measured in the same run (as bench_lb
// does). Ends with name=value lines.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <string>
#include <ctime>
#include <vector>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "bench_timing.h"
#include "core/grid/grid.h"
#include "core/lb/lb_params.h"
#include "core/lb/lb_solver.h"
#include "core/volume/pyroclastic.h"
#include "core/volume/smoke.h"

using namespace sylva;

namespace {

// Time to stream `bytes` through memory once (read half, write half), best of five.
double copySeconds(size_t bytes)
{
    const size_t n = std::max<size_t>(1, bytes / 2 / sizeof(float));
    std::vector<float> a(n, 1.0f), b(n, 0.0f);
    double best = 1e30;
    for (int rep = 0; rep < 5; ++rep) {
        const double t0 = bench::now();
        tbb::parallel_for(tbb::blocked_range<size_t>(0, n, 1 << 16), [&](const tbb::blocked_range<size_t>& r) {
            std::memcpy(&b[r.begin()], &a[r.begin()], (r.end() - r.begin()) * sizeof(float));
        });
        best = std::min(best, bench::now() - t0);
    }
    return best;
}

// Geist & Westall's cloud grid: two pyroclastic clouds side by side on 256 x 128 x 128 nodes.
DensityGrid cloud256()
{
    DensityGrid g;
    g.geometry.dims = {256, 128, 128};
    g.geometry.spacing = 1.0 / 126.0;
    g.density.assign(g.geometry.nodeCount(), 0.0f);
    g.woodFraction.assign(g.geometry.nodeCount(), 0.0f);
    for (int half = 0; half < 2; ++half) {
        volume::PyroclasticParams p;
        p.radius = 0.42f;
        p.amplitude = 0.22f;
        p.frequency = 3.0f;
        p.resolution = 128;
        p.seed = uint64_t(7 + half);
        const DensityGrid c = volume::makePyroclasticCloud(p);
        for (int i = 0; i < 128; ++i)
            for (int j = 0; j < 128; ++j)
                for (int k = 0; k < 128; ++k) g.density[g.geometry.index(128 * half + i, j, k)] = c.density[c.geometry.index(i, j, k)];
    }
    return g;
}

// Processor seconds of this process (all threads): what a step costs independent of other load.
double cpuSeconds()
{
    timespec t{};
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
    return double(t.tv_sec) + 1e-9 * double(t.tv_nsec);
}

} // namespace

int main(int argc, char** argv)
{
    bool sim = true, lb = true;
    int n = 128, reps = 3;
    double tol = volume::SmokeSettings{}.pressureTolerance;
    for (int a = 1; a < argc; ++a) {
        const std::string s = argv[a];
        if (s == "--sim-only") lb = false;
        else if (s == "--lb-only") sim = false;
        else if (s == "--grid" && a + 1 < argc) n = std::atoi(argv[++a]);
        else if (s == "--reps" && a + 1 < argc) reps = std::atoi(argv[++a]);
        else if (s == "--tol" && a + 1 < argc) tol = std::atof(argv[++a]);
        else {
            std::printf("usage: bench_volume [--sim-only | --lb-only] [--grid N (simulation, default 128)] [--reps R] [--tol T (pressure, default 1e-6)]\n");
            return s == "--help" ? 0 : 2;
        }
    }
    if (sim) {
        volume::SmokeSettings s;
        s.cells = glm::ivec3(n);
        s.cellSize = 1.0f / float(n);
        s.dt = 0.02f;
        s.pressureTolerance = tol;
        volume::SmokeSource src;
        src.shape.centre = glm::vec3(0.5f, 0.12f, 0.5f);
        src.shape.radius = 0.1f;
        s.sources.push_back(src);
        for (const auto interp : {volume::SmokeInterp::Linear, volume::SmokeInterp::MonotonicCubic}) {
            s.interp = interp;
            volume::SmokeSim smoke(s);
            for (int w = 0; w < 5; ++w) smoke.step();   // a rising plume, a warm pressure start
            double iterations = 0.0;
            const double cpu0 = cpuSeconds();
            const bench::Timing t = bench::timeReps(reps, [&] {
                smoke.step();
                iterations += smoke.lastStats().pressureIterations;
            });
            iterations /= std::max(1, reps);
            const double cpuPerStep = (cpuSeconds() - cpu0) / std::max(1, reps);
            // Bytes a step must move at least (each array read or written once per pass): forces and
            // vorticity ~ 120 B/cell, the two advections ~ 64 B/cell, each CG iteration ~ 250 B/cell: the
            // double vectors ~ 100 (operator with x.q, the fused update writing the V-cycle's float input,
            // r.z, the direction update) and the float V-cycle ~ 150 (on the finest level 8 red-black
            // sweeps of 13 B, residual, transfers; the coarser levels an eighth of it each).
            const double cells = double(n) * n * n;
            const double bytes = cells * (184.0 + 250.0 * iterations);
            const double floor = copySeconds(size_t(bytes));
            const char* name = interp == volume::SmokeInterp::Linear ? "linear" : "cubic";
            std::printf("smoke step %d^3 (%s, pressure tolerance %g): %.3f s median of %d (min %.3f), %.2f processor s per step, %.1f pressure "
                        "iterations; streaming floor of %.0f MB %.3f s (%.1fx the floor)\n",
                        n, name, tol, t.median, reps, t.min, cpuPerStep, iterations, bytes / 1e6, floor, t.median / floor);
            const volume::SmokeStepStats& st = smoke.lastStats();
            const double divRatio = st.divergenceBefore > 0.0 ? st.divergenceAfter / st.divergenceBefore : 0.0;
            std::printf("  divergence after / before the last projection: %.2e\n", divRatio);
            std::printf("smoke_step_%s_divergence_ratio=%.3e\n", name, divRatio);
            std::printf("smoke_step_%s_cpu_s=%.3f\n", name, cpuPerStep);
            std::printf("smoke_step_%s_s=%.4f\nsmoke_step_%s_iterations=%.1f\nsmoke_step_%s_floor_s=%.4f\nsmoke_step_%s_vs_floor=%.2f\n", name,
                        t.median, name, iterations, name, floor, name, t.median / floor);
            std::fflush(stdout);
        }
    }
    if (lb) {
        const DensityGrid grid = cloud256();
        size_t occupied = 0;
        for (float r : grid.density) occupied += r > 0.0f;
        std::printf("LB of the cloud, 256x128x128, cloud preset (one channel solve), %.1f%% of nodes with medium\n",
                    100.0 * double(occupied) / double(grid.density.size()));
        lb::LbParams seedCfg = lb::paramsFromPreset(*lb::findPreset("cloud"));
        seedCfg.sun = {0.3f, 1.0f, 0.2f};
        lb::LbParams cli = seedCfg;
        lb::useFrontDefaults(cli);
        auto run = [&](const char* name, const lb::LbParams& p, lb::SolveStats& st, LightingGrid& out) {
            std::vector<double> times;
            for (int r = 0; r < std::max(1, reps / 2); ++r) {
                out = lb::solveLighting(grid, p, nullptr, &st);
                times.push_back(st.seconds);
            }
            std::sort(times.begin(), times.end());
            std::printf("  %-26s %8.3f s  %4d steps  %.0f MB/step\n", name, times[times.size() / 2], st.steps, st.bytesPerStep / 1e6);
            std::fflush(stdout);
            return times[times.size() / 2];
        };
        lb::SolveStats s32, sDef;
        LightingGrid ref, def;
        const double t32 = run("seed (fp32, 2 x edge)", seedCfg, s32, ref);
        const double tDef = run("sylva light default", cli, sDef, def);
        double num = 0.0, den = 0.0;
        for (size_t i = 0; i < ref.rgb.size(); ++i) {
            num += (double(def.rgb[i]) - ref.rgb[i]) * (double(def.rgb[i]) - ref.rgb[i]);
            den += double(ref.rgb[i]) * ref.rgb[i];
        }
        const double err = std::sqrt(num / den);
        const double floor32 = copySeconds(size_t(s32.bytesPerStep)) * s32.steps;
        std::printf("fp32 streaming floor of the seed's configuration (%d steps): %.3f s; default rel L2 vs seed %.2e\n", s32.steps, floor32, err);
        std::printf("lb_cloud_seed_s=%.4f\nlb_cloud_seed_vs_floor=%.3f\nlb_cloud_default_s=%.4f\nlb_cloud_default_vs_floor=%.3f\n"
                    "lb_cloud_default_err=%.3e\nlb_cloud_floor_s=%.4f\n",
                    t32, t32 / floor32, tDef, tDef / floor32, err, floor32);
    }
    return 0;
}
