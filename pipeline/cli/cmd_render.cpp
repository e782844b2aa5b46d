// sylva render: a scene file (or the bundled default forest) to a picture, whole or in bands of rows.
#include <cstdio>
#include <filesystem>

#include "core/scene/quality.h"
#include "pipeline/cli/cli_util.h"
#include "pipeline/cli/commands.h"
#include "pipeline/cli/common_options.h"
#include "pipeline/io/env_map_io.h"
#include "pipeline/io/image_module.h"
#include "pipeline/io/output_path.h"
#include "pipeline/lighting_job.h"
#include "pipeline/render/display_view.h"
#include "pipeline/render/render_job.h"
#include "pipeline/render/render_passes.h"
#include "pipeline/scene/scene_file.h"
#include "pipeline/services/render_stats.h"
#if SYLVA_HAVE_MPI
#include "pipeline/mpi/mpi_render.h"
#endif

namespace fs = std::filesystem;

namespace sylva::cli {
namespace {

// The scene of the positional argument (or the default forest) with the options' overrides applied;
// stem: the output's default name.
Scene sceneForArgs(const Args& args, std::string* stem)
{
    Scene scene;
    *stem = "default_forest";
    if (args.positional().empty()) {
        scene = defaultScene();
    } else {
        const std::string path = args.positional()[0];
        requireReadable(path, "scene file");
        scene = readSceneFile(path);
        *stem = fs::path(path).stem().string();
        if (stem->size() > 6 && stem->substr(stem->size() - 6) == ".sylva") stem->resize(stem->size() - 6);
    }
    RenderSettings& r = scene.render;
    if (args.has("--quality")) {
        const QualityPreset* q = findQualityPreset(args.get("--quality"));
        if (!q) throw UsageError("option --quality: expected preview, final or reference, got '" + args.get("--quality") + "'");
        applyQuality(scene, *q);
    }
    if (args.has("--width")) r.width = int(parseInteger("--width", args.get("--width"), 1, 32768));
    if (args.has("--height")) r.height = int(parseInteger("--height", args.get("--height"), 1, 32768));
    if (args.has("--spp")) r.spp = int(parseInteger("--spp", args.get("--spp"), 1, 4096));
    if (args.has("--mode") && !parseRenderMode(args.get("--mode"), &r.mode))
        throw UsageError("option --mode: expected full, local, ambient or lb, got '" + args.get("--mode") + "'");
    if (args.has("--accel") && !parseAccel(args.get("--accel"), &r.accel))
        throw UsageError("option --accel: expected bvh or kdtree, got '" + args.get("--accel") + "'");
    if (args.has("--no-shadows")) r.shadows = false;
    if (args.has("--integrator") && !parseIntegrator(args.get("--integrator"), &r.integrator))
        throw UsageError("option --integrator: expected lb or path, got '" + args.get("--integrator") + "'");
    if (args.has("--max-bounces")) r.maxBounces = int(parseInteger("--max-bounces", args.get("--max-bounces"), 0, kMaxPathBounces));
    if (args.has("--bounce-samples")) r.bounceSamples = int(parseInteger("--bounce-samples", args.get("--bounce-samples"), 0, 4096));
    if (args.has("--direct") && !parseDirectLight(args.get("--direct"), &scene.lighting.direct))
        throw UsageError("option --direct: expected once or seed, got '" + args.get("--direct") + "'");
    if (args.has("--bounces")) scene.lighting.bounces = int(parseInteger("--bounces", args.get("--bounces"), 0, kMaxPathBounces));
    if (args.has("--cells")) {
        if (!scene.terrain.enabled()) throw UsageError("option --cells: the scene has no terrain");
        scene.terrain.cells = int(parseInteger("--cells", args.get("--cells"), 1, 65536));
        if (scene.terrain.tiles.plants.empty()) throw UsageError("option --cells: the scene's terrain has no tiles (terrain.tiles)");
    }
    if (args.has("--forest-grid") && !parseForestGridMode(args.get("--forest-grid"), &scene.lighting.forestGrid))
        throw UsageError("option --forest-grid: expected off, auto or on, got '" + args.get("--forest-grid") + "'");
    if (args.has("--forest-grid-resolution")) {
        const long long n = parseInteger("--forest-grid-resolution", args.get("--forest-grid-resolution"), 0, 512);
        if (n > 0 && n < 4) throw UsageError("option --forest-grid-resolution: expected 0 (automatic) or 4 .. 512, got " + std::to_string(n));
        scene.lighting.forestGridResolution = int(n);
    }
    if (args.has("--sun") && args.has("--sun-at")) throw UsageError("give either --sun or --sun-at, not both");
    if (args.has("--sun")) {
        if (args.get("--sun").find(',') == std::string::npos) throw UsageError("option --sun: expected X,Y,Z");
        scene.sun.direction = parseTriple("--sun", args.get("--sun"));
        if (!(glm::length(scene.sun.direction) > 0.0f)) throw UsageError("option --sun: the direction must not be zero");
        scene.sun.place.reset();
    }
    if (args.has("--sun-at")) {
        scene.sun.place = parseSunAt(args.get("--sun-at"));
        scene.sun.direction = sky::placeSunDirection(*scene.sun.place);
    }
    if ((args.has("--sun") || args.has("--sun-at")) && scene.skyModel.kind == sky::SkyKind::Preetham) {
        scene.skyModel.built.reset();   // the Preetham sky follows its sun
        loadSceneSky(scene);
    }
    for (auto [option, field] : {std::pair{"--alpha-distance", &r.alphaDistance}, std::pair{"--prune-distance", &r.pruneDistance}}) {
        if (!args.has(option)) continue;
        const double m = parseNumber(option, args.get(option));
        if (m < 0.0 || m > 1e30) throw UsageError(std::string("option ") + option + ": expected metres >= 0 (0: off), got " + args.get(option));
        *field = float(m);
    }
    if (args.has("--view")) r.view = args.get("--view");
    if (args.has("--display")) r.display = args.get("--display");
    if (args.has("--volume-tracer")) {
        VolumeTracer t;
        if (!parseVolumeTracer(args.get("--volume-tracer"), &t))
            throw UsageError("option --volume-tracer: expected lb, single or combined, got '" + args.get("--volume-tracer") + "'");
        for (VolumeDesc& v : scene.volumes) {
            v.tracer = t;
            v.lit = t != VolumeTracer::Single;   // single scattering solves no LB grid
        }
    }
    return scene;
}

void printStats(const AccelStats& st, const RenderTimings& timings, const RenderSettings& r, float ambient)
{
    std::printf("time: assets %.3f s, build %.3f s, trace %.3f s\n", timings.assets, timings.build, timings.trace);
    const AccelSummary s = summarizeAccel(st);
    std::printf("acceleration structures: %.1f MB (tlas %zu B, instances %zu B, blas %zu B, triangles %zu B, the CPU's "
                "8-wide copies: tlas %zu B, blas %zu B); %.4f B per instanced triangle, %.1f B per instance; depth tlas %d, "
                "blas %d\n",
                s.totalBytes / 1e6, st.tlasBytes, st.instanceBytes, st.blasBytes, st.triangleBytes, st.wideTlasBytes, st.wideBlasBytes,
                s.bytesPerInstancedTriangle, s.bytesPerInstance, st.tlasDepth, st.maxBlasDepth);
    if (st.prunedLevels > 0) {
        std::printf("pruning from %g m: %zu pruned levels built (%.1f MB); instances per level (kept 1, 1/2, 1/4, ...):",
                    double(r.pruneDistance), st.prunedLevels, double(st.pruneBytes) / 1e6);
        for (size_t n : st.instancesPerLevel) std::printf(" %zu", n);
        std::printf("\n");
    }
    if (st.terrainBytes > 0)
        std::printf("terrain: %zu x %zu samples, %.0f triangles implied, %.1f MB of heights and min/max pyramid\n", st.terrainSamplesX,
                    st.terrainSamplesZ, double(st.terrainSamplesX - 1) * double(st.terrainSamplesZ - 1) * 2.0, double(st.terrainBytes) / 1e6);
    if (st.landscapeBytes > 0)
        std::printf("landscape: %zu cells, %zu tiles of %zu-%zu plants, %.3g potentially visible instances, %.3g triangles, %.1f MB, built in %.2f s\n",
                    st.landscape.cells, st.landscape.tiles, st.landscape.plantsPerTileMin, st.landscape.plantsPerTileMax, st.landscape.instances,
                    st.landscape.triangles, double(st.landscapeBytes) / 1e6, st.landscape.buildSeconds);
    std::fputs(forestGridLine(st.forestGrid, st.landscapeLight).c_str(), stdout);
    if (r.mode == RenderMode::Ambient) std::printf("ambient constant %.4f\n", ambient);
}

// Whether this process writes the picture: always, except on the ranks other than 0 of --mpi.
bool writesPicture(bool useMpi)
{
#if SYLVA_HAVE_MPI
    return !useMpi || mpi::launchRank() == 0;
#else
    (void)useMpi;
    return true;
#endif
}

int runRender(const Args& args)
{
    if (args.has("--list-views")) {
        std::fputs(describeViews(colorConfig()).c_str(), stdout);
        return kOk;
    }
    const bool useMpi = args.has("--mpi");
#if SYLVA_HAVE_MPI
    if (useMpi && !mpi::launchedByMpi())
        throw UsageError("option --mpi: this process was not started by mpirun; run: mpirun -np N sylva render --mpi ... "
                         "(docs/DISTRIBUTED.md), or drop --mpi");
#else
    if (useMpi)
        throw UsageError("option --mpi: this sylva was built without MPI (configure with -DSYLVA_ENABLE_MPI=ON where an MPI "
                         "library is installed, e.g. Debian's libopenmpi-dev)");
#endif
    if (!useMpi && args.has("--mpi-timeout")) throw UsageError("option --mpi-timeout: applies to --mpi only");
    if (!useMpi && args.has("--mpi-scene")) throw UsageError("option --mpi-scene: applies to --mpi only");
    const std::string mpiScene = args.get("--mpi-scene", "broadcast");
    if (mpiScene != "broadcast" && mpiScene != "each")
        throw UsageError("option --mpi-scene: expected broadcast or each, got '" + mpiScene + "'");
    // Under --mpi the ranks set their own thread limits (rank 0 builds with its node's threads).
    auto threads = useMpi ? nullptr : threadLimit(args);
    const std::string backend = backendName(args);
    std::string stem;
    const Scene scene = sceneForArgs(args, &stem);
    const RenderSettings& r = scene.render;
    const bool passes = args.has("--passes");
    const std::string out = args.get("--output", stem + (passes ? ".exr" : ".png"));
    const std::string ext = lowerExtension(out);
    if (ext != ".png" && ext != ".exr" && ext != ".tif" && ext != ".tiff")
        throw UsageError("output " + out + ": unknown image extension (use .png, .exr, .tif or .tiff)");
    if (passes && ext != ".exr")
        throw UsageError("option --passes: the passes are layers of one multi-layer EXR; use -o NAME.exr, not " + out);
    if (passes && args.has("--band-rows")) throw UsageError("option --passes: a frame in bands cannot be written with passes; drop --band-rows");
    // The view is found before any work: an unknown name (the option's a usage error) lists the views there are.
    DisplayTransform display;
    const bool viewOption = args.has("--view") || args.has("--display");
    if (viewOption || (ext != ".exr" && !passes)) {
        try {
            display = displayTransformOf(r);
        } catch (const Error& e) {
            if (viewOption) throw UsageError(std::string("option --view/--display: ") + e.what());
            throw;
        }
        if (viewOption && ext == ".exr")
            std::fprintf(stderr, "note: %s stays scene-linear (Rec.709); the view applies to .png and .tif pictures\n", out.c_str());
    }
    const bool writer = writesPicture(useMpi);
    if (writer) {
        requireReplaceableFile(out);
        image_module::requireFindable();   // loaded when the picture is written
    }
    int bandRows = 0;   // 0: the whole frame at once
    if (args.has("--band-rows")) bandRows = int(parseInteger("--band-rows", args.get("--band-rows"), 1, 32768));
    else if (!frameFitsMemory(r)) bandRows = bandRowsFor(r);
    if (bandRows >= r.height) bandRows = 0;
    if (passes && bandRows > 0)
        throw Error("--passes: the " + std::to_string(r.width) + "x" + std::to_string(r.height) +
                    " frame does not fit in the available memory and would be traced in bands, which writes no passes; "
                    "render a smaller frame or without --passes");
    auto compute = openBackend(backend);
    auto cache = openCache(args);
    // The render and its picture, its tracing by `tracer` when given (--mpi: the ranks'), on `ranks` processes.
    auto renderAndWrite = [&](const FilmRowsTracer& tracer, int ranks, int hosts, const std::function<void()>& beforeCompute) {
        // The hook holds the MPI lead's state: it leaves the cache with this render.
        struct Hook {
            GridCache* cache;
            ~Hook()
            {
                if (cache) cache->setBeforeCompute({});
            }
        } hook{cache && beforeCompute ? cache.get() : nullptr};
        if (hook.cache) hook.cache->setBeforeCompute(beforeCompute);
        JobLog log;
        AccelStats st;
        RenderTimings timings;
        float ambient = 0.0f;
        std::string device = compute->name();
        if (bandRows > 0) {
            const int bands = (r.height + bandRows - 1) / bandRows;
            std::fprintf(stderr, "note: tracing the %dx%d frame in %d bands of %d rows%s\n", r.width, r.height, bands, bandRows,
                         args.has("--band-rows") ? "" : " (the whole frame does not fit in the available memory)");
            if (device != "cpu") std::fprintf(stderr, "note: a frame in bands is traced on the CPU (the LB solves still run on %s)\n", device.c_str());
            ProgressPrinter bar("render", args.has("--quiet"));
            const BandedRender result = renderSceneInBands(scene, out, bandRows, cache.get(), &bar.progress(), &log, compute.get(), tracer);
            bar.finish();
            st = result.stats;
            timings = result.timings;
            ambient = result.ambient;
            device = "cpu, " + std::to_string(bands) + " bands";
        } else {
            ProgressPrinter bar("render", args.has("--quiet"));
            const RenderOutput result = renderScene(scene, cache.get(), &bar.progress(), &log, compute.get(), tracer, passes);
            bar.finish();
            if (passes) {
                RenderPasses layers = renderPasses(result.film, r.mode, composeSky(scene));
                layers.cryptomatte = cryptomatteLayers(result.mattes, scene);
                writeRenderPasses(out, layers);
                ambient = layers.ambient;
            } else {
                const std::vector<glm::vec3> linear = composeMode(result.film, r.mode, composeSky(scene), &ambient);
                writeRender(out, linear, r.width, r.height, r.exposureKey, display);
            }
            st = result.stats;
            timings = result.timings;
        }
        if (tracer) {
            device = (bandRows > 0 ? device : std::string("cpu")) + ", " + std::to_string(ranks) + (ranks == 1 ? " MPI rank" : " MPI ranks");
            if (hosts > 0) device += " on " + std::to_string(hosts) + (hosts == 1 ? " host" : " hosts") + " (a copy of the frame per host)";
        }
        for (const auto& w : log.warnings) std::fprintf(stderr, "warning: %s\n", w.c_str());
        std::printf("rendered %dx%d, %d spp, mode %s, %zu instances of %zu species (%.0f instanced triangles) on %s\nwrote %s\n",
                    r.width, r.height, r.spp, renderModeName(r.mode), st.instances, scene.species.size(), st.instancedTriangles,
                    device.c_str(), out.c_str());
        if (args.has("--stats")) printStats(st, timings, r, ambient);
        return kOk;
    };
    if (!useMpi) return renderAndWrite({}, 1, 0, {});
#if SYLVA_HAVE_MPI
    mpi::RenderJob job;
    job.prepare = [&](Progress* progress) {
        RenderTimings t;
        return prepareRenderScene(scene, cache.get(), progress, nullptr, compute.get(), t);
    };
    job.lead = renderAndWrite;
    // Species lighting across the ranks: species s is solved by rank s mod N into the shared cache.
    if (cache && modeNeedsLighting(r.mode))
        job.lightShare = [&](int rank, int ranks, Progress* progress) {
            int solves = 0;
            for (size_t s = size_t(rank); s < scene.species.size(); s += size_t(ranks)) {
                JobLog lit;
                loadSpeciesGrids(scene, s, cache.get(), progress, &lit, nullptr, compute.get());
                for (const std::string& stage : lit.stages) solves += stage == "light" ? 1 : 0;
            }
            return solves;
        };
    job.broadcastScene = mpiScene == "broadcast";
    if (args.has("--threads")) job.threads = int(parseInteger("--threads", args.get("--threads"), 1, 1024));
    if (args.has("--mpi-timeout")) job.timeoutSeconds = double(parseInteger("--mpi-timeout", args.get("--mpi-timeout"), 1, 86400));
    return mpi::runRender(job);
#else
    return kFailure;
#endif
}

} // namespace

Command renderCommand()
{
    return {"render", "[SCENE.sylva.json] [-o OUT.png|.exr|.tif] [--passes -o OUT.exr]",
            "render a scene (the bundled default forest when none is given)",
            {{"--quality", "preview|final|reference", "quality preset: LB grid, steps and storage of every species, samples and distance knobs, "
                                                 "integrator and lighting (preview, final: the LB grid as a radiance cache after 1 and 2 bounces; "
                                                 "reference: the path tracer; docs/ACCURACY.md); the options below override it"},
             {"--width", "W", "image width in pixels (default: the scene's)"},
             {"--height", "H", "image height in pixels (default: the scene's)"},
             {"--spp", "N", "samples per pixel, 1..4096 (default: the scene's)"},
             {"--mode", "M", "full (LB indirect + sun), local (sun only), ambient (sun + matched constant), lb"},
             {"--accel", "bvh|kdtree", "acceleration structure (default: the scene's, bvh)"},
             {"--no-shadows", "", "no shadow rays"},
             {"--integrator", "lb|path", "lb: the LB model (default: the scene's render.integrator); path: the reference path tracer, "
                                         "every bounce with next-event estimation to the sun and sky (docs/RENDERING.md \"The path tracer\")"},
             {"--max-bounces", "N", "path: bounces after the camera's hit, 0 .. 100 (default: the scene's render.max_bounces, 64)"},
             {"--bounce-samples", "N", "lb with --bounces > 0: samples of a pixel that trace the bounces, the others sharing their light by "
                                      "albedo; 0 = all (default: the scene's render.bounce_samples; docs/RENDERING.md \"Bounce samples\")"},
             {"--direct", "once|seed", "once: the LB grids add only scattered light to the shadow-rayed sun; seed: the seed's sum "
                                   "(grid as solved, direct light counted twice in crowns); default: the scene's lighting.direct"},
             {"--bounces", "N", "lb: bounces a camera path traces before the LB grid's scattered light ends it, 0 .. 100 "
                                "(0: the grid at the camera's hit; default: the scene's lighting.bounces; docs/RENDERING.md "
                                "\"The LB grid as a radiance cache\")"},
             {"--cells", "N", "plant cells along the terrain's longer side (terrain.cells; the scene needs terrain.tiles)"},
             {"--sun", "X,Y,Z", "direction toward the sun (+Y up, any length), replacing the scene's"},
             kSunAt,
             {"--forest-grid", "off|auto|on", "the forest-level LB grid (default: the scene's lighting.forest_grid; auto: only where "
                                              "exposure differs)"},
             {"--forest-grid-resolution", "N", "forest grid nodes along the plants' longest horizontal extent, 4 .. 512, or 0: "
                                               "automatic, 4 across the median crown, at most 32 (default: the scene's)"},
             {"--alpha-distance", "M", "skip leaf cut-out tests beyond M metres from the camera (0: off, default)"},
             {"--prune-distance", "M", "prune leaves of plants beyond M metres, area-preserving (0: off, default)"},
             {"--volume-tracer", "lb|single|combined", "every volume's tracer, replacing its scene's `tracer` (default lb, the "
                                                       "accuracy study's pick: docs/ACCURACY.md \"Volumes\"); single: sun single "
                                                       "scattering with shadow marches, combined: single + the LB's multiple scattering"},
             {"--view", "NAME", "the picture's display transform (default: the scene's render.view, \"Sylva Reinhard\": the seed's Reinhard "
                                "curve); or a view of the OpenColorIO config, $OCIO's when set, else the bundled one's: Standard, \"ACES 1.0 "
                                "SDR-video\", \"Sylva Filmic\" (docs/RENDERING.md \"Display transforms\"); .exr stays scene-linear"},
             {"--display", "NAME", "the OpenColorIO display of --view (default: the scene's render.display, else the config's default display)"},
             {"--list-views", "", "print the OpenColorIO config's displays and their views (and where the config comes from), then exit"},
             kBackend,
             {"--band-rows", "N", "trace and write the frame in bands of N rows (default: only when the whole frame does not fit in memory)"},
             {"--passes", "", "write one multi-layer EXR (32-bit float) of the render passes: Combined, DiffDir, DiffInd, DiffCol, Env, Normal, Depth, Alpha, and the Cryptomatte ID mattes CryptoObject, CryptoMaterial, CryptoAsset (docs/RENDERING.md); default output NAME.exr"},
             {"--stats", "", "print timings and acceleration structure sizes"},
             {"--mpi", "", "trace the frame across the ranks of an MPI job, tiles from a work queue on rank 0: mpirun -np N sylva render --mpi ... (docs/DISTRIBUTED.md)"},
             {"--mpi-timeout", "S", "with --mpi: end the job when a rank stays silent S seconds (default 10)"},
             {"--mpi-scene", "broadcast|each", "with --mpi: rank 0 builds the frame and hands it to the other ranks, one shared copy per host (default), or "
                                               "every rank builds its own from the species assets (docs/DISTRIBUTED.md)"},
             kOutput, kCache, kNoCache, kThreads, kQuiet},
            0, 1, &runRender};
}

} // namespace sylva::cli
