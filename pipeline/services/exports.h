// The export jobs of the front ends as library calls: a scene's picture into an image file, a
// species' density and lighting grids into .npy files with their sidecars. Each takes the backend
// that solves and traces (null = the CPU) and a progress.
#pragma once

#include <string>
#include <vector>

#include "core/base/progress.h"
#include "core/render/cryptomatte.h"
#include "core/render/render_cpu.h"
#include "core/render/render_scene.h"
#include "core/scene/scene.h"
#include "pipeline/io/grid_file.h"
#include "pipeline/lighting_job.h"

namespace sylva {

class Backend;
class GridCache;

// The lighting job's stages as log lines naming the species: "NAME: STAGE" (a stage that already
// starts with "NAME:" as it is), then "warning: ..." for each warning.
std::vector<std::string> speciesLogLines(const std::string& species, const JobLog& log);

// The picture of `scene` with the species' assets (in species order; with lighting grids when the
// mode needs them) into `path`: buildRenderScene, the film on `backend`, composeMode, writeRender
// (.png/.tif/.tiff 8-bit through the scene's view, .exr linear); with `passes`, renderPasses and writeRenderPasses
// instead (one multi-layer EXR: .exr only), with the Cryptomatte types of the frame's renderMatteFilm. Throws Error (bad extension, unwritable file) or Cancelled.
void exportRender(const Scene& scene, const std::vector<SpeciesAssets>& assets, const std::string& path,
                  Backend* backend = nullptr, Progress* progress = nullptr, bool passes = false);

// The file exportRender writes, for a film of `scene` already traced (the studio's render window saves
// its finished render with it): `scene`'s mode, sky, exposure key and view; .png/.tif/.tiff 8-bit,
// .exr linear, or with `passes` the multi-layer EXR (with mattes: its Cryptomatte types, cryptomatteLayers).
// Throws Error (bad extension, unwritable file).
void writeRenderFilm(const std::string& path, const Film& film, const Scene& scene, bool passes = false, const MatteFilm* mattes = nullptr);

// A file name base for a species' grids: ASCII letters, digits, '.', '-' and '_' kept, any other
// character '_' ("Tree 1 (2)/x" -> "Tree_1__2__x"); "species" for an empty name.
std::string gridFileBase(const std::string& speciesName);

// The files a grid export writes into `folder` for a species. Npy: FOLDER/BASE.density.npy (with
// BASE.density.wood.npy) and FOLDER/BASE.lighting.npy, each with its .json sidecar. Vdb: one file
// FOLDER/BASE.vdb with the density, wood fraction and lighting grids (density == lighting).
struct GridExportFiles {
    std::string density, lighting;
};
GridExportFiles gridExportFiles(const std::string& folder, const std::string& speciesName,
                                GridFileFormat format = GridFileFormat::Npy);

// Species `species` of `scene` through loadSpeciesGrids (the grid cache: a lit species is a cache
// hit; mesh: the species' mesh when it is in memory) into gridExportFiles(folder, its name, format)
// (pipeline/io/grid_file); the lighting's parameters (sidecar or .vdb metadata) are
// lightingParamsJson's (as `sylva light` writes them). Stages go to log. Returns the files written.
// Throws Error or Cancelled.
GridExportFiles exportSpeciesGrids(const Scene& scene, size_t species, const std::string& folder, GridCache* cache,
                                   Backend* backend = nullptr, Progress* progress = nullptr, JobLog* log = nullptr,
                                   const TriangleMesh* mesh = nullptr, GridFileFormat format = GridFileFormat::Npy);

} // namespace sylva
