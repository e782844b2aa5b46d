// sylva export: a scene's species grids (density, wood fraction and LB lighting) as OpenVDB or .npy
// files, the studio's Export Species Grids on the command line (pipeline/services/exports).
#include <cstdio>
#include <map>
#include <string>
#include <vector>

#include "core/base/error.h"
#include "pipeline/cli/cli_util.h"
#include "pipeline/cli/commands.h"
#include "pipeline/cli/common_options.h"
#include "pipeline/io/grid_file.h"
#include "pipeline/io/output_path.h"
#include "pipeline/render/render_job.h"
#include "pipeline/scene/scene_file.h"
#include "pipeline/services/exports.h"

namespace sylva::cli {
namespace {

int runExport(const Args& args)
{
    auto threads = threadLimit(args);
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
    std::vector<size_t> chosen;
    if (args.has("--species")) {
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
    return {"export", "[SCENE.sylva.json] [--species A,B] [--format vdb|npy] [--out DIR]",
            "write the species' density, wood fraction and lighting grids (OpenVDB or .npy)",
            {{"--species", "A,B", "the species to export, by name (default: every species of the scene)"},
             {"--format", "vdb|npy", "vdb (default): one NAME.vdb per species; npy: NAME.density.npy and NAME.lighting.npy with sidecars"},
             {"--out", "DIR", "folder of the files (default: the current folder); NAME is the species name made file-safe"},
             kBackend, kCache, kNoCache, kThreads, kQuiet},
            0, 1, &runExport};
}

} // namespace sylva::cli
