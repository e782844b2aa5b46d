// LB solve benchmark: 128^3 RGB leaf lighting, fp32/fp16 x fixed/tolerance, against the memory-bandwidth floor measured in the same run.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <random>
#include <string>
#include <vector>

#include <tbb/parallel_for.h>

#include "core/grid/grid.h"
#include "core/lb/lb_basis.h"
#include "core/grid/grid_compare.h"
#include "core/lb/lb_params.h"
#include "core/lb/lb_solver.h"
#include "core/voxel/voxelize.h"
#include "pipeline/grow/tree_grower.h"

using namespace sylva;
using namespace sylva::lb;

namespace {

double now()
{
    return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

// A tree-like density: an ellipsoidal crown of random leaf clusters over a wooden trunk, empty margin.
DensityGrid treeLikeGrid(int n, uint32_t seed)
{
    DensityGrid g;
    g.geometry.dims = {n, n, n};
    g.density.assign(g.geometry.nodeCount(), 0.0f);
    g.woodFraction.assign(g.geometry.nodeCount(), 0.0f);
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    const float c = 0.5f * float(n - 1);
    for (int i = 1; i < n - 1; ++i)
        for (int j = 1; j < n - 1; ++j)
            for (int k = 1; k < n - 1; ++k) {
                const float x = (float(i) - c) / (0.45f * float(n)), y = (float(j) - 0.62f * float(n)) / (0.36f * float(n)),
                            z = (float(k) - c) / (0.45f * float(n));
                const size_t node = g.geometry.index(i, j, k);
                if (x * x + y * y + z * z < 1.0f && u(rng) < 0.55f) g.density[node] = u(rng) * 0.7f;
                const float r = std::hypot(float(i) - c, float(k) - c);
                if (r < 0.03f * float(n) && j < int(0.7f * float(n))) {
                    g.density[node] = 1.0f;
                    g.woodFraction[node] = 1.0f;
                }
            }
    return g;
}

// Memory floor: time to stream `bytes` through memory once (read half, write half), best of several.
double copySeconds(size_t bytes)
{
    const size_t n = bytes / 2 / sizeof(float);
    std::vector<float> a(n, 1.0f), b(n, 0.0f);
    double best = 1e30;
    for (int rep = 0; rep < 5; ++rep) {
        const double t0 = now();
        tbb::parallel_for(tbb::blocked_range<size_t>(0, n, 1 << 16), [&](const tbb::blocked_range<size_t>& r) {
            std::memcpy(&b[r.begin()], &a[r.begin()], (r.end() - r.begin()) * sizeof(float));
        });
        best = std::min(best, now() - t0);
    }
    return best;
}

struct Row {
    std::string name;
    double seconds;
    int steps;
    double error;
    double bytesPerStep;
};

} // namespace

int main(int argc, char** argv)
{
    int n = 128, reps = 1;
    double tol = 2e-4;
    bool dense = false, grown = false, coarseOnly = false, cliOnly = false, relightOnly = false;
    for (int a = 1; a < argc; ++a) {
        std::string s = argv[a];
        if (s == "--grid" && a + 1 < argc) n = std::atoi(argv[++a]);
        else if (s == "--reps" && a + 1 < argc) reps = std::atoi(argv[++a]);
        else if (s == "--tol" && a + 1 < argc) tol = std::atof(argv[++a]);
        else if (s == "--dense") dense = true;
        else if (s == "--grown") grown = true;
        else if (s == "--coarse-only") coarseOnly = true;
        else if (s == "--cli-only") cliOnly = true;
        else if (s == "--relight") relightOnly = true;
        else {
            std::printf("usage: bench_lb [--grid N] [--reps R] [--tol T] [--dense | --grown] [--coarse-only | --cli-only | --relight]\n");
            return s == "--help" ? 0 : 2;
        }
    }
    DensityGrid grid = treeLikeGrid(n, 42);
    if (dense) std::fill(grid.density.begin(), grid.density.end(), 1.0f);
    if (grown) {   // the main job's default tree: broadleaf, seed 1, 200k triangles, voxelized at N
        GrowOptions g;
        g.targetTriangles = 200000;
        VoxelizeSettings v;
        v.longestAxisNodes = n;
        grid = voxelize(growTree(g).mesh, v);
    }
    size_t occupied = 0;
    for (float r : grid.density) occupied += r > 0.0f;
    const glm::ivec3 dd = grid.geometry.dims;
    std::printf("LB benchmark: %dx%dx%d grid, %s, %.1f%% of nodes with medium, leaf preset (3 distinct channels), sun (0.3,1,0.2)\n",
                dd.x, dd.y, dd.z, grown ? "grown default tree" : (dense ? "dense medium" : "tree-like crown"),
                100.0 * double(occupied) / double(grid.density.size()));

    LbParams base = paramsFromPreset(*findPreset("leaf"));
    base.sun = {0.3f, 1.0f, 0.2f};

    auto run = [&](const char* name, LbParams p, const LightingGrid* ref, LightingGrid* keep) {
        std::vector<double> times;
        SolveStats st;
        LightingGrid out;
        for (int r = 0; r < reps; ++r) {
            out = solveLighting(grid, p, nullptr, &st);
            times.push_back(st.seconds);
        }
        std::sort(times.begin(), times.end());
        Row row{name, times[times.size() / 2], st.steps, ref ? relativeL2(out, *ref) : 0.0, st.bytesPerStep};
        std::printf("  %-22s %8.3f s  %4d steps  %6.2f ms/step  rel L2 vs fp32 default %.2e  %.0f MB/step", name,
                    row.seconds, row.steps, 1e3 * row.seconds / row.steps, row.error, row.bytesPerStep / 1e6);
        if (st.coarseSteps > 0) std::printf("  (+%d steps on coarser grids)", st.coarseSteps);
        std::printf("\n");
        std::fflush(stdout);
        if (keep) *keep = std::move(out);
        return row;
    };

    if (relightOnly) {
        // Relighting by linearity: the basis of sylva light's default configuration, then
        // random suns composed from it against a direct solve of each, side by side.
        LbParams p = base;
        useFrontDefaults(p);
        std::vector<int> dirs = basisDirections(BasisSet::All);
        std::vector<LightingGrid> basis;
        const auto tb = std::chrono::steady_clock::now();
        for (int m : dirs) basis.push_back(solveLighting(grid, basisParams(p, m)));
        const double basisSeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - tb).count();
        std::vector<const LightingGrid*> ptrs;
        double bytes = 0.0;
        for (const LightingGrid& g : basis) ptrs.push_back(&g), bytes += double(g.rgb.size()) * sizeof(float);
        std::mt19937 rng(7);
        std::normal_distribution<float> nd(0.0f, 1.0f);
        std::vector<double> relightTimes, solveTimes;
        double worst = 0.0;
        for (int t = 0; t < 5; ++t) {
            p.sun = {nd(rng), std::fabs(nd(rng)) + 0.1f, nd(rng)};
            const BoundaryWeights w = sunWeights(p.sun, p.intensity);
            LightingGrid relit;
            for (int r = 0; r < 5; ++r) {
                const auto t0 = std::chrono::steady_clock::now();
                relit = composeLighting(dirs, ptrs, w);
                relightTimes.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
            }
            SolveStats st;
            const LightingGrid direct = solveLighting(grid, p, nullptr, &st);
            solveTimes.push_back(st.seconds);
            worst = std::max(worst, relativeL2(relit, direct));
        }
        std::sort(relightTimes.begin(), relightTimes.end());
        std::sort(solveTimes.begin(), solveTimes.end());
        const double relight = relightTimes[relightTimes.size() / 2], solve = solveTimes[solveTimes.size() / 2];
        std::printf("relight from an 18-direction basis (fp16, 1 x edge): %.2f ms median, direct solve %.3f s (%.0fx); basis "
                    "build %.2f s (%.1f solves' time), %.1f MB as fp32 grids (%.1f MB as fp16); worst rel L2 vs direct %.2e\n",
                    1e3 * relight, solve, solve / relight, basisSeconds, basisSeconds / solve, bytes / 1e6, bytes / 2e6, worst);
        std::printf("lb_relight_ms=%.3f\nlb_relight_direct_s=%.4f\nlb_relight_basis_build_s=%.3f\nlb_relight_basis_mb=%.2f\nlb_relight_err=%.3e\n",
                    1e3 * relight, solve, basisSeconds, bytes / 1e6, worst);
        return 0;
    }

    LightingGrid reference;
    Row fp32 = run("fp32 default steps", base, nullptr, &reference);
    LbParams p16 = base;
    p16.storage = Storage::Fp16;
    // sylva light's default (useFrontDefaults) against the fp32 streaming floor of the seed's configuration,
    // both measured in this run (target: <= 0.33 x the floor at <= 1% from the seed's result).
    {
        LbParams cli = base;
        useFrontDefaults(cli);
        const Row def = run("sylva light default", cli, &reference, nullptr);
        LbParams cliWarm = cli;
        cliWarm.warmStart = true;
        const Row warm = run("default + warm start", cliWarm, &reference, nullptr);
        const double floor32 = copySeconds(size_t(fp32.bytesPerStep)) * fp32.steps;
        std::printf("fp32 streaming floor of the seed's configuration (%d steps): %.3f s\n", fp32.steps, floor32);
        std::printf("lb_cli_default_s=%.4f\nlb_cli_default_steps=%d\nlb_cli_default_err=%.3e\nlb_cli_default_vs_floor=%.3f\n", def.seconds,
                    def.steps, def.error, def.seconds / floor32);
        std::printf("lb_cli_warm_s=%.4f\nlb_cli_warm_err=%.3e\nlb_cli_warm_vs_floor=%.3f\n", warm.seconds, warm.error, warm.seconds / floor32);
        std::printf("lb_seed_s=%.4f\nlb_seed_vs_floor=%.3f\nlb_floor_seed_s=%.4f\n", fp32.seconds, fp32.seconds / floor32, floor32);
        if (cliOnly) return 0;
    }
    if (coarseOnly) {
        // Only the coarse-start rows (with the fp32 reference above), for quick experiments.
        for (double t : {1e-3, 3e-3, 1e-2}) {
            LbParams q = p16;
            q.coarseStart = true;
            q.tolerance = t;
            char name[64];
            std::snprintf(name, sizeof name, "fp16 coarse tol %.0e", t);
            run(name, q, &reference, nullptr);
        }
        return 0;
    }
    Row fp16 = run("fp16 default steps", p16, &reference, nullptr);
    LbParams t32 = base;
    t32.tolerance = tol;
    Row tol32 = run("fp32 tolerance", t32, &reference, nullptr);
    LbParams t16 = p16;
    t16.tolerance = tol;
    Row tol16 = run("fp16 tolerance", t16, &reference, nullptr);
    LbParams w16 = t16;
    w16.warmStart = true;
    Row warm16 = run("fp16 tolerance warm", w16, &reference, nullptr);

    // Tolerance sweep, fp16 + warm start: the accuracy each tolerance buys and what it costs.
    std::vector<Row> sweep;
    for (double t : {1e-4, 3e-4, 1e-3, 3e-3}) {
        LbParams q = w16;
        q.tolerance = t;
        char name[64];
        std::snprintf(name, sizeof name, "fp16 warm tol %.0e", t);
        sweep.push_back(run(name, q, &reference, nullptr));
    }

    // Coarse start: the solve on grids of half, quarter ... resolution first, interpolated as the start.
    std::vector<Row> coarse;
    for (double t : {3e-4, 1e-3, 3e-3, 1e-2}) {
        LbParams q = t16;
        q.coarseStart = true;
        q.tolerance = t;
        char name[64];
        std::snprintf(name, sizeof name, "fp16 coarse tol %.0e", t);
        coarse.push_back(run(name, q, &reference, nullptr));
    }

    const double floorStep32 = copySeconds(size_t(fp32.bytesPerStep));
    const double floorStep16 = copySeconds(size_t(fp16.bytesPerStep));
    std::printf("memory floor (parallel memcpy of the same bytes): fp32 %.2f ms/step (%.1f GB/s), fp16 %.2f ms/step\n",
                1e3 * floorStep32, fp32.bytesPerStep / floorStep32 / 1e9, 1e3 * floorStep16);
    std::printf("  fp32 default: %.2fx the floor for its steps; fp16 tolerance: %.2fx the fp32 default-step floor\n",
                fp32.seconds / (floorStep32 * fp32.steps), tol16.seconds / (floorStep32 * fp32.steps));

    std::printf("lb_grid=%d\n", n);
    std::printf("lb_fp32_default_s=%.4f\nlb_fp32_default_steps=%d\n", fp32.seconds, fp32.steps);
    std::printf("lb_fp16_default_s=%.4f\nlb_fp16_default_err=%.3e\n", fp16.seconds, fp16.error);
    std::printf("lb_fp32_tol_s=%.4f\nlb_fp32_tol_steps=%d\nlb_fp32_tol_err=%.3e\n", tol32.seconds, tol32.steps, tol32.error);
    std::printf("lb_fp16_tol_s=%.4f\nlb_fp16_tol_steps=%d\nlb_fp16_tol_err=%.3e\n", tol16.seconds, tol16.steps, tol16.error);
    std::printf("lb_bytes_per_step_fp32=%.0f\nlb_bytes_per_step_fp16=%.0f\n", fp32.bytesPerStep, fp16.bytesPerStep);
    std::printf("lb_floor_fp32_default_s=%.4f\nlb_floor_gbps=%.2f\n", floorStep32 * fp32.steps, fp32.bytesPerStep / floorStep32 / 1e9);
    std::printf("lb_fp16_tol_warm_s=%.4f\nlb_fp16_tol_warm_steps=%d\nlb_fp16_tol_warm_err=%.3e\n", warm16.seconds, warm16.steps,
                warm16.error);
    for (const Row& r : sweep) {
        const std::string tag = r.name.substr(r.name.rfind(' ') + 1);
        std::printf("lb_fp16_warm_tol_%s_s=%.4f\nlb_fp16_warm_tol_%s_steps=%d\nlb_fp16_warm_tol_%s_err=%.3e\n", tag.c_str(), r.seconds,
                    tag.c_str(), r.steps, tag.c_str(), r.error);
    }
    for (const Row& r : coarse) {
        const std::string tag = r.name.substr(r.name.rfind(' ') + 1);
        std::printf("lb_fp16_coarse_tol_%s_s=%.4f\nlb_fp16_coarse_tol_%s_steps=%d\nlb_fp16_coarse_tol_%s_err=%.3e\n", tag.c_str(),
                    r.seconds, tag.c_str(), r.steps, tag.c_str(), r.error);
    }
    std::printf("lb_speedup_fp16_tol_vs_fp32_default=%.2f\n", fp32.seconds / tol16.seconds);
    std::printf("lb_speedup_fp16_tol_warm_vs_fp32_default=%.2f\n", fp32.seconds / warm16.seconds);
    return 0;
}
