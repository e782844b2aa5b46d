// The lighting inspector's loading: which species the inspector shows (the outliner selection), the
// Inspect job that reads its grids (loadSpeciesGrids, through the grid cache), and waiting for the
// lighting job instead of solving the same grids twice.
#pragma once

#include <functional>
#include <string>

#include <QPointer>

#include "studio/studio_controller.h"

class QDockWidget;

namespace sylva {

class AssetStore;
class Backend;
class GridCache;
class Job;
class JobManager;
class LightingScheduler;
class SceneDocument;
class VolumeInspector;

class InspectorController : public StudioController {
    Q_OBJECT

public:
    // selectedSpecies: the species the selection points at (-1: none). The inspector is refreshed
    // while dock is visible (and when it is shown). backend: where a solve the cache lacks runs (null =
    // the CPU).
    InspectorController(SceneDocument* doc, JobManager* jobs, AssetStore* assets, GridCache* cache, Backend* backend,
                        LightingScheduler* lighting, VolumeInspector* inspector, QDockWidget* dock,
                        std::function<int()> selectedSpecies, QObject* parent = nullptr);

    // Shows the selected species' grids (a job when they are not loaded; a wait while lighting runs).
    void refresh();
    // Loads the species' density and lighting grids in a job and shows them. Null for a bad index.
    Job* inspectSpecies(int species);
    // selectedVolume: the volume the selection points at (-1: none); refresh shows its density grid and,
    // once the lighting job has solved it, its LB lighting (VolumeLightStore).
    void setSelectedVolume(std::function<int()> selectedVolume) { m_selectedVolume = std::move(selectedVolume); }
    // Shows volume `volume`'s grids now; false for a bad index or a volume whose grid is not loaded.
    bool inspectVolume(int volume);

Q_SIGNALS:
    void updated();   // the inspector shows new grids (or a message)

private:
    SceneDocument* m_doc;
    JobManager* m_jobs;
    AssetStore* m_assets;
    GridCache* m_cache;
    Backend* m_backend;
    LightingScheduler* m_lighting;
    VolumeInspector* m_inspector;
    QDockWidget* m_dock;
    std::function<int()> m_selectedSpecies;
    std::function<int()> m_selectedVolume;
    QPointer<Job> m_job;
    std::string m_inspectedKey;   // asset key of what the inspector shows (or is loading)
};

} // namespace sylva
