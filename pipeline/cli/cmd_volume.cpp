// sylva volume cloud: a pyroclastic cloud density grid (core/volume/pyroclastic.h), .npy or .vdb.
#include <cstdio>

#include "core/volume/pyroclastic.h"
#include "pipeline/cli/cli_util.h"
#include "pipeline/cli/commands.h"
#include "pipeline/cli/common_options.h"
#include "pipeline/cli/grid_options.h"
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
    if (args.has("--radius")) p.radius = float(parseNumber("--radius", args.get("--radius")));
    if (args.has("--amplitude")) p.amplitude = float(parseNumber("--amplitude", args.get("--amplitude")));
    if (args.has("--frequency")) p.frequency = float(parseNumber("--frequency", args.get("--frequency")));
    if (args.has("--octaves")) p.octaves = int(parseInteger("--octaves", args.get("--octaves"), 1, 12));
    if (args.has("--resolution"))
        p.resolution = int(parseInteger("--resolution", args.get("--resolution"), volume::kCloudMinNodes, volume::kCloudMaxNodes));
    if (args.has("--density")) p.density = float(parseNumber("--density", args.get("--density")));
    if (args.has("--seed")) p.seed = uint64_t(parseInteger("--seed", args.get("--seed"), 0, (1ll << 62)));
    if (args.has("--centre")) p.centre = parseTriple("--centre", args.get("--centre"));
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
    return {"volume", "cloud [options] -o CLOUD.npy|.vdb",
            "make a density volume: a pyroclastic cloud (a sphere displaced by |fBm noise|)",
            {{"--radius", "R", "radius of the undisplaced sphere, metres (default 1)"},
             {"--amplitude", "A", "largest outward displacement by the noise, metres (default 0.5)"},
             {"--frequency", "F", "noise cells per metre of the first octave (default 1.5)"},
             {"--octaves", "N", "fBm octaves, 1..12 (default 4)"},
             {"--resolution", "N", "nodes per axis of the cubic grid, 8..512 (default 128)"},
             {"--density", "D", "density inside the cloud, (0, 1] (default 1)"},
             {"--seed", "N", "noise seed (default 1); the same seed gives the same grid"},
             {"--centre", "X,Y,Z", "world position of the centre, metres (default 0,0,0)"},
             kOutput, kPicture, kSlices, kAxis, kThreads, kQuiet},
            1, 1, &runVolume};
}

} // namespace sylva::cli
