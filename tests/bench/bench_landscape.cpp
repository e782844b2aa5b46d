// Landscape benchmark, Dietrich et al.'s ("Terrain Guided Multi-Level Instancing of Highly Complex Plant
// Populations") Table 1: the bundled landscape's species as Wang tiles on the St Helens DEM stretched to 82 km,
// 64^2 .. 512^2 cells, 640 x 480, one primary and one shadow ray per pixel (alpha-tested leaves), a panorama
// over the terrain. Per cell count: build time, memory, potentially visible instances and triangles (with and
// without the density rule's thinning), primary, shadow and frame time; the scaling time(512^2) / time(64^2);
// the same rays traced ray by ray (traceScene) and an 8x8 tile at a time (traceScenePacket, as the CPU renderer
// traces a landscape), and with --embree beside Embree 3's single rays and streams; the frame as the renderer
// renders it (renderFilm: those packets, the surface stage and shading with the species' LB lighting, the
// seed's frame time); the scaling again from the first and last counts' frames timed in turn (--pairs). Ends
// with name=value lines.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <iterator>
#include <memory>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include <tbb/blocked_range.h>
#include <tbb/global_control.h>
#include <tbb/parallel_for.h>

#include "core/render/render_cpu.h"
#include "core/render/render_scene.h"
#include "core/render/shade.h"
#include "core/render/trace_packet.h"
#include "pipeline/cache/grid_cache.h"
#include "pipeline/io/dem_io.h"
#include "pipeline/render/frame_build.h"
#include "pipeline/render/render_job.h"
#include "pipeline/scene/scene_file.h"
#include "tests/bench/bench_timing.h"
#ifdef SYLVA_HAVE_EMBREE
#include "tests/bench/bench_embree.h"
#endif

using namespace sylva;

namespace {

struct Row {
    int cells;
    double build, landscapeBuild, mb, landscapeMb, instances, triangles, keptFraction, primary, shadow, primaryPacket, shadowPacket, rendered;
    size_t hits, occluded, packetDiffer;
};

// A cell count's scene and its frame's rays in the renderer's order (8x8 tiles; camStart / shStart: each tile's
// first camera / shadow ray), traced a tile at a time into hits / got and shHits / occ. The first and last counts'
// are kept for the scaling's paired timing: their frames alternate, so drift in the machine's speed (this VM's
// drifts by 1.5x) falls on both alike.
struct FrameRun {
    int cells = 0;
    std::unique_ptr<RenderScene> rs;
    std::vector<Ray> cam, sh;
    std::vector<size_t> camStart, shStart;
    std::vector<Hit> hits, shHits;
    std::unique_ptr<bool[]> got, occ;

    FrameRun(int n, std::unique_ptr<RenderScene> scene, std::vector<Ray> camera, std::vector<Ray> shadow, std::vector<size_t> camTiles,
             std::vector<size_t> shTiles)
        : cells(n), rs(std::move(scene)), cam(std::move(camera)), sh(std::move(shadow)), camStart(std::move(camTiles)), shStart(std::move(shTiles)),
          hits(cam.size()), shHits(sh.size()), got(new bool[std::max<size_t>(cam.size(), 1)]), occ(new bool[std::max<size_t>(sh.size(), 1)])
    {
    }
    void primaryPackets()
    {
        const RenderView v = rs->view();
        tbb::parallel_for(tbb::blocked_range<size_t>(0, camStart.size() - 1, 1), [&](const tbb::blocked_range<size_t>& b) {
            for (size_t t = b.begin(); t != b.end(); ++t)
                traceScenePacket<false>(v, &cam[camStart[t]], int(camStart[t + 1] - camStart[t]), &hits[camStart[t]], &got[camStart[t]]);
        });
    }
    void shadowPackets()
    {
        const RenderView v = rs->view();
        tbb::parallel_for(tbb::blocked_range<size_t>(0, shStart.size() - 1, 1), [&](const tbb::blocked_range<size_t>& b) {
            for (size_t t = b.begin(); t != b.end(); ++t)
                if (shStart[t + 1] > shStart[t])
                    traceScenePacket<true>(v, &sh[shStart[t]], int(shStart[t + 1] - shStart[t]), &shHits[shStart[t]], &occ[shStart[t]]);
        });
    }
    // One frame of packets, primary then shadow, seconds.
    double packetFrame()
    {
        const double t0 = bench::now();
        primaryPackets();
        shadowPackets();
        return bench::now() - t0;
    }
    // The frame as the renderer makes it (renderFilm at 1 sample a pixel: its camera rays and their sun rays as packets
    // an 8x8 tile at a time, the surface stage, shading and the film), seconds: the seed's frame time.
    double renderFrame()
    {
        const double t0 = bench::now();
        const Film film = renderFilm(rs->view());
        return bench::now() - t0;
    }
    // The same frame a ray at a time (traceScene), seconds.
    double singleFrame()
    {
        const RenderView v = rs->view();
        const double t0 = bench::now();
        for (const std::vector<Ray>* rays : {&cam, &sh})
            tbb::parallel_for(tbb::blocked_range<size_t>(0, rays->size(), 64), [&](const tbb::blocked_range<size_t>& b) {
                for (size_t i = b.begin(); i != b.end(); ++i) {
                    Hit h{};
                    if (rays == &cam) traceScene<false>(v, (*rays)[i], h);
                    else traceScene<true>(v, (*rays)[i], h);
                }
            });
        return bench::now() - t0;
    }
};

// The share of plants the density rule keeps: every plant of every 8th cell along each axis.
double keptFraction(const RenderView& v)
{
    const HeightFieldView h{v.terrain.layout, v.terrainHeights, v.terrainRanges};
    double kept = 0.0, all = 0.0;
    for (uint32_t cz = 0; cz < v.landscape.layout.cellsZ; cz += 8)
        for (uint32_t cx = 0; cx < v.landscape.layout.cellsX; cx += 8) {
            const LandCell& c = v.landCells[size_t(cz) * v.landscape.layout.cellsX + cx];
            const TileRecord& t = v.tileRecords[c.tile];
            for (uint32_t q = t.plantOffset; q < t.plantOffset + t.plantCount; ++q) {
                float y;
                all += 1.0;
                kept += landPlantGrows(v.landscape.layout, h, v.terrain.snowY, v.terrain.rockCos, cx, cz, v.tilePlants[q], y) ? 1.0 : 0.0;
            }
        }
    return all > 0.0 ? kept / all : 0.0;
}

#ifdef SYLVA_HAVE_EMBREE
// This process's resident bytes (/proc/self/statm): Embree's memory monitor does not see every allocation (its
// instance objects), so the cap and the comparison use what the process holds.
long long residentBytes()
{
    long long pages = 0, resident = 0;
    if (FILE* f = std::fopen("/proc/self/statm", "r")) {
        if (std::fscanf(f, "%lld %lld", &pages, &resident) != 2) resident = 0;
        std::fclose(f);
    }
    return resident * 4096;
}

// The landscape flattened for Embree 3: the terrain as one indexed triangle mesh (the height field's triangles,
// camera-relative), every plant that grows (landPlantGrows) as an instance of its species' scene with the
// landscape's own map (landPlantInstance) inverted. Stops adding instances once the process has grown by more
// than `capBytes` (complete = false: Embree cannot hold this landscape under the cap). bytes: Embree's memory
// monitor; resident: the process's growth over the build.
struct EmbreeLandscape {
    RTCDevice device = nullptr;
    RTCScene top = nullptr;
    std::vector<RTCScene> species;
    std::vector<std::unique_ptr<bench::EmbreeGeomData>> geomData;
    long long bytes = 0, resident = 0;
    size_t instances = 0;
    bool complete = true;
    double buildSeconds = 0.0;

    EmbreeLandscape(const RenderScene& rs, const RenderView& v, int threads, long long capBytes)
    {
        const std::string config = "threads=" + std::to_string(threads);
        device = rtcNewDevice(config.c_str());
        if (!device) throw std::runtime_error("rtcNewDevice failed");
        rtcSetDeviceErrorFunction(device, bench::embreeError, nullptr);
        rtcSetDeviceMemoryMonitorFunction(device, bench::embreeMemoryMonitor, nullptr);
        const long long base = bench::g_embreeBytes.load(), rss0 = residentBytes();
        const double t0 = bench::now();
        species = bench::embreeSpeciesScenes(device, rs, v, RTC_BUILD_QUALITY_MEDIUM, geomData, false);
        top = rtcNewScene(device);
        rtcSetSceneBuildQuality(top, RTC_BUILD_QUALITY_MEDIUM);
        // The terrain: sample (i, j) at terrainBase + ((i - baseI) dx, h, (j - baseJ) dz); triangles 2c = (p00, p11,
        // p10), 2c + 1 = (p00, p01, p11) as height_field.h splits its cells.
        const HeightFieldLayout& H = v.terrain.layout;
        RTCGeometry g = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
        auto* vb = static_cast<float*>(rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float), size_t(H.nx) * H.nz));
        for (uint32_t j = 0; j < H.nz; ++j)
            for (uint32_t i = 0; i < H.nx; ++i) {
                const size_t k = size_t(j) * H.nx + i;
                vb[3 * k + 0] = v.terrain.base.x + float(int(i) - v.terrain.baseI) * H.dx;
                vb[3 * k + 1] = v.terrain.base.y + v.terrainHeights[k];
                vb[3 * k + 2] = v.terrain.base.z + float(int(j) - v.terrain.baseJ) * H.dz;
            }
        const size_t cellsT = size_t(H.nx - 1) * (H.nz - 1);
        auto* ib = static_cast<uint32_t*>(rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(uint32_t), 2 * cellsT));
        for (uint32_t j = 0; j + 1 < H.nz; ++j)
            for (uint32_t i = 0; i + 1 < H.nx; ++i) {
                const size_t c = size_t(j) * (H.nx - 1) + i;
                const uint32_t p00 = j * H.nx + i, p10 = p00 + 1, p01 = p00 + H.nx, p11 = p01 + 1;
                const uint32_t t[6] = {p00, p11, p10, p00, p01, p11};
                for (int q = 0; q < 6; ++q) ib[6 * c + size_t(q)] = t[q];
            }
        rtcCommitGeometry(g);
        const unsigned terrainId = rtcAttachGeometry(top, g);
        rtcReleaseGeometry(g);
        (void)terrainId;
        const HeightFieldView h{v.terrain.layout, v.terrainHeights, v.terrainRanges};
        for (uint32_t cell = 0; cell < v.landscape.layout.cellsX * v.landscape.layout.cellsZ && complete; ++cell) {
            const LandCell& c = v.landCells[cell];
            const TileRecord& t = v.tileRecords[c.tile];
            const uint32_t cx = cell % v.landscape.layout.cellsX, cz = cell / v.landscape.layout.cellsX;
            for (uint32_t q = t.plantOffset; q < t.plantOffset + t.plantCount; ++q) {
                float y;
                if (!landPlantGrows(v.landscape.layout, h, v.terrain.snowY, v.terrain.rockCos, cx, cz, v.tilePlants[q], y)) continue;
                const InstanceRecord in = trace_detail::landPlantInstance(v, cell, q);
                float xfm[12];
                bench::embreeInstanceTransform(in, xfm);
                RTCGeometry gi = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_INSTANCE);
                rtcSetGeometryInstancedScene(gi, species[in.geometry]);
                rtcSetGeometryTimeStepCount(gi, 1);
                rtcSetGeometryTransform(gi, 0, RTC_FORMAT_FLOAT3X4_COLUMN_MAJOR, xfm);
                rtcCommitGeometry(gi);
                rtcAttachGeometry(top, gi);
                rtcReleaseGeometry(gi);
                ++instances;
            }
            if ((cell & 63u) == 0 && residentBytes() - rss0 > capBytes) complete = false;
        }
        if (complete) rtcCommitScene(top);
        bytes = bench::g_embreeBytes.load() - base;
        resident = residentBytes() - rss0;
        if (resident > capBytes) complete = false;
        buildSeconds = bench::now() - t0;
    }

    ~EmbreeLandscape()
    {
        if (top) rtcReleaseScene(top);
        for (RTCScene sc : species)
            if (sc) rtcReleaseScene(sc);
        if (device) rtcReleaseDevice(device);
    }
};

void embreeRay(RTCRay& r, const Ray& ray)
{
    r.org_x = ray.org.x, r.org_y = ray.org.y, r.org_z = ray.org.z, r.tnear = ray.tmin;
    r.dir_x = ray.dir.x, r.dir_y = ray.dir.y, r.dir_z = ray.dir.z, r.time = 0.0f;
    r.tfar = ray.tmax, r.mask = 0xffffffffu, r.id = 0, r.flags = 0;
}
#endif

#if defined(SYLVA_TRAVERSAL_STATS)
// The work per ray (core/base/traversal_stats.h), counted on this thread over `rays` serial traces.
template <class Fn>
void countPerRay(const char* what, int cells, size_t rays, Fn&& trace)
{
    uint64_t* const c[] = {&g_landNodeVisits, &g_landCellVisits, &g_tileNodeVisits, &g_plantBoxTests, &g_plantRootReads, &g_plantMeshEntries,
                           &g_bvhNodeVisits, &g_bvhLeafVisits, &g_triangleTests, &g_terrainBlockVisits, &g_terrainCellTests};
    const char* const name[] = {"land_nodes", "land_cells", "tile_nodes", "plant_box_tests", "plant_root_reads", "plant_mesh_entries",
                                "mesh_bvh_nodes", "mesh_bvh_leaves", "triangle_tests", "terrain_blocks", "terrain_cells"};
    for (uint64_t* p : c) *p = 0;
    trace();
    std::printf("%4d^2 cells, %s rays (%zu), per ray:", cells, what, rays);
    for (size_t k = 0; k < std::size(c); ++k) std::printf(" %s %.2f", name[k], double(*c[k]) / double(std::max<size_t>(rays, 1)));
    std::printf("\n");
    for (size_t k = 0; k < std::size(c); ++k) std::printf("cells%d_%s_%s_per_ray=%.3f\n", cells, what, name[k], double(*c[k]) / double(std::max<size_t>(rays, 1)));
}

// The work per packet (the packet counters of core/base/traversal_stats.h), counted on this thread.
template <class Fn>
void countPerPacket(const char* what, int cells, size_t packets, Fn&& trace)
{
    uint64_t* const c[] = {&g_pkLandTests, &g_pkLandLanes, &g_pkCells, &g_pkCellLanes, &g_pkTileTests, &g_pkTileLanes, &g_pkPlantTests, &g_pkPlantLanes,
                           &g_pkRootReads, &g_plantMeshEntries};
    const char* const name[] = {"land_tests", "land_lanes", "cells", "cell_lanes", "tile_tests", "tile_lanes", "plant_tests", "plant_lanes", "root_reads",
                                "plant_mesh_entries"};
    for (uint64_t* p : c) *p = 0;
    trace();
    std::printf("%4d^2 cells, %s packets (%zu), per packet:", cells, what, packets);
    for (size_t k = 0; k < std::size(c); ++k) std::printf(" %s %.2f", name[k], double(*c[k]) / double(std::max<size_t>(packets, 1)));
    std::printf("\n");
}
#endif

} // namespace

int main(int argc, char** argv)
{
    std::string scenePath = std::string(SYLVA_SOURCE_DIR) + "/resources/landscape.sylva.json";
    int reps = 3, threads = 0, width = 640, height = 480, pairs = -1;
    double spacing = 41.0, plantSpacing = 0.36;
    std::vector<int> cellCounts = {64, 128, 256, 512};
    std::vector<int> embreeCells;   // --embree: these cell counts flattened into Embree beside ours
    double embreeCapGb = 8.0;
    bool lit = true;   // --unlit: the species without their LB lighting grids (the rendered frame shades without them)
    for (int a = 1; a < argc; ++a) {
        const std::string s = argv[a];
        const bool more = a + 1 < argc;
        if (s == "--scene" && more) scenePath = argv[++a];
        else if (s == "--spacing" && more) spacing = std::atof(argv[++a]);
        else if (s == "--plant-spacing" && more) plantSpacing = std::atof(argv[++a]);
        else if (s == "--reps" && more) reps = std::max(1, std::atoi(argv[++a]));
        else if (s == "--pairs" && more) pairs = std::max(0, std::atoi(argv[++a]));
        else if (s == "--threads" && more) threads = std::max(1, std::atoi(argv[++a]));
        else if (s == "--width" && more) width = std::max(8, std::atoi(argv[++a]));
        else if (s == "--height" && more) height = std::max(8, std::atoi(argv[++a]));
        else if (s == "--unlit") lit = false;
        else if (s == "--embree" && more) {
            std::stringstream ss(argv[++a]);
            for (std::string item; std::getline(ss, item, ',');) embreeCells.push_back(std::max(1, std::atoi(item.c_str())));
        } else if (s == "--embree-cap-gb" && more) embreeCapGb = std::atof(argv[++a]);
        else if (s == "--cells" && more) {
            cellCounts.clear();
            std::stringstream ss(argv[++a]);
            for (std::string item; std::getline(ss, item, ',');) cellCounts.push_back(std::max(1, std::atoi(item.c_str())));
        } else {
            std::printf("usage: bench_landscape [--scene PATH] [--spacing M] [--plant-spacing F] [--cells 64,128,256,512] [--reps N]\n"
                        "                       [--threads N] [--width W] [--height H] [--embree 16,32,64] [--embree-cap-gb G] [--pairs N]\n"
                        "                       [--unlit]\n"
                        "  default: resources/landscape.sylva.json, its DEM stretched to 41 m spacing (82 km), the tiles' plant\n"
                        "  spacings x 0.36 (the seed's plant density), 640x480, one primary + one shadow ray per pixel;\n"
                        "  --embree: the landscape flattened into Embree 3 at those cell counts (terrain mesh + every plant an\n"
                        "  instance, built until Embree holds more than the cap, default 8 GB), same rays, side by side;\n"
                        "  --pairs: the first and last cell counts' frames timed in turn for the scaling (default 3 x reps);\n"
                        "  the rendered frame (renderFilm, the renderer's whole frame at 1 sample a pixel) shades with the species'\n"
                        "  LB lighting grids from the cache, as sylva render does; --unlit: without them\n");
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
    const std::vector<SpeciesAssets> assets = loadSpeciesAssets(scene, &cache, lit);
    const double assetSeconds = bench::now() - ta;
    std::printf("landscape benchmark: %s, DEM %u x %u at %.0f m (%.1f x %.1f km), plant spacing x %.2f, %dx%d, 1 primary + 1 shadow ray a "
                "pixel, alpha leaves, %d threads, %d reps (median); assets %.1f s\n",
                scenePath.c_str(), hf.layout.nx, hf.layout.nz, spacing, W / 1000.0, D / 1000.0, plantSpacing, width, height, threadsUsed, reps,
                assetSeconds);

    if (pairs < 0) pairs = 3 * reps;
    std::vector<Row> rows;
    std::unique_ptr<FrameRun> kept[2];
    for (int n : cellCounts) {
        scene.terrain.cells = n;
        const double t0 = bench::now();
        auto owned = std::make_unique<RenderScene>(buildRenderScene(scene, assets, sunRadiance(scene.sun)));
        const RenderScene& rs = *owned;
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
        // The camera rays in the renderer's order: 8 x 8 pixel tiles (camStart: each tile's first ray), for every
        // tracer alike; the shadow rays of a tile follow one another too (shStart).
        const size_t np = size_t(width) * size_t(height);
        std::vector<Ray> cam;
        std::vector<size_t> camStart;
        cam.reserve(np);
        for (int ty = 0; ty < height; ty += 8)
            for (int tx = 0; tx < width; tx += 8) {
                camStart.push_back(cam.size());
                for (int y = ty; y < std::min(ty + 8, height); ++y)
                    for (int x = tx; x < std::min(tx + 8, width); ++x) cam.push_back(cameraRay(v, float(x) + 0.5f, float(y) + 0.5f));
            }
        camStart.push_back(np);
        const size_t tiles = camStart.size() - 1;
        std::vector<Hit> hits(np);
        std::vector<char> got(np);
        r.primary = bench::timeReps(reps, [&] {
                        tbb::parallel_for(tbb::blocked_range<size_t>(0, np, 64), [&](const tbb::blocked_range<size_t>& b) {
                            for (size_t i = b.begin(); i != b.end(); ++i) got[i] = traceScene<false>(v, cam[i], hits[i]);
                        });
                    }).median;
        // Shadow rays as the renderer casts them (offset off the surface it shades).
        std::vector<Ray> sh;
        std::vector<size_t> shStart;
        for (size_t t = 0; t < tiles; ++t) {
            shStart.push_back(sh.size());
            for (size_t i = camStart[t]; i < camStart[t + 1]; ++i) {
                if (!got[i]) continue;
                ++r.hits;
                const SurfacePoint s = surfaceStage(v, cam[i], hits[i]);
                sh.push_back(Ray{offsetPoint(s.p, s.ng, s.extent), 0.0f, lbLight(v).direction, 1e30f});
            }
        }
        shStart.push_back(sh.size());
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
        // The same rays a tile at a time through traceScenePacket; every answer compared with the ray alone. The
        // run owns the scene from here (rs stays where it is).
        auto run = std::make_unique<FrameRun>(n, std::move(owned), cam, sh, camStart, shStart);
        FrameRun& R = *run;
        auto primaryPackets = [&] { R.primaryPackets(); };
        auto shadowPackets = [&] { R.shadowPackets(); };
        r.primaryPacket = bench::timeReps(reps, primaryPackets).median;
        r.shadowPacket = bench::timeReps(reps, shadowPackets).median;
        r.rendered = bench::timeReps(reps, [&] { R.renderFrame(); }).median;
        r.packetDiffer = 0;
        for (size_t i = 0; i < np; ++i)
            r.packetDiffer += (got[i] != 0) != R.got[i] || (R.got[i] && (hits[i].t != R.hits[i].t || hits[i].prim != R.hits[i].prim));
        for (size_t i = 0; i < sh.size(); ++i) r.packetDiffer += (occ[i] != 0) != R.occ[i];
#if defined(SYLVA_TRAVERSAL_STATS)
        countPerRay("primary", n, np, [&] {
            for (size_t i = 0; i < np; ++i) {
                Hit h{};
                traceScene<false>(v, cam[i], h);
            }
        });
        countPerRay("shadow", n, sh.size(), [&] {
            for (size_t i = 0; i < sh.size(); ++i) {
                Hit h{};
                traceScene<true>(v, sh[i], h);
            }
        });
        {
            // Serially, on this thread (the counters are per thread).
            tbb::global_control serial(tbb::global_control::max_allowed_parallelism, 1);
            countPerPacket("primary", n, tiles, primaryPackets);
            countPerPacket("shadow", n, tiles, shadowPackets);
        }
#endif
        std::printf("%4d^2 cells: build %.2f s (landscape %.3f s), %.1f MB (landscape %.1f MB); %.3g instances, %.3g triangles potentially "
                    "visible (%.3g after thinning, %.0f%% kept); primary %.3f s (%zu hits), shadow %.3f s (%zu occluded), frame %.3f s\n",
                    n, r.build, r.landscapeBuild, r.mb, r.landscapeMb, r.instances, r.triangles, r.triangles * r.keptFraction, 100.0 * r.keptFraction,
                    r.primary, r.hits, r.shadow, r.occluded, r.primary + r.shadow);
        std::printf("%4d^2 cells, 8x8 packets: primary %.3f s, shadow %.3f s, frame %.3f s (%.2fx the single rays'); %zu of %zu answers differ from "
                    "the single rays'\n",
                    n, r.primaryPacket, r.shadowPacket, r.primaryPacket + r.shadowPacket, (r.primary + r.shadow) / (r.primaryPacket + r.shadowPacket),
                    r.packetDiffer, np + sh.size());
        std::printf("%4d^2 cells, rendered (renderFilm, %s): frame %.3f s\n", n, lit ? "LB lighting" : "unlit", r.rendered);
        std::fflush(stdout);
        rows.push_back(r);
        if (cellCounts.size() >= 2 && (n == cellCounts.front() || n == cellCounts.back()))
            kept[n == cellCounts.back()] = std::move(run);   // R stays valid
#ifdef SYLVA_HAVE_EMBREE
        if (std::find(embreeCells.begin(), embreeCells.end(), n) == embreeCells.end()) continue;
        // The same rays through Embree holding the landscape flattened; ours timed again beside it (same run).
        const EmbreeLandscape em(rs, v, threadsUsed, (long long)(embreeCapGb * 1e9));
        if (!em.complete) {
            std::printf("%4d^2 cells: Embree ran out: %.2f GB resident (cap %.1f GB) after %zu instances of %.0f\n", n, double(em.resident) / 1e9,
                        embreeCapGb, em.instances, r.instances * r.keptFraction);
            std::printf("cells%d_embree_out_of_memory=1\n", n);
            continue;
        }
        std::vector<float> tEm(np);
        std::vector<char> occEm(sh.size());
        const double ourPrimary = bench::timeReps(reps, [&] {
                                      tbb::parallel_for(tbb::blocked_range<size_t>(0, np, 64), [&](const tbb::blocked_range<size_t>& b) {
                                          for (size_t i = b.begin(); i != b.end(); ++i) got[i] = traceScene<false>(v, cam[i], hits[i]);
                                      });
                                  }).median;
        const double emPrimary = bench::timeReps(reps, [&] {
                                     tbb::parallel_for(tbb::blocked_range<size_t>(0, np, 64), [&](const tbb::blocked_range<size_t>& b) {
                                         RTCIntersectContext ctx;
                                         rtcInitIntersectContext(&ctx);
                                         for (size_t i = b.begin(); i != b.end(); ++i) {
                                             RTCRayHit rh;
                                             embreeRay(rh.ray, cam[i]);
                                             rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
                                             rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
                                             rtcIntersect1(em.top, &ctx, &rh);
                                             tEm[i] = rh.hit.geomID != RTC_INVALID_GEOMETRY_ID ? rh.ray.tfar : -1.0f;
                                         }
                                     });
                                 }).median;
        const double ourShadow = bench::timeReps(reps, [&] {
                                     tbb::parallel_for(tbb::blocked_range<size_t>(0, sh.size(), 64), [&](const tbb::blocked_range<size_t>& b) {
                                         for (size_t i = b.begin(); i != b.end(); ++i) {
                                             Hit h{};
                                             occ[i] = traceScene<true>(v, sh[i], h);
                                         }
                                     });
                                 }).median;
        const double emShadow = bench::timeReps(reps, [&] {
                                    tbb::parallel_for(tbb::blocked_range<size_t>(0, sh.size(), 64), [&](const tbb::blocked_range<size_t>& b) {
                                        RTCIntersectContext ctx;
                                        rtcInitIntersectContext(&ctx);
                                        for (size_t i = b.begin(); i != b.end(); ++i) {
                                            RTCRay ray;
                                            embreeRay(ray, sh[i]);
                                            rtcOccluded1(em.top, &ctx, &ray);
                                            occEm[i] = ray.tfar < 0.0f;
                                        }
                                    });
                                }).median;
        // Ours a tile at a time (traceScenePacket), and Embree's stream mode on the same tiles: a tile's rays as one
        // rtcIntersect1M / rtcOccluded1M call with the coherent flag (Embree regroups a stream into packets itself).
        const double ourPrimaryPacket = bench::timeReps(reps, primaryPackets).median;
        const double ourShadowPacket = bench::timeReps(reps, shadowPackets).median;
        std::vector<float> tEmS(np);
        std::vector<char> occEmS(sh.size());
        const double emPrimaryStream = bench::timeReps(reps, [&] {
                                           tbb::parallel_for(tbb::blocked_range<size_t>(0, tiles, 1), [&](const tbb::blocked_range<size_t>& b) {
                                               RTCIntersectContext ctx;
                                               rtcInitIntersectContext(&ctx);
                                               ctx.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
                                               RTCRayHit rh[64];
                                               for (size_t t = b.begin(); t != b.end(); ++t) {
                                                   const size_t i0 = camStart[t], count = camStart[t + 1] - i0;
                                                   for (size_t k = 0; k < count; ++k) {
                                                       embreeRay(rh[k].ray, cam[i0 + k]);
                                                       rh[k].hit.geomID = RTC_INVALID_GEOMETRY_ID;
                                                       rh[k].hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
                                                   }
                                                   rtcIntersect1M(em.top, &ctx, rh, unsigned(count), sizeof(RTCRayHit));
                                                   for (size_t k = 0; k < count; ++k)
                                                       tEmS[i0 + k] = rh[k].hit.geomID != RTC_INVALID_GEOMETRY_ID ? rh[k].ray.tfar : -1.0f;
                                               }
                                           });
                                       }).median;
        const double emShadowStream = bench::timeReps(reps, [&] {
                                          tbb::parallel_for(tbb::blocked_range<size_t>(0, tiles, 1), [&](const tbb::blocked_range<size_t>& b) {
                                              RTCIntersectContext ctx;
                                              rtcInitIntersectContext(&ctx);
                                              ctx.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
                                              RTCRay ray[64];
                                              for (size_t t = b.begin(); t != b.end(); ++t) {
                                                  const size_t i0 = shStart[t], count = shStart[t + 1] - i0;
                                                  if (count == 0) continue;
                                                  for (size_t k = 0; k < count; ++k) embreeRay(ray[k], sh[i0 + k]);
                                                  rtcOccluded1M(em.top, &ctx, ray, unsigned(count), sizeof(RTCRay));
                                                  for (size_t k = 0; k < count; ++k) occEmS[i0 + k] = ray[k].tfar < 0.0f;
                                              }
                                          });
                                      }).median;
        size_t streamDiffer = 0;
        for (size_t i = 0; i < np; ++i)
            streamDiffer += (tEm[i] >= 0.0f) != (tEmS[i] >= 0.0f) || (tEm[i] >= 0.0f && std::fabs(tEm[i] - tEmS[i]) > 1e-3f * std::max(tEm[i], tEmS[i]));
        for (size_t i = 0; i < sh.size(); ++i) streamDiffer += occEm[i] != occEmS[i];
        size_t primaryDiffer = 0, shadowDiffer = 0;
        for (size_t i = 0; i < np; ++i) {
            const bool a = got[i] != 0, b = tEm[i] >= 0.0f;
            if (a != b || (a && std::fabs(hits[i].t - tEm[i]) > 1e-3f * std::max(hits[i].t, tEm[i]))) ++primaryDiffer;
        }
        for (size_t i = 0; i < sh.size(); ++i) shadowDiffer += occ[i] != occEm[i];
        const double raysAll = double(np + sh.size());
        const double ours = raysAll / (ourPrimary + ourShadow), theirs = raysAll / (emPrimary + emShadow);
        std::printf("%4d^2 cells vs Embree 3 (%zu instances + the terrain mesh, built in %.1f s): memory %.1f MB ours / %.1f MB Embree (monitor; resident %.1f MB) = %.4f (resident %.4f); "
                    "primary %.3f / %.3f s, shadow %.3f / %.3f s; rays/s ours / Embree = %.3f (primary %.3f, shadow %.3f); %zu of %zu primary and "
                    "%zu of %zu shadow results differ\n",
                    n, em.instances, em.buildSeconds, r.mb, double(em.bytes) / 1e6, double(em.resident) / 1e6, r.mb * 1e6 / double(em.bytes),
                    r.mb * 1e6 / double(std::max(em.resident, 1ll)), ourPrimary, emPrimary, ourShadow,
                    emShadow, ours / theirs, emPrimary / ourPrimary, emShadow / ourShadow, primaryDiffer, np, shadowDiffer, sh.size());
        const double oursPacket = raysAll / (ourPrimaryPacket + ourShadowPacket), theirsStream = raysAll / (emPrimaryStream + emShadowStream);
        std::printf("%4d^2 cells, 8x8 tiles: ours packets primary %.3f s, shadow %.3f s; Embree stream primary %.3f s, shadow %.3f s (%zu answers "
                    "differ from its single rays); rays/s ours packets / Embree single = %.3f (primary %.3f, shadow %.3f), / Embree stream = %.3f "
                    "(primary %.3f, shadow %.3f)\n",
                    n, ourPrimaryPacket, ourShadowPacket, emPrimaryStream, emShadowStream, streamDiffer, oursPacket / theirs, emPrimary / ourPrimaryPacket,
                    emShadow / ourShadowPacket, oursPacket / theirsStream, emPrimaryStream / ourPrimaryPacket, emShadowStream / ourShadowPacket);
        std::printf("cells%d_packet_rays_per_s_ratio=%.4f\ncells%d_packet_vs_stream_ratio=%.4f\ncells%d_packet_primary_ratio=%.4f\n"
                    "cells%d_packet_shadow_ratio=%.4f\n",
                    n, oursPacket / theirs, n, oursPacket / theirsStream, n, emPrimary / ourPrimaryPacket, n, emShadow / ourShadowPacket);
        std::printf("cells%d_embree_resident_mb=%.3f\n", n, double(em.resident) / 1e6);
        std::printf("cells%d_embree_instances=%zu\ncells%d_embree_mb=%.3f\ncells%d_memory_ratio=%.5f\ncells%d_rays_per_s_ratio=%.4f\n"
                    "cells%d_primary_ratio=%.4f\ncells%d_shadow_ratio=%.4f\ncells%d_primary_differ=%zu\ncells%d_shadow_differ=%zu\n",
                    n, em.instances, n, double(em.bytes) / 1e6, n, r.mb * 1e6 / double(em.bytes), n, ours / theirs, n, emPrimary / ourPrimary, n,
                    emShadow / ourShadow, n, primaryDiffer, n, shadowDiffer);
        std::fflush(stdout);
#endif
    }
    std::printf("\n| cells | triangles (thinned) | instances (thinned) | frame s | primary s | shadow s | frame s, 8x8 packets | frame s, "
                "rendered | build s | MB |\n"
                "|---|---|---|---|---|---|---|---|---|---|\n");
    for (const Row& r : rows)
        std::printf("| %d^2 | %.3g | %.3g | %.3f | %.3f | %.3f | %.3f | %.3f | %.2f | %.1f |\n", r.cells, r.triangles * r.keptFraction,
                    r.instances * r.keptFraction, r.primary + r.shadow, r.primary, r.shadow, r.primaryPacket + r.shadowPacket, r.rendered, r.build, r.mb);
    for (const Row& r : rows)
        std::printf("cells%d_frame_s=%.4f\ncells%d_build_s=%.4f\ncells%d_landscape_build_s=%.4f\ncells%d_mb=%.3f\ncells%d_triangles=%.4g\ncells%d_"
                    "triangles_thinned=%.4g\n",
                    r.cells, r.primary + r.shadow, r.cells, r.build, r.cells, r.landscapeBuild, r.cells, r.mb, r.cells, r.triangles, r.cells,
                    r.triangles * r.keptFraction);
    for (const Row& r : rows)
        std::printf("cells%d_packet_frame_s=%.4f\ncells%d_packet_speedup=%.4f\ncells%d_packet_differ=%zu\ncells%d_render_frame_s=%.4f\n", r.cells,
                    r.primaryPacket + r.shadowPacket, r.cells, (r.primary + r.shadow) / (r.primaryPacket + r.shadowPacket), r.cells, r.packetDiffer, r.cells,
                    r.rendered);
    if (rows.size() >= 2) {
        std::printf("scaling=%.4f\n", (rows.back().primary + rows.back().shadow) / (rows.front().primary + rows.front().shadow));
        std::printf("packet_scaling=%.4f\n",
                    (rows.back().primaryPacket + rows.back().shadowPacket) / (rows.front().primaryPacket + rows.front().shadowPacket));
        std::printf("render_scaling=%.4f\n", rows.back().rendered / rows.front().rendered);
    }
    if (kept[0] && kept[1] && pairs > 0) {
        // The scaling again, each pair's frames taken one right after the other: packets, single rays, rendered frames.
        auto median = [](std::vector<double> x) {
            std::sort(x.begin(), x.end());
            return x.size() % 2 ? x[x.size() / 2] : 0.5 * (x[x.size() / 2 - 1] + x[x.size() / 2]);
        };
        enum Kind { Packets, Single, Rendered };
        for (const Kind kind : {Packets, Single, Rendered}) {
            auto frame = [kind](FrameRun& run) { return kind == Packets ? run.packetFrame() : kind == Single ? run.singleFrame() : run.renderFrame(); };
            std::vector<double> t0, t1, ratio;
            for (int k = 0; k < pairs; ++k) {
                t0.push_back(frame(*kept[0]));
                t1.push_back(frame(*kept[1]));
                ratio.push_back(t1.back() / t0.back());
            }
            const auto [lo, hi] = std::minmax_element(ratio.begin(), ratio.end());
            const char* what = kind == Packets ? "packet" : kind == Single ? "single-ray" : "rendered (renderFilm)";
            const char* name = kind == Packets ? "packet_scaling" : kind == Single ? "scaling" : "render_scaling";
            std::printf("paired %s frames, %d pairs: %d^2 %.3f s, %d^2 %.3f s (medians); time(%d^2) / time(%d^2) %.3f (median of the pairs' "
                        "ratios, %.3f-%.3f)\n",
                        what, pairs, kept[0]->cells, median(t0), kept[1]->cells, median(t1), kept[1]->cells, kept[0]->cells, median(ratio), *lo, *hi);
            std::printf("%s_paired=%.4f\n", name, median(ratio));
        }
    }
    return 0;
}
