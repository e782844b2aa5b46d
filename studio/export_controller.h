// Exports: File > Export Render (a picture of the scene, renderFilm + composeMode + writeRender) and
// File > Export Species Grids (a species' density and lighting grids as .npy with sidecars), each a
// background job, with their dialogs.
#pragma once

#include <QString>

#include "studio/dialogs.h"
#include "studio/studio_controller.h"

class QWidget;

namespace sylva {

class AssetStore;
class GridCache;
class Job;
class JobManager;
class SceneDocument;

class ExportController : public StudioController {
    Q_OBJECT

public:
    // window: the parent of the dialogs.
    ExportController(SceneDocument* doc, JobManager* jobs, AssetStore* assets, GridCache* cache, QWidget* window,
                     QObject* parent = nullptr);

    // Renders the scene at the settings' size and samples into settings.path (PNG/TIFF tone-mapped,
    // EXR linear). Null (and an error) for an empty scene.
    Job* exportRender(const ExportSettings& settings);
    // Writes a species' grids (loadSpeciesGrids) into folder as NAME.density.npy (+ NAME.density.wood.npy)
    // and NAME.lighting.npy, each with its JSON sidecar (CONTRACTS.md); NAME is gridFileBase of the
    // species name. Null (and an error) for a bad species index.
    Job* exportSpeciesGrids(int species, const QString& folder);
    // The species name with characters other than letters, digits, '.', '-', '_' replaced by '_'.
    static QString gridFileBase(const QString& speciesName);

    // The Export Render dialog (starting from the last export's settings), then exportRender.
    void exportDialog();
    // A folder dialog for the species' grids (an error without a species), then exportSpeciesGrids.
    void exportGridsDialog(int species);

private:
    SceneDocument* m_doc;
    JobManager* m_jobs;
    AssetStore* m_assets;
    GridCache* m_cache;
    QWidget* m_window;
    ExportSettings m_lastExport;
};

} // namespace sylva
