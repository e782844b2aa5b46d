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
    // Crown width in forest-grid cells: the study's stand (docs/ACCURACY.md "Scene scale") needs about 3 for the
    // forest grid to beat none.
    std::vector<double> crowns;
    for (const lb::ForestPlant& pl : plants) {
        const lb::ForestSpecies& sp = species[size_t(pl.species)];
        crowns.push_back(double(pl.scale) * std::max(sp.boxMax.x - sp.boxMin.x, sp.boxMax.z - sp.boxMin.z));
    }
    std::sort(crowns.begin(), crowns.end());
    const double crown = crowns.empty() ? 0.0 : crowns[crowns.size() / 2];
    std::printf("median crown width %.2f m\n", crown);
    for (int res : {lb::kAutoResolution, 16, 32, 48, 64}) {
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
        const std::string key = res == lb::kAutoResolution ? std::string("auto") : std::to_string(res);
        std::printf("  resolution %s: %s (median %.3f s wall, %.3f s CPU; %.1f cells a median crown)\n", key.c_str(),
                    lb::forestGridSummary(r).c_str(), t[t.size() / 2], cpu[cpu.size() / 2], crown / r.geometry.spacing);
        std::printf("forest_grid_%s_resolution=%d\n", key.c_str(), r.resolution);
        std::printf("forest_grid_%s_cpu_s=%.4f\n", key.c_str(), cpu[cpu.size() / 2]);
        std::printf("forest_grid_%s_s=%.4f\nforest_grid_%s_min_factor=%.4f\nforest_grid_%s_max_factor=%.4f\n", key.c_str(), t[t.size() / 2], key.c_str(),
                    double(r.minFactor), key.c_str(), double(r.maxFactor));
    }
    return 0;
}
