// sylva reference: the Monte Carlo reference lighting (mean and standard error), optionally compared
// with an LB grid.
#include <cstdio>
#include <optional>

#include "core/base/error.h"
#include "core/base/param_spec.h"
#include "core/reference/mc_reference.h"
#include "pipeline/cli/cli_util.h"
#include "pipeline/cli/commands.h"
#include "pipeline/cli/common_options.h"
#include "pipeline/cli/grid_options.h"
#include "pipeline/io/grid_file.h"
#include "pipeline/io/npy.h"
#include "pipeline/io/output_path.h"
#include "pipeline/services/grid_stats.h"
#include "pipeline/services/reference_stats.h"
#include "pipeline/services/sidecars.h"

namespace sylva::cli {
namespace {

int runReference(const Args& args)
{
    auto threads = threadLimit(args);
    if (args.has("--density") == args.has("--mesh"))
        throw UsageError("'sylva reference' needs exactly one of --density FILE or --mesh FILE");
    const lb::LbParams params = lightParams(args);
    ReferenceSettings settings;
    if (args.has("--paths"))
        settings.paths = uint64_t(parseInteger("--paths", args.get("--paths"), 2, (long long)kMaxReferencePaths));
    if (args.has("--seed")) settings.seed = uint64_t(parseInteger("--seed", args.get("--seed"), 0, (long long)kMaxSeed));
    if (args.has("--max-bounces")) settings.maxBounces = int(parseInteger("--max-bounces", args.get("--max-bounces"), 0, 1000000000));
    if (args.has("--collimated")) settings.incidence = Incidence::Collimated;
    const VoxelizeSettings voxel = voxelSettings(args);
    rejectMeshOptionsWithDensity(args);
    const std::string out = outputFile(args, {".npy"});   // with its standard error file: .npy only
    const std::string errPath = standardErrorPath(out);
    for (const std::string& target : {out, gridSidecarPath(out), errPath, gridSidecarPath(errPath)}) requireReplaceableFile(target);
    std::optional<LightingGrid> compare;
    if (args.has("--compare")) {
        requireReadable(args.get("--compare"), "lighting grid");
        compare = readLightingFile(args.get("--compare"));
    }
    auto cache = openCache(args);
    JobLog log;
    const DensityGrid density = loadDensityInput(args, voxel, cache.get(), log);
    if (compare && compare->geometry.dims != density.geometry.dims)
        throw Error(args.get("--compare") + ": grid " + gridDimsText(compare->geometry) + " differs from the density grid " +
                    gridDimsText(density.geometry));
    printDensitySummary(density);
    ProgressPrinter bar("reference", args.has("--quiet"));
    const ReferenceResult ref = solveReference(density, params, settings, &bar.progress());
    bar.finish();
    for (const auto& w : log.warnings) std::fprintf(stderr, "warning: %s\n", w.c_str());
    // The sidecars record what produced the grids.
    const std::string preset = args.get("--preset", "leaf");
    writeLightingGrid(out, ref.mean, referenceParamsJson(params, preset, settings, ReferenceQuantity::Mean));
    const LightingGrid seGrid{ref.mean.geometry, ref.standardError};
    writeLightingGrid(errPath, seGrid, referenceParamsJson(params, preset, settings, ReferenceQuantity::StandardError));

    const ReferenceSummary summary = summarizeReference(ref, params);
    const glm::dvec3 mean = summary.meanNormalized;
    std::printf("reference %s: %llu paths x %d channel solves in %.1f s, %.2f collisions per path; mean RGB / unobstructed "
                "(%.4f, %.4f, %.4f), relative noise %.4f (interior nodes)\nwrote %s (+ %s)\n",
                gridDimsText(summary.normalized.geometry).c_str(), (unsigned long long)ref.paths, ref.channelSolves, ref.seconds,
                ref.collisionsPerPath, mean.x, mean.y, mean.z, summary.relativeNoise, out.c_str(), errPath.c_str());
    if (compare) {
        const ReferenceComparison c = compareWithReference(std::move(*compare), summary, params);
        std::printf("%s against the reference (both / unobstructed value, interior nodes): relative L2 error %.4f "
                    "(R %.4f, G %.4f, B %.4f), reference noise %.4f, without the noise ~%.4f; mean LB / mean reference %.4f\n",
                    args.get("--compare").c_str(), c.relativeL2, c.relativeL2PerChannel.x, c.relativeL2PerChannel.y,
                    c.relativeL2PerChannel.z, c.noise, c.withoutNoise, c.meanRatio);
    }
    return kOk;
}

} // namespace

Command referenceCommand()
{
    return {"reference", "(--density DENSITY.npy | --mesh MESH) (--sun X,Y,Z | --sun-at DATE,TIME,ZONE,LAT,LON) -o REF.npy",
            "Monte Carlo reference lighting (slow; measures the LB model): mean and standard error",
            {{"--density", "FILE", "density grid: .npy from sylva voxelize, or .vdb (the float grid 'density', else the first float grid)"},
             {"--mesh", "FILE", "mesh to voxelize first (with --grid)"},
             kGrid, kSubcells, kLeafMaterials,
             {"--preset", "NAME", "leaf (default), dogrose, cloud or pmma (the optics of sylva light)"},
             {"--sigma-a", "R,G,B", "absorption per lattice step (one number: all channels)"},
             {"--sigma-s", "R,G,B", "scattering per lattice step; sigma_a + sigma_s <= 1"},
             {"--g", "R,G,B", "Henyey-Greenstein asymmetry in [-1, 1]"},
             {"--keep-f0", "", "absorbed light is re-emitted isotropically (clouds, plastics)"},
             {"--zero-f0", "", "absorbed light is removed (plants)"},
             {"--sun", "X,Y,Z", "direction toward the sun (any length)"},
             kSunAt,
             {"--intensity", "R,G,B", "sun intensity per channel (default 1)"},
             {"--paths", "N", "paths per channel (default 1000000); the error falls as 1/sqrt(N)"},
             {"--seed", "S", "random seed (default 1); the same seed gives the same bits"},
             {"--max-bounces", "K", "scattering events per path (default unlimited; 0: direct light only)"},
             {"--collimated", "", "one beam along the sun instead of the LB's 18 lattice beams"},
             {"--compare", "LIGHT.npy|.vdb", "print the normalized error of this LB grid against the reference"},
             kOutput, kCache, kNoCache, kThreads, kQuiet},
            0, 0, &runReference};
}

} // namespace sylva::cli
