// Exports: File > Export Render (a picture of the scene, the pipeline's exportRender) and File > Export
// Species Grids (a species' density and lighting grids as .npy with sidecars, or as one OpenVDB file:
// exportSpeciesGrids), each a background job on the studio's backend, with their dialogs; File > Export Scene
// as glTF (the scene's meshes, materials and instances as one .glb: exportGltf).
#pragma once

#include <functional>
#include <memory>
#include <vector>

#include <QString>

#include "core/render/render_cpu.h"

#include "pipeline/io/grid_file.h"
#include "pipeline/services/gltf_export.h"
#include "studio/dialogs.h"
#include "studio/studio_controller.h"

class QWidget;

namespace sylva {

class AssetStore;
class Backend;
class GridCache;
class Job;
class JobManager;
class SceneDocument;

class ExportController : public StudioController {
    Q_OBJECT

public:
    // window: the parent of the dialogs. backend: where the solves and the traces run (null = the CPU).
    ExportController(SceneDocument* doc, JobManager* jobs, AssetStore* assets, GridCache* cache, Backend* backend,
                     QWidget* window, QObject* parent = nullptr);

    // Renders the scene at the settings' size and samples into settings.path (PNG/TIFF tone-mapped,
    // EXR linear). Null (and an error) for an empty scene.
    Job* exportRender(const ExportSettings& settings);
    // Render > Render Image: `scene` at its render size and samples, traced in passes of growing sample
    // counts (renderSamplePasses) that are accumulated (RenderView::sampleBegin/End, accumulateFilm) into
    // the frame of render.spp samples: sylva render's frame (up to float rounding), built and traced by
    // the calls exportRender makes. On a backend other than the CPU the frame is traced whole, in one
    // pass. onPass runs on the job's thread after each pass with the film so far and its samples per
    // pixel. Null (and an error) for a bad render size.
    using PassCallback = std::function<void(const Film& film, int samples)>;
    Job* renderImage(const Scene& scene, PassCallback onPass);
    // The sample counts the passes of renderImage end at: the first of `subsets` samples (one cycle of
    // a sky's light subsets; at least 1), then doubling in multiples of it, the last spp (ascending).
    static std::vector<int> renderSamplePasses(int spp, int subsets);

    // Writes a species' grids (loadSpeciesGrids) into folder as NAME.density.npy (+ NAME.density.wood.npy)
    // and NAME.lighting.npy, each with its JSON sidecar (CONTRACTS.md), or with GridFileFormat::Vdb as
    // one NAME.vdb (density, wood fraction and lighting grids, docs/FILES.md); NAME is gridFileBase of
    // the species name. Null (and an error) for a bad species index.
    Job* exportSpeciesGrids(int species, const QString& folder, GridFileFormat format = GridFileFormat::Npy);
    // The species name with characters other than letters, digits, '.', '-', '_' replaced by '_'
    // (the pipeline's gridFileBase).
    static QString gridFileBase(const QString& speciesName);

    // Writes the scene as binary glTF (pipeline/services/gltf_export.h) into path (.glb): the species' meshes
    // (from the store, or grown / imported), their materials and instances, the ground or the terrain. The job
    // first logs the count and the estimated size ("glTF: N instances ..., about X MB"); above the export's limit
    // (kGltfInstanceLimit instances or kGltfByteLimit bytes) it fails with that message and writes nothing, unless
    // options.force. Null (and an error) for a path that is no .glb. lastGltfPlan() holds the last count.
    Job* exportGltf(const QString& path, const GltfExportOptions& options = {});
    const GltfPlan& lastGltfPlan() const { return *m_lastGltfPlan; }
    // A save dialog for the .glb, then exportGltf with the dialog's limits; over them, asks whether to export anyway.
    void exportGltfDialog();
    // The limits exportGltfDialog exports under (the export's defaults, kGltfInstanceLimit and kGltfByteLimit, unless set).
    void setGltfLimits(size_t instances, double bytes) { m_gltfInstanceLimit = instances, m_gltfByteLimit = bytes; }

    // The Export Render dialog (starting from the last export's settings), then exportRender.
    void exportDialog();
    // A folder dialog for the species' grids (an error without a species), then exportSpeciesGrids.
    void exportGridsDialog(int species, GridFileFormat format = GridFileFormat::Npy);

private:
    SceneDocument* m_doc;
    JobManager* m_jobs;
    AssetStore* m_assets;
    GridCache* m_cache;
    Backend* m_backend;
    QWidget* m_window;
    ExportSettings m_lastExport;
    std::shared_ptr<GltfPlan> m_lastGltfPlan = std::make_shared<GltfPlan>();
    size_t m_gltfInstanceLimit = kGltfInstanceLimit;
    double m_gltfByteLimit = kGltfByteLimit;
};

} // namespace sylva
