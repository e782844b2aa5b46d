// Landscape benchmark, seed 002's Table 1: the bundled landscape's species as Wang tiles on the St Helens DEM
// stretched to 82 km, 64^2 .. 512^2 cells, 640 x 480, one primary and one shadow ray per pixel (alpha-tested
// leaves), a panorama over the terrain. Per cell count: build time, memory, potentially visible instances and
// triangles (with and without the density rule's thinning), primary, shadow and frame time; the scaling
// time(512^2) / time(64^2). Ends with name=value lines.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include <tbb/blocked_range.h>
#include <tbb/global_control.h>
#include <tbb/parallel_for.h>

#include "core/render/render_scene.h"
#include "core/render/shade.h"
#include "pipeline/cache/grid_cache.h"
#include "pipeline/io/dem_io.h"
#include "pipeline/render/render_job.h"
#include "pipeline/scene/scene_file.h"
#include "tests/bench/bench_timing.h"

using namespace sylva;

namespace {

struct Row {
    int cells;
    double build, landscapeBuild, mb, landscapeMb, instances, triangles, keptFraction, primary, shadow;
    size_t hits, occluded;
};

// The share of plants the density rule keeps: every plant of every 8th cell along each axis.
double keptFraction(const RenderView& v)
{
    const HeightFieldView h{v.terrain, v.terrainHeights, v.terrainRanges};
    double kept = 0.0, all = 0.0;
    for (uint32_t cz = 0; cz < v.land.cellsZ; cz += 8)
        for (uint32_t cx = 0; cx < v.land.cellsX; cx += 8) {
            const LandCell& c = v.landCells[size_t(cz) * v.land.cellsX + cx];
            const TileRecord& t = v.tileRecords[c.tile];
            for (uint32_t q = t.plantOffset; q < t.plantOffset + t.plantCount; ++q) {
                float y;
                all += 1.0;
                kept += landPlantGrows(v.land, h, v.terrainSnowY, v.terrainRockCos, cx, cz, v.tilePlants[q], y) ? 1.0 : 0.0;
            }
        }
    return all > 0.0 ? kept / all : 0.0;
}

} // namespace

int main(int argc, char** argv)
{
    std::string scenePath = std::string(SYLVA_SOURCE_DIR) + "/resources/landscape.sylva.json";
    int reps = 3, threads = 0, width = 640, height = 480;
    double spacing = 41.0, plantSpacing = 0.36;
    std::vector<int> cellCounts = {64, 128, 256, 512};
    for (int a = 1; a < argc; ++a) {
        const std::string s = argv[a];
        const bool more = a + 1 < argc;
        if (s == "--scene" && more) scenePath = argv[++a];
        else if (s == "--spacing" && more) spacing = std::atof(argv[++a]);
        else if (s == "--plant-spacing" && more) plantSpacing = std::atof(argv[++a]);
        else if (s == "--reps" && more) reps = std::max(1, std::atoi(argv[++a]));
        else if (s == "--threads" && more) threads = std::max(1, std::atoi(argv[++a]));
        else if (s == "--width" && more) width = std::max(8, std::atoi(argv[++a]));
        else if (s == "--height" && more) height = std::max(8, std::atoi(argv[++a]));
        else if (s == "--cells" && more) {
            cellCounts.clear();
            std::stringstream ss(argv[++a]);
            for (std::string item; std::getline(ss, item, ',');) cellCounts.push_back(std::max(1, std::atoi(item.c_str())));
        } else {
            std::printf("usage: bench_landscape [--scene PATH] [--spacing M] [--plant-spacing F] [--cells 64,128,256,512] [--reps N]\n"
                        "                       [--threads N] [--width W] [--height H]\n"
                        "  default: resources/landscape.sylva.json, its DEM stretched to 41 m spacing (82 km), the tiles' plant\n"
                        "  spacings x 0.36 (the seed's plant density), 640x480, one primary + one shadow ray per pixel\n");
            return s == "--help" ? 0 : 2;
        }
    }
    std::unique_ptr<tbb::global_control> limit;
    if (threads > 0) limit = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism, threads);
    const int threadsUsed = int(tbb::global_control::active_value(tbb::global_control::max_allowed_parallelism));

    Scene scene = readSceneFile(scenePath);
    scene.terrain.spacing = spacing;
    scene.terrain.field = std::make_shared<const HeightField>(loadDem(scene.terrain.dem, spacing, scene.terrain.heightScale));
    for (TilePlantDesc& p : scene.terrain.tiles.plants) p.spacing *= plantSpacing;
    scene.instances.clear();
    const HeightField& hf = *scene.terrain.field;
    const double W = double(hf.layout.nx - 1) * spacing, D = double(hf.layout.nz - 1) * spacing;
    // The seed's viewpoint kind: a panorama from 250 m over the south-west quarter toward the mountain.
    const glm::dvec3 o = scene.terrain.origin;
    const double ex = 0.2 * W, ez = 0.25 * D;
    scene.camera.position = o + glm::dvec3(ex, surfaceHeight(hf, ex, ez) + 250.0, ez);
    scene.camera.target = o + glm::dvec3(0.5 * W, surfaceHeight(hf, 0.5 * W, 0.5 * D), 0.5 * D);
    scene.camera.fovY = 50.0f;
    scene.render.width = width;
    scene.render.height = height;
    scene.render.spp = 1;

    const double ta = bench::now();
    GridCache cache;
    const std::vector<SpeciesAssets> assets = loadSpeciesAssets(scene, &cache, false);
    const double assetSeconds = bench::now() - ta;
    std::printf("landscape benchmark: %s, DEM %u x %u at %.0f m (%.1f x %.1f km), plant spacing x %.2f, %dx%d, 1 primary + 1 shadow ray a "
                "pixel, alpha leaves, %d threads, %d reps (median); assets %.1f s\n",
                scenePath.c_str(), hf.layout.nx, hf.layout.nz, spacing, W / 1000.0, D / 1000.0, plantSpacing, width, height, threadsUsed, reps,
                assetSeconds);

    std::vector<Row> rows;
    for (int n : cellCounts) {
        scene.terrain.cells = n;
        const double t0 = bench::now();
        const RenderScene rs = buildRenderScene(scene, assets, sunRadiance(scene.sun));
        const double build = bench::now() - t0;
        const RenderView v = rs.view();
        const AccelStats& st = rs.stats();
        Row r{};
        r.cells = n;
        r.build = build;
        r.landscapeBuild = st.landscape.buildSeconds;
        r.mb = double(st.blasBytes + st.triangleBytes + st.wideBlasBytes + st.terrainBytes + st.landscapeBytes) / 1e6;
        r.landscapeMb = double(st.landscapeBytes) / 1e6;
        r.instances = st.landscape.instances;
        r.triangles = st.landscape.triangles;
        r.keptFraction = keptFraction(v);
        const size_t np = size_t(width) * size_t(height);
        std::vector<Ray> cam(np);
        std::vector<Hit> hits(np);
        std::vector<char> got(np);
        for (int y = 0; y < height; ++y)
            for (int x = 0; x < width; ++x) cam[size_t(y) * width + x] = cameraRay(v, float(x) + 0.5f, float(y) + 0.5f);
        r.primary = bench::timeReps(reps, [&] {
                        tbb::parallel_for(tbb::blocked_range<size_t>(0, np, 64), [&](const tbb::blocked_range<size_t>& b) {
                            for (size_t i = b.begin(); i != b.end(); ++i) got[i] = traceScene<false>(v, cam[i], hits[i]);
                        });
                    }).median;
        // Shadow rays as the renderer casts them (offset off the surface it shades).
        std::vector<Ray> sh;
        for (size_t i = 0; i < np; ++i) {
            if (!got[i]) continue;
            ++r.hits;
            const SurfacePoint s = surfaceStage(v, cam[i], hits[i]);
            sh.push_back(Ray{offsetPoint(s.p, s.ng, s.extent), 0.0f, v.sunDir, 1e30f});
        }
        std::vector<char> occ(sh.size());
        r.shadow = bench::timeReps(reps, [&] {
                       tbb::parallel_for(tbb::blocked_range<size_t>(0, sh.size(), 64), [&](const tbb::blocked_range<size_t>& b) {
                           for (size_t i = b.begin(); i != b.end(); ++i) {
                               Hit h{};
                               occ[i] = traceScene<true>(v, sh[i], h);
                           }
                       });
                   }).median;
        for (char c : occ) r.occluded += c != 0;
        std::printf("%4d^2 cells: build %.2f s (landscape %.3f s), %.1f MB (landscape %.1f MB); %.3g instances, %.3g triangles potentially "
                    "visible (%.3g after thinning, %.0f%% kept); primary %.3f s (%zu hits), shadow %.3f s (%zu occluded), frame %.3f s\n",
                    n, r.build, r.landscapeBuild, r.mb, r.landscapeMb, r.instances, r.triangles, r.triangles * r.keptFraction, 100.0 * r.keptFraction,
                    r.primary, r.hits, r.shadow, r.occluded, r.primary + r.shadow);
        std::fflush(stdout);
        rows.push_back(r);
    }
    std::printf("\n| cells | triangles (thinned) | instances (thinned) | frame s | primary s | shadow s | build s | MB |\n|---|---|---|---|---|---|---|---|\n");
    for (const Row& r : rows)
        std::printf("| %d^2 | %.3g | %.3g | %.3f | %.3f | %.3f | %.2f | %.1f |\n", r.cells, r.triangles * r.keptFraction, r.instances * r.keptFraction,
                    r.primary + r.shadow, r.primary, r.shadow, r.build, r.mb);
    for (const Row& r : rows)
        std::printf("cells%d_frame_s=%.4f\ncells%d_build_s=%.4f\ncells%d_landscape_build_s=%.4f\ncells%d_mb=%.3f\ncells%d_triangles=%.4g\ncells%d_"
                    "triangles_thinned=%.4g\n",
                    r.cells, r.primary + r.shadow, r.cells, r.build, r.cells, r.landscapeBuild, r.cells, r.mb, r.cells, r.triangles, r.cells,
                    r.triangles * r.keptFraction);
    if (rows.size() >= 2) std::printf("scaling=%.4f\n", (rows.back().primary + rows.back().shadow) / (rows.front().primary + rows.front().shadow));
    return 0;
}
