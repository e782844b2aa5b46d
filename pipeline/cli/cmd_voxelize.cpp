// sylva voxelize: a mesh into a density grid (+ wood fraction), through the grid cache.
#include <cstdio>

#include "pipeline/cli/cli_util.h"
#include "pipeline/cli/commands.h"
#include "pipeline/cli/common_options.h"
#include "pipeline/cli/grid_options.h"
#include "pipeline/io/npy.h"
#include "pipeline/io/output_path.h"
#include "pipeline/lighting_job.h"

namespace sylva::cli {
namespace {

int runVoxelize(const Args& args)
{
    auto threads = threadLimit(args);
    const std::string mesh = args.positional()[0];
    const std::string out = args.require("--output");
    DensityJob job{mesh, importOptions(args), voxelSettings(args)};   // usage errors before file errors
    const PictureOptions picture = pictureOptions(args);
    requireReadable(mesh, "mesh file");
    requireReplaceableFile(out);
    auto cache = openCache(args);
    ProgressPrinter bar("voxelize", args.has("--quiet"));
    JobLog log;
    const DensityGrid grid = densityForMesh(job, cache.get(), &bar.progress(), &log);
    writeDensityGrid(out, grid);
    bar.finish(log.stages.empty() ? "" : log.stages.back());
    for (const auto& w : log.warnings) std::fprintf(stderr, "warning: %s\n", w.c_str());
    printDensitySummary(grid);
    std::printf("wrote %s (+ %s, %s)\n", out.c_str(), woodFractionPath(out).c_str(), gridSidecarPath(out).c_str());
    writePicture(picture, &grid, nullptr);
    return kOk;
}

} // namespace

Command voxelizeCommand()
{
    return {"voxelize", "MESH -o DENSITY.npy", "voxelize a mesh into a density grid (+ wood fraction)",
            {kGrid, kSubcells, kLeafMaterials, kOutput, kPicture, kSlices, kAxis, kCache, kNoCache, kThreads, kQuiet},
            1, 1, &runVoxelize};
}

} // namespace sylva::cli
