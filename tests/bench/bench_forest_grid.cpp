// The forest-level LB grid on the default forest (issue 18 item 1): build + solve time at a few resolutions,
// with the factor range it gives. Species densities come from loadSpeciesGrids (through a grid cache in
// $TMPDIR so reruns skip the per-species solves); only the timed part is the forest grid.
#include <algorithm>
#include <chrono>
#include <ctime>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "core/lb/forest_grid.h"
#include "pipeline/cache/grid_cache.h"
#include "pipeline/render/render_job.h"

using namespace sylva;

int main(int argc, char** argv)
{
    int reps = 3;
    for (int a = 1; a < argc; ++a) {
        const std::string s = argv[a];
        if (s == "--reps" && a + 1 < argc) reps = std::atoi(argv[++a]);
        else {
            std::printf("usage: bench_forest_grid [--reps R]\n");
            return s == "--help" ? 0 : 2;
        }
    }
    const Scene scene = defaultScene();
    const char* tmp = std::getenv("TMPDIR");
    GridCache cache(std::string(tmp ? tmp : "/tmp") + "/sylva_bench_forest_grid_cache");
    std::vector<lb::ForestSpecies> species;
    for (size_t s = 0; s < scene.species.size(); ++s) species.push_back(lb::forestSpecies(loadSpeciesGrids(scene, s, &cache).density));
    std::vector<lb::ForestPlant> plants;
    size_t grouped = 0;
    for (const InstanceDesc& in : scene.instances) {
        if (in.group != kNoGroup) {
            ++grouped;
            continue;
        }
        plants.push_back({in.position, in.scale, int(in.species)});
    }
    lb::LbParams p = scene.species.empty() ? lb::paramsFromPreset(*lb::findPreset("leaf")) : scene.species[0].lighting;
    p.sun = scene.sun.direction;
    std::printf("forest grid on the default forest: %zu instances, %zu species (%zu group placements left out)\n", plants.size(),
                species.size(), grouped);
    for (int res : {16, 32, 64}) {
        std::vector<double> t, cpu;
        lb::ForestGridResult r;
        for (int k = 0; k < reps; ++k) {
            const std::clock_t c0 = std::clock();
            r = lb::solveForestGrid(plants, species, p, {res});
            cpu.push_back(double(std::clock() - c0) / CLOCKS_PER_SEC);
            t.push_back(r.seconds);
        }
        std::sort(t.begin(), t.end());
        std::sort(cpu.begin(), cpu.end());
        // CPU time (all threads) as well: on the shared VM the wall clock stretches with the load.
        std::printf("  resolution %2d: %s (median %.3f s wall, %.3f s CPU)\n", res, lb::forestGridSummary(r).c_str(), t[t.size() / 2],
                    cpu[cpu.size() / 2]);
        std::printf("forest_grid_%d_cpu_s=%.4f\n", res, cpu[cpu.size() / 2]);
        std::printf("forest_grid_%d_s=%.4f\nforest_grid_%d_min_factor=%.4f\nforest_grid_%d_max_factor=%.4f\n", res, t[t.size() / 2], res,
                    double(r.minFactor), res, double(r.maxFactor));
    }
    return 0;
}
