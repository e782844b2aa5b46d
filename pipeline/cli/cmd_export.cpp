// sylva export: a scene's species grids (density, wood fraction and LB lighting) as OpenVDB or .npy
// files, the studio's Export Species Grids on the command line (pipeline/services/exports); with
// --output FILE.glb the scene itself as instanced binary glTF, the studio's Export Scene as glTF
// (pipeline/services/gltf_export).
#include <cstdio>
#include <map>
#include <string>
#include <vector>

#include "core/base/error.h"
#include "pipeline/cli/cli_util.h"
#include "pipeline/cli/commands.h"
#include "pipeline/cli/common_options.h"
#include "pipeline/io/file_extension.h"
#include "pipeline/io/grid_file.h"
#include "pipeline/io/output_path.h"
#include "pipeline/render/render_job.h"
#include "pipeline/scene/scene_file.h"
#include "pipeline/services/exports.h"
#include "pipeline/services/gltf_export.h"

namespace sylva::cli {
namespace {

// The species named by --species (indices), or every species of the scene.
std::vector<size_t> chosenSpecies(const Args& args, const Scene& scene, const std::string& sceneName);

// --output FILE.glb: the scene's meshes, materials and instances (pipeline/services/gltf_export.h); the count and
// the estimated size are printed before anything is written, and an export above the limits is refused
// without --force.
int runGltfExport(const Args& args, const Scene& scene, const std::string& sceneName)
{
    const std::string path = args.get("--output");
    if (args.has("--format") || args.has("--out")) throw UsageError("--output FILE.glb writes the scene as glTF; --format and --out are for the grids");
    if (lowerExtension(path) != ".glb") throw UsageError("option --output: expected a .glb file, got '" + path + "'");
    GltfExportOptions options;
    if (args.has("--region")) {
        try {
            options.region = parseGltfRegion(args.get("--region"));
        } catch (const Error& e) {
            throw UsageError(std::string("option --region: ") + e.what());
        }
    }
    if (args.has("--species")) options.species = chosenSpecies(args, scene, sceneName);
    options.force = args.has("--force");
    requireReplaceableFile(path);
    ProgressPrinter bar("export " + path, args.has("--quiet"));
    JobLog log;
    SubProgress assetsPart(&bar.progress(), 0.0, 0.5);
    Progress assetsProgress([&](double f, const std::string& m) { assetsPart.report(f, m); });
    const std::vector<SpeciesAssets> assets = loadSpeciesAssets(scene, nullptr, false, &assetsProgress, &log);
    for (const std::string& w : log.warnings) std::fprintf(stderr, "warning: %s\n", w.c_str());
    const GltfPlan plan = planGltfExport(scene, assets, options);
    std::printf("%s: %s\n", path.c_str(), plan.summary().c_str());
    for (size_t s = 0; s < plan.perSpecies.size(); ++s)
        if (plan.perSpecies[s] > 0) std::printf("  %s: %zu\n", scene.species[s].name.c_str(), plan.perSpecies[s]);
    if (plan.terrainSamplesX > 0) std::printf("  terrain: %zu x %zu samples\n", plan.terrainSamplesX, plan.terrainSamplesZ);
    std::fflush(stdout);
    if (plan.overLimit() && !options.force) {
        bar.finish();
        throw Error("refused, nothing written: " + plan.summary() + " is above the limit (" + std::to_string(plan.instanceLimit) + " instances, " +
                    std::to_string(int(plan.byteLimit / 1048576.0)) + " MiB estimated); narrow --region or --species, or add --force");
    }
    SubProgress writePart(&bar.progress(), 0.5, 1.0);
    Progress writeProgress([&](double f, const std::string& m) { writePart.report(f, m); });
    const GltfPlan written = exportGltf(scene, assets, path, options, &writeProgress);
    bar.finish();
    std::printf("wrote %s (%.0f bytes)\n", path.c_str(), written.estimatedBytes);
    return kOk;
}

std::vector<size_t> chosenSpecies(const Args& args, const Scene& scene, const std::string& sceneName)
{
    std::vector<size_t> chosen;
    for (const std::string& name : splitList(args.get("--species"))) {
        size_t found = scene.species.size();
        for (size_t s = 0; s < scene.species.size(); ++s)
            if (scene.species[s].name == name) found = s;
        if (found == scene.species.size()) {
            std::string names;
            for (const SpeciesDesc& sp : scene.species) {
                names += names.empty() ? "'" : ", '";
                names += sp.name;
                names += "'";
            }
            throw Error(sceneName + ": no species '" + name + "' (it has " + (names.empty() ? std::string("none") : names) + ")");
        }
        chosen.push_back(found);
    }
    return chosen;
}

int runExport(const Args& args)
{
    auto threads = threadLimit(args);
    if (!args.has("--output") && (args.has("--region") || args.has("--force")))
        throw UsageError("--region and --force belong to the glTF export (--output FILE.glb)");
    const std::string formatName = args.get("--format", "vdb");
    if (formatName != "vdb" && formatName != "npy") throw UsageError("option --format: expected vdb or npy, got '" + formatName + "'");
    const GridFileFormat format = formatName == "vdb" ? GridFileFormat::Vdb : GridFileFormat::Npy;
    const std::string folder = args.get("--out", ".");
    const std::string backend = backendName(args);
    Scene scene;
    std::string sceneName = "the default forest";
    if (args.positional().empty()) {
        scene = defaultScene();
    } else {
        sceneName = args.positional()[0];
        requireReadable(sceneName, "scene file");
        scene = readSceneFile(sceneName);
    }
    if (args.has("--output")) return runGltfExport(args, scene, sceneName);
    std::vector<size_t> chosen;
    if (args.has("--species")) {
        chosen = chosenSpecies(args, scene, sceneName);
    } else {
        for (size_t s = 0; s < scene.species.size(); ++s) chosen.push_back(s);
    }
    if (chosen.empty()) throw Error(sceneName + ": the scene has no species to export");
    // Every target is checked before any work, and two species may not write the same file.
    std::map<std::string, std::string> writer;
    for (size_t s : chosen) {
        const GridExportFiles files = gridExportFiles(folder, scene.species[s].name, format);
        for (const std::string& target : densityFilesFor(files.density)) requireReplaceableFile(target);
        for (const std::string& target : lightingFilesFor(files.lighting)) requireReplaceableFile(target);
        const auto [it, fresh] = writer.emplace(files.lighting, scene.species[s].name);
        if (!fresh && it->second != scene.species[s].name)
            throw Error("species '" + it->second + "' and '" + scene.species[s].name + "' would both be written to " + files.lighting +
                        "; rename one");
    }
    auto compute = openBackend(backend);
    auto cache = openCache(args);
    for (size_t s : chosen) {
        const std::string& name = scene.species[s].name;
        ProgressPrinter bar("export " + name, args.has("--quiet"));
        JobLog log;
        const GridExportFiles files = exportSpeciesGrids(scene, s, folder, cache.get(), compute.get(), &bar.progress(), &log, nullptr, format);
        bar.finish();
        for (const std::string& line : speciesLogLines(name, log)) std::fprintf(stderr, "%s\n", line.c_str());
        std::vector<std::string> written = densityFilesFor(files.density);
        if (files.lighting != files.density)
            for (const std::string& f : lightingFilesFor(files.lighting)) written.push_back(f);
        for (const std::string& f : written) std::printf("wrote %s\n", f.c_str());
    }
    return kOk;
}

} // namespace

Command exportCommand()
{
    return {"export", "[SCENE.sylva.json] [--species A,B] ([--format vdb|npy] [--out DIR] | -o FILE.glb [--region X0,Z0,X1,Z1] [--force])",
            "write the species' density, wood fraction and lighting grids (OpenVDB or .npy), or with -o FILE.glb the scene as instanced glTF",
            {{"--species", "A,B", "the species to export, by name (default: every species of the scene)"},
             {"--format", "vdb|npy", "vdb (default): one NAME.vdb per species; npy: NAME.density.npy and NAME.lighting.npy with sidecars"},
             {"--out", "DIR", "folder of the files (default: the current folder); NAME is the species name made file-safe"},
             {"--output", "FILE.glb", "glTF mode: the scene as one binary glTF file (species meshes, materials, instances through EXT_mesh_gpu_instancing, ground or terrain)"},
             {"--region", "X0,Z0,X1,Z1", "glTF: only what stands in this box of world x, z (metres): instances, landscape plants, terrain"},
             {"--force", "", "glTF: write even above the limit (" + std::to_string(kGltfInstanceLimit) + " instances or 1 GiB estimated)"},
             kBackend, kCache, kNoCache, kThreads, kQuiet},
            0, 1, &runExport};
}

} // namespace sylva::cli
