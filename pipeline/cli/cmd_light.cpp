// sylva light: the LB lighting of a density grid (or of a mesh voxelized first), through the grid cache.
#include <cstdio>

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

int runLight(const Args& args)
{
    auto threads = threadLimit(args);
    if (args.has("--density") == args.has("--mesh")) throw UsageError("'sylva light' needs exactly one of --density FILE or --mesh FILE");
    auto compute = openBackend(backendName(args));
    const lb::LbParams params = lightParams(args);
    auto cache = openCache(args);
    JobLog log;
    const VoxelizeSettings voxel = voxelSettings(args);
    rejectMeshOptionsWithDensity(args);
    const PictureOptions picture = pictureOptions(args);
    const std::string out = outputFile(args, gridFileExtensions());
    requireReplaceableFile(out);
    const DensityGrid density = loadDensityInput(args, voxel, cache.get(), log);
    printDensitySummary(density);
    ProgressPrinter bar("light", args.has("--quiet"));
    const LightingGrid light = lightingFor(density, params, cache.get(), &bar.progress(), &log, compute.get());
    bar.finish(log.stages.back());
    for (const auto& w : log.warnings) std::fprintf(stderr, "warning: %s\n", w.c_str());
    // The sidecar records what produced the grid: the optics actually used (after any overrides).
    // A .vdb holds the density beside the lighting (one file for a renderer); .npy the lighting alone.
    writeLightingFile(out, light, lightingParamsJson(params, args.get("--preset", "leaf"), density.geometry.dims), &density);
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
             {"--preset", "NAME", "leaf (default), dogrose, cloud or pmma"},
             {"--sigma-a", "R,G,B", "absorption per lattice step (one number: all channels)"},
             {"--sigma-s", "R,G,B", "scattering per lattice step; sigma_a + sigma_s <= 1"},
             {"--g", "R,G,B", "Henyey-Greenstein asymmetry in [-1, 1]"},
             {"--keep-f0", "", "keep absorbed light (clouds, plastics)"},
             {"--zero-f0", "", "zero f_0 after each step (plants)"},
             {"--sun", "X,Y,Z", "direction toward the sun (any length)"},
             kSunAt,
             {"--intensity", "R,G,B", "sun intensity per channel (default 1)"},
             {"--steps", "N", "fixed step count (default 2 x the longest grid edge)"},
             {"--tol", "T", "stop when the relative change per step falls under T"},
             {"--fp16", "", "store the distributions in half precision (half the memory)"},
             {"--warm-start", "", "start from the unobstructed light field: same steady state, fewer steps"},
             {"--coarse-start", "", "with --tol: solve on half-resolution grids first and start from that (fastest to a given error)"},
             kBackend,
             {"--output", "FILE", "output file (also -o): .npy (+ sidecar), or .vdb (lighting, its channels, density and wood fraction)"},
             kPicture, kSlices, kAxis, kCache, kNoCache, kThreads, kQuiet},
            0, 0, &runLight};
}

} // namespace sylva::cli
