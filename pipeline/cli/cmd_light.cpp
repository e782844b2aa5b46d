// sylva light: the LB lighting of a density grid (or of a mesh voxelized first), through the grid cache.
#include <cstdio>

#include "core/base/error.h"
#include "core/lb/lb_basis.h"
#include "pipeline/cli/cli_util.h"
#include "pipeline/cli/commands.h"
#include "pipeline/cli/common_options.h"
#include "pipeline/cli/grid_options.h"
#include "pipeline/io/grid_file.h"
#include "pipeline/io/output_path.h"
#include "pipeline/lighting_job.h"
#include "pipeline/services/grid_stats.h"

namespace sylva::cli {
namespace {

// sylva light's defaults on the measured front (issue 18 item 3): fp16, 1 x the longest edge, unless
// --seed-steps (the seed's fp32, 2 x the longest edge), --steps/--tol or --fp32 say otherwise. Parameters
// fp16 cannot hold (a large intensity) fall back to fp32 with a note.
void applyLightDefaults(const Args& args, lb::LbParams& p)
{
    if (args.has("--seed-steps") && (args.has("--steps") || args.has("--tol")))
        throw UsageError("--seed-steps and --steps/--tol exclude each other");
    if (args.has("--fp32") && args.has("--fp16")) throw UsageError("--fp16 and --fp32 exclude each other");
    if (args.has("--seed-steps")) {
        p.stepsPerEdge = 2;
        if (!args.has("--fp16")) p.storage = lb::Storage::Fp32;
        return;
    }
    const lb::Storage asked = p.storage;
    lb::useFrontDefaults(p);
    if (args.has("--fp32")) p.storage = lb::Storage::Fp32;
    else if (asked == lb::Storage::Fp32 && !args.has("--fp16")) {
        try {
            lb::validate(p);
        } catch (const Error&) {
            p.storage = lb::Storage::Fp32;   // e.g. an intensity over fp16's range
            std::fprintf(stderr, "note: fp32 storage (these parameters do not fit the default fp16)\n");
        }
    }
}

int runLight(const Args& args)
{
    auto threads = threadLimit(args);
    if (args.has("--density") == args.has("--mesh")) throw UsageError("'sylva light' needs exactly one of --density FILE or --mesh FILE");
    auto compute = openBackend(backendName(args));
    lb::LbParams params = lightParams(args);
    applyLightDefaults(args, params);
    auto cache = openCache(args);
    if (args.has("--basis") && !cache) throw UsageError("--basis stores the relighting basis in the grid cache; it cannot be used with --no-cache");
    if (args.has("--basis") && params.tolerance > 0.0)
        throw UsageError("--basis needs fixed steps (a tolerance solve is not linear in the boundary); drop --tol");
    const std::string part = args.get("--part", "all");
    if (part != "all" && part != "scattered" && part != "uncollided")
        throw UsageError("option --part: expected all, scattered or uncollided, got '" + part + "'");
    JobLog log;
    VoxelizeSettings voxel = voxelSettings(args);
    voxel.solid = args.has("--solid");   // plastics: the interior filled (winding numbers), as sylva voxelize --solid
    rejectMeshOptionsWithDensity(args);
    const PictureOptions picture = pictureOptions(args);
    const std::string out = outputFile(args, gridFileExtensions());
    requireReplaceableFile(out);
    const DensityGrid density = loadDensityInput(args, voxel, cache.get(), log);
    printDensitySummary(density);
    ProgressPrinter bar("light", args.has("--quiet"));
    LightingGrid light;
    if (args.has("--basis")) {
        const LightingBasis basis = lightingBasisFor(density, params, cache.get(), &bar.progress(), &log, compute.get());
        light = relight(basis, params);
        bar.finish("relit from the basis");
        std::printf("relighting basis: %zu directions, %.1f MB in memory (fp32 grids), in the cache for later --sun\n",
                    basis.grids.size(), basisBytes(basis) / 1e6);
    } else {
        light = lightingFor(density, params, cache.get(), &bar.progress(), &log, compute.get());
        bar.finish(log.stages.back());
    }
    if (part != "all") {
        // The first collision separated (issue 18 item 4): the same LB with scattering off is the uncollided light.
        ProgressPrinter ubar("uncollided", args.has("--quiet"));
        JobLog ulog;
        const LightingGrid uncollided = lightingFor(density, lb::uncollidedParams(params), cache.get(), &ubar.progress(), &ulog, compute.get());
        ubar.finish(ulog.stages.back());
        light = part == "uncollided" ? uncollided : lb::scatteredPart(light, uncollided);
    }
    for (const auto& w : log.warnings) std::fprintf(stderr, "warning: %s\n", w.c_str());
    // The sidecar records what produced the grid: the optics actually used (after any overrides).
    // A .vdb holds the density beside the lighting (one file for a renderer); .npy the lighting alone.
    std::string sidecar = lightingParamsJson(params, args.get("--preset", "leaf"), density.geometry.dims);
    if (part != "all") sidecar.insert(sidecar.size() - 1, ",\"part\":\"" + part + "\"");
    writeLightingFile(out, light, sidecar, &density);
    const ChannelStats s = channelStats(light);
    std::printf("lighting grid %s: mean RGB (%.4f, %.4f, %.4f), max RGB (%.4f, %.4f, %.4f)\nwrote %s\n",
                gridDimsText(light.geometry).c_str(), s.mean.x, s.mean.y, s.mean.z, s.max.x, s.max.y, s.max.z, out.c_str());
    writePicture(picture, &density, &light);
    return kOk;
}

} // namespace

Command lightCommand()
{
    return {"light", "(--density DENSITY.npy|.vdb | --mesh MESH) (--sun X,Y,Z | --sun-at DATE,TIME,ZONE,LAT,LON) -o LIGHT.npy|.vdb",
            "solve the lattice-Boltzmann lighting of a density grid",
            {{"--density", "FILE", "density grid: .npy from sylva voxelize, or .vdb (the float grid 'density', else the first float grid)"},
             {"--mesh", "FILE", "mesh to voxelize first (with --grid)"},
             kGrid, kSubcells, kLeafMaterials,
             {"--solid", "", "with --mesh: voxelize it as a solid (interior filled, as sylva voxelize --solid; e.g. --preset pmma)"},
             {"--preset", "NAME", "leaf (default), dogrose, cloud or pmma"},
             {"--sigma-a", "R,G,B", "absorption per lattice step (one number: all channels)"},
             {"--sigma-s", "R,G,B", "scattering per lattice step; sigma_a + sigma_s <= 1"},
             {"--g", "R,G,B", "Henyey-Greenstein asymmetry in [-1, 1]"},
             {"--keep-f0", "", "keep absorbed light (clouds, plastics)"},
             {"--zero-f0", "", "zero f_0 after each step (plants)"},
             {"--sun", "X,Y,Z", "direction toward the sun (any length)"},
             kSunAt,
             {"--intensity", "R,G,B", "sun intensity per channel (default 1)"},
             {"--steps", "N", "fixed step count (default 1 x the longest grid edge, fp16: a point on the measured front, "
                              "0.9% relative L2 from the seed's configuration on the 128^3 benchmark crown)"},
             {"--seed-steps", "", "the seed's configuration: 2 x the longest edge in fp32 (with --fp16: in fp16)"},
             {"--fp32", "", "store the distributions in single precision (the default is fp16)"},
             {"--basis", "", "solve (or load) the relighting basis (18 solves, one per lattice direction) into the cache and "
                             "compose --sun from it; later runs of any --sun on this grid and optics relight from it, no solve"},
             {"--part", "all|scattered|uncollided", "all light (default, the seed's), only the scattered part (the "
                                                    "renderer's shadow rays draw the direct sun), or only the uncollided sunlight"},
             {"--tol", "T", "stop when the relative change per step falls under T"},
             {"--fp16", "", "store the distributions in half precision (the default; with --seed-steps half the memory)"},
             {"--warm-start", "", "start from the unobstructed light field: same steady state, fewer steps"},
             {"--coarse-start", "", "with --tol: solve on half-resolution grids first and start from that (fastest to a given error)"},
             kBackend,
             {"--output", "FILE", "output file (also -o): .npy (+ sidecar), or .vdb (lighting, its channels, density and wood fraction)"},
             kPicture, kSlices, kAxis, kCache, kNoCache, kThreads, kQuiet},
            0, 0, &runLight};
}

} // namespace sylva::cli
