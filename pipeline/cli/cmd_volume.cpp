// sylva volume cloud: a pyroclastic cloud density grid (core/volume/pyroclastic.h), .npy or .vdb.
#include <cstdio>

#include "core/volume/pyroclastic.h"
#include "pipeline/cli/cli_util.h"
#include "pipeline/cli/commands.h"
#include "pipeline/cli/common_options.h"
#include "pipeline/cli/grid_options.h"
#include "pipeline/cli/param_options.h"
#include "pipeline/io/grid_file.h"
#include "pipeline/io/output_path.h"

namespace sylva::cli {
namespace {

int runVolume(const Args& args)
{
    auto threads = threadLimit(args);
    const std::string kind = args.positional()[0];
    if (kind != "cloud") throw UsageError("unknown volume kind '" + kind + "' (the one there is: cloud)");
    volume::PyroclasticParams p;
    readParam(args, volume::kCloudRadius, p.radius);
    readParam(args, volume::kCloudAmplitude, p.amplitude);
    readParam(args, volume::kCloudFrequency, p.frequency);
    readParam(args, volume::kCloudOctaves, p.octaves);
    readParam(args, volume::kCloudResolution, p.resolution);
    readParam(args, volume::kCloudDensity, p.density);
    readParam(args, volume::kCloudSeed, p.seed);
    readParam(args, volume::kCloudCentre, p.centre);
    const PictureOptions picture = pictureOptions(args);
    const std::string out = outputFile(args, gridFileExtensions());
    volume::validatePyroclastic(p);   // bad values: exit 1 before any file is touched
    requireReplaceableFile(out);
    const DensityGrid grid = volume::makePyroclasticCloud(p);
    writeDensityFile(out, grid);
    printDensitySummary(grid);
    std::printf("wrote %s\n", out.c_str());
    writePicture(picture, &grid, nullptr);
    return kOk;
}

} // namespace

Command volumeCommand()
{
    Command c{"volume", "cloud [options] -o CLOUD.npy|.vdb",
              "make a density volume: a pyroclastic cloud (a sphere displaced by |fBm noise|)", {}, 1, 1, &runVolume};
    for (const ParamSpec* spec : volume::kCloudParams) c.options.push_back(paramOption(*spec));
    for (const OptionSpec& o : {kOutput, kPicture, kSlices, kAxis, kThreads, kQuiet}) c.options.push_back(o);
    return c;
}

} // namespace sylva::cli
