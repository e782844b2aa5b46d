// InspectorController: the selected species' grids into the volume inspector.
#include "studio/inspector_controller.h"

#include <memory>

#include <QDockWidget>

#include "pipeline/render/render_job.h"
#include "pipeline/render/volume_job.h"
#include "pipeline/services/exports.h"
#include "studio/asset_store.h"
#include "studio/job_manager.h"
#include "studio/lighting_scheduler.h"
#include "studio/scene_document.h"
#include "studio/volume_inspector.h"

namespace sylva {

InspectorController::InspectorController(SceneDocument* doc, JobManager* jobs, AssetStore* assets, GridCache* cache,
                                         Backend* backend, LightingScheduler* lighting, VolumeInspector* inspector,
                                         QDockWidget* dock, std::function<int()> selectedSpecies, QObject* parent)
    : StudioController(parent),
      m_doc(doc),
      m_jobs(jobs),
      m_assets(assets),
      m_cache(cache),
      m_backend(backend),
      m_lighting(lighting),
      m_inspector(inspector),
      m_dock(dock),
      m_selectedSpecies(std::move(selectedSpecies))
{
    connect(m_dock, &QDockWidget::visibilityChanged, this, [this](bool visible) {
        if (visible) refresh();
    });
}

void InspectorController::refresh()
{
    if (!m_dock->isVisible()) return;
    const int species = m_selectedSpecies();
    if (species < 0 && m_selectedVolume && m_selectedVolume() >= 0) {
        if (m_job) m_job->cancel();
        m_inspectedKey.clear();
        if (inspectVolume(m_selectedVolume())) return;
    }
    if (species < 0) {
        if (m_job) m_job->cancel();
        m_inspectedKey.clear();
        m_inspector->setMessage(tr("Select a species (or one of its instances) to inspect its lighting grids."));
        Q_EMIT updated();
        return;
    }
    const Scene& s = m_doc->scene();
    const std::string key = assetKey(s.species[size_t(species)], s, true);
    if (key == m_inspectedKey) return;   // shown or loading
    if (m_lighting->isPending()) {
        // The lighting job solves these grids (or is about to): read them from the cache when it is
        // done rather than solve them twice at once.
        if (m_job) m_job->cancel();
        m_inspectedKey.clear();
        m_inspector->setMessage(tr("Waiting for the lighting job..."));
        return;
    }
    inspectSpecies(species);
}

bool InspectorController::inspectVolume(int volume)
{
    const Scene& scene = m_doc->scene();
    if (volume < 0 || size_t(volume) >= scene.volumes.size() || !scene.volumes[size_t(volume)].data) return false;
    // The lit copy when the lighting job has made it (the viewport's), else the loaded density alone.
    Scene lit;
    const bool solved = m_lighting->volumeLights()->litScene(scene, true, &lit);
    const VolumeDesc& v = solved ? lit.volumes[size_t(volume)] : scene.volumes[size_t(volume)];
    auto g = std::make_shared<SpeciesGrids>();
    g->density = v.data->density;
    if (g->density.woodFraction.size() != g->density.density.size()) g->density.woodFraction.assign(g->density.density.size(), 0.0f);
    g->lighting = v.data->lighting;
    g->lightingNorm = v.data->lightingNorm;
    g->params = volumeLightingParams(scene, v);
    m_inspector->setGrids(QString::fromStdString(v.name), g);
    Q_EMIT updated();
    return true;
}

Job* InspectorController::inspectSpecies(int species)
{
    const Scene scene = m_doc->scene();
    if (species < 0 || size_t(species) >= scene.species.size()) return nullptr;
    const SpeciesDesc& sp = scene.species[size_t(species)];
    const std::string key = assetKey(sp, scene, true);
    if (m_job) m_job->cancel();
    m_inspectedKey = key;
    const QString name = QString::fromStdString(sp.name);
    m_inspector->setMessage(tr("Loading the grids of %1...").arg(name));
    // The species' mesh when the viewport already holds it (no second import).
    AssetsPtr held = m_assets->find(assetKey(sp, scene, true));
    if (!held) held = m_assets->find(assetKey(sp, scene, false));
    auto result = std::make_shared<std::shared_ptr<const SpeciesGrids>>();
    GridCache* cache = m_cache;
    Backend* backend = m_backend;
    m_job = m_jobs->start(tr("Inspect %1").arg(name),
                          [scene, species, held, cache, backend, result](Job& job, Progress& progress) {
                              JobLog log;
                              SpeciesGrids g = loadSpeciesGrids(scene, size_t(species), cache, &progress, &log,
                                                                held ? &held->mesh : nullptr, backend);
                              for (const std::string& line : speciesLogLines(scene.species[size_t(species)].name, log))
                                  job.log(QString::fromStdString(line));
                              *result = std::make_shared<const SpeciesGrids>(std::move(g));
                          },
                          [this, key, name, result](Job* job) {
                              if (key != m_inspectedKey) return;   // the selection moved on
                              if (job->state() == Job::State::Succeeded) {
                                  m_inspector->setGrids(name, *result);
                              } else {
                                  m_inspectedKey.clear();
                                  m_inspector->setMessage(job->state() == Job::State::Failed
                                                              ? tr("The grids of %1 could not be loaded: %2").arg(name, job->error())
                                                              : tr("Loading the grids of %1 was cancelled.").arg(name));
                              }
                              Q_EMIT updated();
                          });
    return m_job;
}

} // namespace sylva
