// sylva voxelize: a mesh into a density grid (+ wood fraction), through the grid cache.
#include <cstdio>

#include "pipeline/cli/cli_util.h"
#include "pipeline/cli/commands.h"
#include "pipeline/cli/common_options.h"
#include "pipeline/cli/grid_options.h"
#include "pipeline/io/grid_file.h"
#include "pipeline/io/output_path.h"
#include "pipeline/lighting_job.h"

namespace sylva::cli {
namespace {

int runVoxelize(const Args& args)
{
    auto threads = threadLimit(args);
    const std::string mesh = args.positional()[0];
    DensityJob job{mesh, importOptions(args), voxelSettings(args)};   // usage errors before file errors
    job.voxel.solid = args.has("--solid");
    const PictureOptions picture = pictureOptions(args);
    const std::string out = outputFile(args, gridFileExtensions());
    requireReadable(mesh, "mesh file");
    requireReplaceableFile(out);
    auto cache = openCache(args);
    ProgressPrinter bar("voxelize", args.has("--quiet"));
    JobLog log;
    const DensityGrid grid = densityForMesh(job, cache.get(), &bar.progress(), &log);
    writeDensityFile(out, grid);
    bar.finish(log.stages.empty() ? "" : log.stages.back());
    for (const auto& w : log.warnings) std::fprintf(stderr, "warning: %s\n", w.c_str());
    printDensitySummary(grid);
    const std::vector<std::string> files = densityFilesFor(out);
    std::string also;   // "wrote d.npy (+ d.wood.npy, d.npy.json)", "wrote d.vdb"
    for (size_t f = 1; f < files.size(); ++f) {
        also += f == 1 ? " (+ " : ", ";
        also += files[f];
    }
    if (files.size() > 1) also += ")";
    std::printf("wrote %s%s\n", out.c_str(), also.c_str());
    writePicture(picture, &grid, nullptr);
    return kOk;
}

} // namespace

Command voxelizeCommand()
{
    return {"voxelize", "MESH -o DENSITY.npy|.vdb", "voxelize a mesh into a density grid (+ wood fraction)",
            {kGrid, kSubcells, kLeafMaterials,
             {"--solid", "", "fill the interior (winding numbers: open edges and gaps do not leak); the grid is a medium, wood 0"},
             kOutput, kPicture, kSlices, kAxis, kCache, kNoCache, kThreads, kQuiet},
            1, 1, &runVoxelize};
}

} // namespace sylva::cli
