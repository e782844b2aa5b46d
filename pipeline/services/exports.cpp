// Render and grid exports (exports.h).
#include "pipeline/services/exports.h"

#include <filesystem>

#include "core/backend/backend.h"
#include "core/base/error.h"
#include "core/render/render_cpu.h"
#include "pipeline/io/file_extension.h"
#include "pipeline/io/grid_file.h"
#include "pipeline/render/frame_build.h"
#include "pipeline/render/render_job.h"
#include "pipeline/render/render_passes.h"

namespace sylva {

std::vector<std::string> speciesLogLines(const std::string& species, const JobLog& log)
{
    std::vector<std::string> out;
    for (const std::string& stage : log.stages)
        out.push_back(stage.rfind(species + ":", 0) == 0 ? stage : species + ": " + stage);
    for (const std::string& w : log.warnings) out.push_back("warning: " + w);
    return out;
}

void exportRender(const Scene& scene, const std::vector<SpeciesAssets>& assets, const std::string& path, Backend* backend,
                  Progress* progress, bool passes)
{
    if (passes && lowerExtension(path) != ".exr")
        throw Error(path + ": render passes are written as a multi-layer OpenEXR file (use .exr)");
    if (progress) progress->report(0.0, "building");
    const RenderScene rs = buildRenderScene(scene, assets, sunRadiance(scene.sun));
    if (progress && progress->isCancelled()) throw Cancelled();
    SubProgress tracePart(progress, 0.1, 0.96);
    Progress traceProgress([&](double f, const std::string& m) { tracePart.report(f, m); });
    if (progress && progress->isCancelled()) traceProgress.cancel();
    const Film film = backend ? backend->render(rs, &traceProgress) : renderFilm(rs.view(), &traceProgress);
    MatteFilm mattes;
    if (passes) mattes = renderMatteFilm(rs.view());
    if (progress) progress->report(0.96, "writing");
    writeRenderFilm(path, film, scene, passes, passes ? &mattes : nullptr);
    if (progress) progress->report(1.0, "written");
}

void writeRenderFilm(const std::string& path, const Film& film, const Scene& scene, bool passes, const MatteFilm* mattes)
{
    if (passes && lowerExtension(path) != ".exr")
        throw Error(path + ": render passes are written as a multi-layer OpenEXR file (use .exr)");
    if (passes) {
        RenderPasses layers = renderPasses(film, scene.render.mode, composeSky(scene));
        if (mattes) layers.cryptomatte = cryptomatteLayers(*mattes, scene);
        writeRenderPasses(path, layers);
    } else {
        const std::vector<glm::vec3> linear = composeMode(film, scene.render.mode, composeSky(scene));
        const bool linearOut = lowerExtension(path) == ".exr";
        writeRender(path, linear, film.width, film.height, scene.render.exposureKey,
                    linearOut ? DisplayTransform() : displayTransformOf(scene.render));
    }
}

std::string gridFileBase(const std::string& speciesName)
{
    std::string out;
    for (unsigned char c : speciesName) {
        const bool keep = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '.' ||
                          c == '-' || c == '_';
        // A UTF-8 sequence is one character: one '_' for its lead byte, none for its continuation bytes.
        if (keep) out += char(c);
        else if ((c & 0xC0) != 0x80) out += '_';
    }
    return out.empty() ? std::string("species") : out;
}

GridExportFiles gridExportFiles(const std::string& folder, const std::string& speciesName, GridFileFormat format)
{
    const std::filesystem::path base = std::filesystem::path(folder) / gridFileBase(speciesName);
    if (format == GridFileFormat::Vdb) return {base.string() + ".vdb", base.string() + ".vdb"};
    return {base.string() + ".density.npy", base.string() + ".lighting.npy"};
}

GridExportFiles exportSpeciesGrids(const Scene& scene, size_t species, const std::string& folder, GridCache* cache,
                                   Backend* backend, Progress* progress, JobLog* log, const TriangleMesh* mesh,
                                   GridFileFormat format)
{
    if (species >= scene.species.size())
        throw Error("grid export: no species " + std::to_string(species) + " in a scene of " +
                    std::to_string(scene.species.size()));
    const SpeciesDesc& sp = scene.species[species];
    const GridExportFiles files = gridExportFiles(folder, sp.name, format);
    SubProgress loadPart(progress, 0.0, 0.9);
    Progress loadProgress([&](double f, const std::string& m) { loadPart.report(f, m); });
    if (progress && progress->isCancelled()) loadProgress.cancel();
    const SpeciesGrids g = loadSpeciesGrids(scene, species, cache, &loadProgress, log, mesh, backend);
    if (progress) progress->report(0.9, "writing");
    const std::string params = lightingParamsJson(g.params, sp.preset, g.lighting.geometry.dims);
    if (format == GridFileFormat::Vdb) {
        writeLightingFile(files.lighting, g.lighting, params, &g.density);   // one file, every grid
    } else {
        writeDensityFile(files.density, g.density);
        writeLightingFile(files.lighting, g.lighting, params);
    }
    if (progress) progress->report(1.0, "written");
    return files;
}

} // namespace sylva
