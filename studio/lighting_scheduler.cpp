// LightingScheduler: the viewport's assets and the one lighting job that makes the missing ones.
#include "studio/lighting_scheduler.h"

#include <optional>

#include <QKeySequence>

#include "core/backend/backend.h"
#include "pipeline/render/render_job.h"
#include "studio/asset_store.h"
#include "studio/job_manager.h"
#include "studio/scene_document.h"
#include "studio/viewport.h"

namespace sylva {

LightingScheduler::LightingScheduler(SceneDocument* doc, JobManager* jobs, AssetStore* assets, GridCache* cache,
                                     Backend* backend, Viewport* viewport, QObject* parent)
    : StudioController(parent),
      m_doc(doc),
      m_jobs(jobs),
      m_assets(assets),
      m_cache(cache),
      m_backend(backend),
      m_viewport(viewport)
{
    m_timer.setSingleShot(true);
    m_timer.setInterval(250);
    connect(&m_timer, &QTimer::timeout, this, [this] { computeLighting(); });
}

LightingScheduler::~LightingScheduler() { m_timer.stop(); }

void LightingScheduler::setAutoLighting(bool on)
{
    m_autoLighting = on;
    Q_EMIT autoLightingChanged(on);
    if (on) updateViewport();
    else m_timer.stop();
}

void LightingScheduler::cancel()
{
    if (m_job) m_job->cancel();
}

bool LightingScheduler::viewNeedsLighting() const
{
    const std::optional<RenderMode> compare = m_viewport->compare();
    return modeNeedsLighting(m_doc->scene().render.mode) || (compare && modeNeedsLighting(*compare));
}

void LightingScheduler::updateViewport()
{
    const Scene& s = m_doc->scene();
    const bool lit = viewNeedsLighting();
    std::vector<AssetsPtr> assets = m_assets->forScene(s, lit);
    const bool content = !s.instances.empty() || s.terrain.enabled();   // a landscape may have no instances
    Scene shown;
    const bool volumesReady = m_volumes.litScene(s, lit, &shown);   // the volumes with their lighting
    if (!content || (!assets.empty() && volumesReady)) {
        m_viewport->setScene(volumesReady ? shown : s, std::move(assets));
        return;
    }
    m_viewport->setScene(s, {});
    if (m_autoLighting) {
        m_viewport->setStatus(lit ? tr("Lighting the species...") : tr("Loading the species..."));
        m_timer.start();
    } else {
        m_viewport->setStatus(tr("Lighting not computed: Render > Compute Lighting (%1)")
                                  .arg(QKeySequence(Qt::CTRL | Qt::Key_L).toString(QKeySequence::NativeText)));
    }
}

Job* LightingScheduler::computeLighting(bool reload)
{
    m_timer.stop();
    const Scene scene = m_doc->scene();
    const bool lit = viewNeedsLighting();
    std::vector<std::string> target;
    for (const SpeciesDesc& sp : scene.species) target.push_back(assetKey(sp, scene.sun, lit));
    for (const VolumeDesc& v : scene.volumes) target.push_back(VolumeLightStore::key(scene, v, lit));
    if (m_job) {
        // One lighting job at a time. One that already makes what the scene needs (the camera or an
        // instance moved meanwhile) runs on; otherwise stop it and run again for the scene as it is now.
        if (!reload && target == m_target && !m_job->cancelRequested()) {
            m_again = false;
            return m_job;
        }
        m_job->cancel();
        m_again = true;
        return nullptr;
    }
    if (reload) {
        std::vector<std::string> keep;
        m_assets->retainOnly(keep);
    } else {
        // Keep what the scene uses (and what undo may bring back soon: everything of this sun).
        std::vector<std::string> keep;
        for (const SpeciesDesc& sp : scene.species) {
            keep.push_back(assetKey(sp, scene.sun, true));
            keep.push_back(assetKey(sp, scene.sun, false));
        }
        if (m_assets->size() > 4 * keep.size() + 8) m_assets->retainOnly(keep);
    }
    if (m_assets->missingSpecies(scene, lit).empty() && m_volumes.missing(scene, lit).empty()) {
        updateViewport();
        Q_EMIT settled();
        return nullptr;
    }
    GridCache* cache = m_cache;
    AssetStore* store = m_assets;
    VolumeLightStore* volumes = &m_volumes;
    Backend* backend = m_backend;
    log(lit ? tr("lighting %n species", nullptr, int(m_assets->missingSpecies(scene, lit).size()))
            : tr("loading %n species", nullptr, int(m_assets->missingSpecies(scene, lit).size())));
    m_target = target;
    m_job = m_jobs->start(lit ? tr("Lighting") : tr("Loading"),
                          [scene, lit, store, volumes, cache, backend](Job& job, Progress& progress) {
                              const auto log = [&job](const std::string& line) { job.log(QString::fromStdString(line)); };
                              const bool anyVolume = !volumes->missing(scene, lit).empty();
                              SubProgress speciesPart(&progress, 0.0, anyVolume ? 0.8 : 1.0);
                              Progress sp([&](double f, const std::string& msg) { speciesPart.report(f, msg); });
                              if (progress.isCancelled()) sp.cancel();
                              ensureAssets(scene, lit, *store, cache, &sp, log, backend);
                              if (!anyVolume) return;
                              // The volumes' LB lighting (lightSceneVolumes), through the same cache.
                              SubProgress volumePart(&progress, 0.8, 1.0);
                              Progress vp([&](double f, const std::string& msg) { volumePart.report(f, msg); });
                              if (progress.isCancelled()) vp.cancel();
                              volumes->ensure(scene, lit, cache, &vp, log, backend);
                          },
                          [this](Job* job) {
                              m_job = nullptr;
                              const bool ok = job->state() == Job::State::Succeeded;
                              if (ok)
                                  log(tr("lighting done in %1 s (backend: %2)")
                                          .arg(job->seconds(), 0, 'f', 2)
                                          .arg(QString::fromStdString(m_backend ? m_backend->name() : "cpu")));
                              else if (job->state() == Job::State::Cancelled) log(tr("lighting cancelled"));
                              else fail(tr("Lighting failed"), job->error());
                              if (m_again) {
                                  m_again = false;
                                  computeLighting();
                              } else {
                                  updateViewport();
                              }
                              Q_EMIT settled();
                              Q_EMIT lightingFinished(ok);
                          });
    return m_job;
}

} // namespace sylva
