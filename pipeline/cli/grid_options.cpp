// Options of the grid commands (grid_options.h).
#include "pipeline/cli/grid_options.h"

#include <cstdio>
#include <filesystem>

#include "core/base/error.h"
#include "core/lb/lb_solver.h"
#include "pipeline/cli/cli_util.h"
#include "pipeline/cli/common_options.h"
#include "pipeline/io/grid_file.h"
#include "pipeline/io/grid_picture.h"
#include "pipeline/io/npy.h"
#include "pipeline/io/output_path.h"
#include "pipeline/services/grid_stats.h"

namespace fs = std::filesystem;

namespace sylva::cli {

VoxelizeSettings voxelSettings(const Args& args)
{
    VoxelizeSettings v;
    if (args.has("--grid")) {
        const std::vector<std::string> parts = splitList(args.get("--grid"));
        if (parts.size() == 1) {
            v.longestAxisNodes = int(parseInteger("--grid", parts[0], 3, 512));
        } else if (parts.size() == 3) {
            v.dims = {int(parseInteger("--grid", parts[0], 3, 512)), int(parseInteger("--grid", parts[1], 3, 512)),
                      int(parseInteger("--grid", parts[2], 3, 512))};
        } else {
            throw UsageError("option --grid: expected N or X,Y,Z, got '" + args.get("--grid") + "'");
        }
    }
    if (args.has("--subcells")) v.subcells = int(parseInteger("--subcells", args.get("--subcells"), 1, 16));
    return v;
}

ImportOptions importOptions(const Args& args)
{
    ImportOptions o;
    if (args.has("--leaf-materials"))
        for (const auto& name : splitList(args.get("--leaf-materials")))
            if (!name.empty()) o.leafMaterials.push_back(name);
    return o;
}

PictureOptions pictureOptions(const Args& args)
{
    PictureOptions o;
    if (!args.has("--picture")) {
        if (args.has("--axis") || args.has("--slices")) throw UsageError("--axis and --slices go with --picture");
        return o;
    }
    o.path = args.get("--picture");
    const std::string ext = lowerExtension(o.path);
    if (ext != ".png" && ext != ".tif" && ext != ".tiff" && ext != ".exr" && ext != ".jpg")
        throw UsageError("option --picture: '" + o.path + "' needs an image extension (.png, .tif, .exr, .jpg)");
    if (args.has("--axis")) {
        const std::string a = args.get("--axis");
        if (a == "x") o.axis = 0;
        else if (a == "y") o.axis = 1;
        else if (a == "z") o.axis = 2;
        else throw UsageError("option --axis: expected x, y or z, got '" + a + "'");
    }
    if (args.has("--slices")) o.slices = int(parseInteger("--slices", args.get("--slices"), 1, 64));
    requireReplaceableFile(o.path);
    return o;
}

void writePicture(const PictureOptions& o, const DensityGrid* density, const LightingGrid* light)
{
    if (o.path.empty()) return;
    writeGridMontage(o.path, density, light, o.axis, o.slices, 256);
    std::printf("picture: %s\n", o.path.c_str());
}

lb::LbParams lightParams(const Args& args)
{
    const std::string presetName = args.get("--preset", "leaf");
    const lb::Preset* preset = lb::findPreset(presetName);
    if (!preset) {
        std::string names;
        for (const auto& p : lb::presets()) names += (names.empty() ? "" : ", ") + p.name;
        throw UsageError("option --preset: unknown preset '" + presetName + "' (known: " + names + ")");
    }
    lb::LbParams p = lb::paramsFromPreset(*preset);
    if (args.has("--sigma-a")) {
        const glm::vec3 v = parseTriple("--sigma-a", args.get("--sigma-a"));
        for (int c = 0; c < 3; ++c) p.channels[size_t(c)].sigmaA = v[c];
    }
    if (args.has("--sigma-s")) {
        const glm::vec3 v = parseTriple("--sigma-s", args.get("--sigma-s"));
        for (int c = 0; c < 3; ++c) p.channels[size_t(c)].sigmaS = v[c];
    }
    if (args.has("--g")) {
        const glm::vec3 v = parseTriple("--g", args.get("--g"));
        for (int c = 0; c < 3; ++c) p.channels[size_t(c)].g = v[c];
    }
    if (args.has("--keep-f0") && args.has("--zero-f0")) throw UsageError("--keep-f0 and --zero-f0 exclude each other");
    if (args.has("--keep-f0")) p.zeroF0 = false;
    if (args.has("--zero-f0")) p.zeroF0 = true;
    if (args.has("--sun") && args.has("--sun-at")) throw UsageError("give either --sun or --sun-at, not both");
    if (args.has("--sun-at")) {
        p.sun = sky::placeSunDirection(parseSunAt(args.get("--sun-at")));
    } else {
        p.sun = parseTriple("--sun", args.require("--sun"));
        if (args.get("--sun").find(',') == std::string::npos) throw UsageError("option --sun: expected X,Y,Z");
    }
    if (args.has("--intensity")) p.intensity = parseTriple("--intensity", args.get("--intensity"));
    if (args.has("--steps") && args.has("--tol")) throw UsageError("--steps and --tol exclude each other");
    if (args.has("--steps")) p.steps = int(parseInteger("--steps", args.get("--steps"), 1, 1000000));
    if (args.has("--tol")) {
        p.tolerance = parseNumber("--tol", args.get("--tol"));
        if (!(p.tolerance > 0.0)) throw UsageError("option --tol: must be > 0");
    }
    if (args.has("--fp16")) p.storage = lb::Storage::Fp16;
    if (args.has("--warm-start")) p.warmStart = true;
    if (args.has("--coarse-start")) {
        if (!args.has("--tol")) throw UsageError("--coarse-start applies to tolerance mode (--tol T)");
        p.coarseStart = true;
    }
    lb::validate(p);   // bad parameter values are bad input (exit 1) with a message naming the bound
    return p;
}

void rejectMeshOptionsWithDensity(const Args& args)
{
    if (!args.has("--density")) return;
    for (const char* meshOnly : {"--grid", "--subcells", "--leaf-materials", "--solid"})
        if (args.has(meshOnly)) throw UsageError(std::string(meshOnly) + " applies to --mesh, not to --density");
}

DensityGrid loadDensityInput(const Args& args, const VoxelizeSettings& voxel, GridCache* cache, JobLog& log)
{
    if (args.has("--density")) {
        const std::string path = args.get("--density");
        requireReadable(path, "density grid");
        DensityGrid density = readDensityFile(path);
        try {
            lb::validateDensity(density);
        } catch (const Error& e) {
            throw Error(path + ": " + e.what());
        }
        return density;
    }
    requireReadable(args.get("--mesh"), "mesh file");
    ProgressPrinter vbar("voxelize", args.has("--quiet"));
    DensityGrid density = densityForMesh({args.get("--mesh"), importOptions(args), voxel}, cache, &vbar.progress(), &log);
    vbar.finish(log.stages.back());
    return density;
}

void printDensitySummary(const DensityGrid& d)
{
    const DensityStats s = densityStats(d);
    std::printf("density grid %s, spacing %.4g m, origin (%.4g, %.4g, %.4g): %.1f%% of nodes occupied, mean density %.4f, "
                "%zu brown nodes\n",
                gridDimsText(d.geometry).c_str(), d.geometry.spacing, d.geometry.origin.x, d.geometry.origin.y, d.geometry.origin.z,
                s.occupiedPercent(), s.mean, s.brown);
}

} // namespace sylva::cli
