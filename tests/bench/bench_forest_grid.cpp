// The forest-level LB grid on the default forest: build + solve time at a few resolutions,
// with the factor range it gives. Species densities come from loadSpeciesGrids (through a grid cache in
// $TMPDIR so reruns skip the per-species solves); only the timed part is the forest grid. Then its share over
// the bundled landscape (resources/landscape.sylva.json: the St Helens DEM, 125^2 cells of Wang tiles): the
// lattice's build (which plants grow, their canopy per cell, the ground) + solve at a few resolutions,
// against the scalar loop's node updates (the floor: each node-step reads and writes 19 directions).
#include <algorithm>
#include <chrono>
#include <ctime>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "core/lb/forest_grid.h"
#include "core/render/render_scene.h"
#include "pipeline/cache/grid_cache.h"
#include "pipeline/render/frame_build.h"
#include "pipeline/render/render_job.h"
#include "pipeline/scene/scene_file.h"

using namespace sylva;

namespace {

void benchLandscape(int reps, GridCache& cache)
{
    Scene scene = readSceneFile(std::string(SYLVA_SOURCE_DIR) + "/resources/landscape.sylva.json");
    scene.lighting.forestGrid = ForestGridMode::On;
    const std::vector<SpeciesAssets> assets = loadSpeciesAssets(scene, &cache, true);
    RenderScene rs = buildSceneGeometry(scene, assets);
    const LandscapeStats& ls = rs.stats().landscape;
    std::printf("forest grid over the landscape: %zu cells, %.3g potentially visible plants\n", ls.cells, ls.instances);
    for (int res : {lb::kAutoResolution, 32, 96, 128}) {
        scene.lighting.forestGridResolution = res;
        std::vector<double> t;
        for (int k = 0; k < reps; ++k) {
            buildLandscapeArrays(rs, scene);   // the landscape's arrays (timed apart, in its stats)
            lightLandscape(rs, scene);         // and the lattice
            t.push_back(rs.stats().landscapeLight.seconds);
        }
        std::sort(t.begin(), t.end());
        const LandscapeLightStats& st = rs.stats().landscapeLight;
        const double nodeSteps = double(st.dims.x) * st.dims.y * st.dims.z * 2.0 * std::max({st.dims.x, st.dims.y, st.dims.z}) * 3.0;
        const std::string key = res == lb::kAutoResolution ? std::string("auto") : std::to_string(res);
        std::printf("  resolution %s: %d, %dx%dx%d nodes of %.0f m, %.3g plants growing in %zu cells (%.3g tested); median %.3f s; factors "
                    "%.3f / %.3f / %.3f (min / median / max over cells); %.3g node-steps (x 3 channels), %.1f ns each\n",
                    key.c_str(), st.resolution, st.dims.x, st.dims.y, st.dims.z, st.spacing, st.plantsGrowing, st.cells, st.plantsTested,
                    t[t.size() / 2], double(st.minFactor), double(st.medianFactor), double(st.maxFactor), nodeSteps, 1e9 * t[t.size() / 2] / nodeSteps);
        std::printf("landscape_grid_%s_resolution=%d\nlandscape_grid_%s_s=%.4f\nlandscape_grid_%s_ns_per_node_step=%.2f\n"
                    "landscape_grid_%s_min_factor=%.4f\nlandscape_grid_%s_max_factor=%.4f\n",
                    key.c_str(), st.resolution, key.c_str(), t[t.size() / 2], key.c_str(), 1e9 * t[t.size() / 2] / nodeSteps, key.c_str(),
                    double(st.minFactor), key.c_str(), double(st.maxFactor));
    }
}

} // namespace

int main(int argc, char** argv)
{
    int reps = 3;
    bool landscape = true, forest = true;
    for (int a = 1; a < argc; ++a) {
        const std::string s = argv[a];
        if (s == "--reps" && a + 1 < argc) reps = std::atoi(argv[++a]);
        else if (s == "--no-landscape") landscape = false;
        else if (s == "--landscape-only") forest = false;
        else {
            std::printf("usage: bench_forest_grid [--reps R] [--no-landscape | --landscape-only]\n");
            return s == "--help" ? 0 : 2;
        }
    }
    const char* tmp = std::getenv("TMPDIR");
    GridCache cache(std::string(tmp ? tmp : "/tmp") + "/sylva_bench_forest_grid_cache");
    if (!forest) {
        benchLandscape(reps, cache);
        return 0;
    }
    const Scene scene = defaultScene();
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
    if (landscape) benchLandscape(reps, cache);
    return 0;
}
