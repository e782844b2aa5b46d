// LightingScheduler: the viewport's assets and the one lighting job that makes the missing ones.
#include "studio/lighting_scheduler.h"

#include <cstdio>
#include <optional>
#include <utility>

#include <QKeySequence>

#include "core/backend/backend.h"
#include "core/base/error.h"
#include "pipeline/cache/grid_cache.h"
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
    if (m_doc->scene().render.integrator == Integrator::Path) return false;   // the path tracer reads no grid
    const std::optional<RenderMode> compare = m_viewport->compare();
    return modeNeedsLighting(m_doc->scene().render.mode) || (compare && modeNeedsLighting(*compare));
}

void LightingScheduler::updateViewport()
{
    const Scene& s = m_doc->scene();
    const bool lit = viewNeedsLighting();
    std::vector<AssetsPtr> assets = m_assets->forScene(s, lit);
    const bool speciesReady = assets.size() == s.species.size();   // forScene gives none while one is missing
    Scene shown;
    const bool volumesReady = m_volumes.litScene(s, lit, &shown);   // the volumes with their lighting
    if (speciesReady && volumesReady) {
        m_viewport->setScene(volumesReady ? shown : s, std::move(assets));
        return;
    }
    if (lit && !s.instances.empty()) {
        // The sun moved and every species has its basis in memory: the kept frame is relit, no LB solve.
        if (std::optional<Relighting> r = relightingFor(s)) {
            std::vector<AssetsPtr> base = m_assets->litForAnySun(s);
            if (!base.empty()) {
                m_timer.stop();
                ++m_relights;
                m_viewport->setScene(s, std::move(base), std::move(*r));
                return;
            }
        }
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
    for (const SpeciesDesc& sp : scene.species) target.push_back(assetKey(sp, scene, lit));
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
            keep.push_back(assetKey(sp, scene, true));
            keep.push_back(assetKey(sp, scene, false));
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
                              // A species relit from a basis in the grid cache: hold the bases in memory.
                              if (ok && std::exchange(m_cachedBasisSeen, false) && !hasBases(m_doc->scene())) startBasisJob(false);
                              Q_EMIT settled();
                              Q_EMIT lightingFinished(ok);
                          });
    ++m_lightingJobs;
    m_cachedBasisSeen = false;
    connect(m_job, &Job::logLine, this, [this](const QString& line) {
        if (line.contains(QLatin1String("relit from the cached basis"))) m_cachedBasisSeen = true;
    });
    return m_job;
}

bool LightingScheduler::hasBases(const Scene& scene) const
{
    for (const SpeciesDesc& sp : scene.species)
        if (!m_bases.count(speciesFingerprint(sp))) return false;
    return !scene.species.empty();
}

std::optional<Relighting> LightingScheduler::relightingFor(const Scene& scene) const
{
    if (m_viewport->backend() != QLatin1String("cpu")) return std::nullopt;   // the device frame is built per set of assets
    // Direct light counted once: the grid is the solve minus its uncollided part, which the bases (full
    // solves) do not separate; the lighting job makes those grids.
    if (gridDirectLight(scene.lighting) != DirectLight::Seed) return std::nullopt;
    // The sky in the boundary: the bases would compose it too, but its weights follow the sky and the sun's
    // radiance as well; the lighting job makes those grids.
    if (scene.lighting.boundary != LbBoundary::Sun) return std::nullopt;
    Relighting r;
    r.sun = scene.sun.direction;
    for (const SpeciesDesc& sp : scene.species) {
        auto it = m_bases.find(speciesFingerprint(sp));
        if (it == m_bases.end()) return std::nullopt;
        r.bases.push_back(it->second);
    }
    if (r.bases.empty()) return std::nullopt;
    return r;
}

Job* LightingScheduler::buildRelightingBasis() { return startBasisJob(true); }

Job* LightingScheduler::startBasisJob(bool solve)
{
    if (m_basisJob) return m_basisJob;
    const Scene scene = m_doc->scene();
    if (!m_cache || scene.species.empty()) return nullptr;
    // The species without a basis in memory, with their meshes when they are loaded.
    struct Want {
        size_t index;
        std::string key;
        AssetsPtr geometry;
    };
    std::vector<Want> want;
    std::vector<AssetsPtr> geometry = m_assets->forScene(scene, false);
    if (geometry.empty()) geometry = m_assets->litForAnySun(scene);
    for (size_t i = 0; i < scene.species.size(); ++i) {
        const std::string key = speciesFingerprint(scene.species[i]);
        if (!m_bases.count(key)) want.push_back({i, key, geometry.empty() ? nullptr : geometry[i]});
    }
    if (want.empty()) {
        Q_EMIT basisFinished(true);
        return nullptr;
    }
    auto found = std::make_shared<std::vector<std::pair<std::string, BasisPtr>>>();
    GridCache* cache = m_cache;
    Backend* backend = m_backend;
    m_basisJob = m_jobs->start(
        solve ? tr("Relighting basis") : tr("Relighting basis (cache)"),
        [scene, want, found, cache, backend, solve](Job& job, Progress& progress) {
            for (size_t k = 0; k < want.size(); ++k) {
                const SpeciesDesc& sp = scene.species[want[k].index];
                SubProgress part(&progress, double(k) / double(want.size()), double(k + 1) / double(want.size()));
                Progress sub([&](double f, const std::string& msg) { part.report(f, sp.name + ": " + msg); });
                if (progress.isCancelled()) sub.cancel();
                JobLog log;
                // The density (and the scene sun's lighting) through the same calls as the viewport's assets: cache hits.
                const SpeciesGrids g = loadSpeciesGrids(scene, want[k].index, cache, nullptr, nullptr,
                                                        want[k].geometry ? &want[k].geometry->mesh : nullptr, backend);
                std::optional<LightingBasis> basis;
                try {
                    basis = solve ? std::optional<LightingBasis>(lightingBasisFor(g.density, g.params, cache, &sub, &log, backend))
                                  : cachedLightingBasis(g.density, g.params, *cache, &log);
                } catch (const Cancelled&) {
                    throw;
                } catch (const Error& e) {
                    job.log(QString::fromStdString(sp.name + ": no relighting basis: " + e.what()));
                    continue;
                }
                if (!basis) continue;
                int solved = 0;
                for (const std::string& st : log.stages) solved += st == "basis light" ? 1 : 0;
                char line[256];
                std::snprintf(line, sizeof line, "%s: relighting basis, %zu grids, %.1f MB in memory, %d solved, %zu from the cache",
                              sp.name.c_str(), basis->grids.size(), basisBytes(*basis) / 1e6, solved, basis->grids.size() - size_t(solved));
                job.log(QString::fromUtf8(line));
                auto b = std::make_shared<SpeciesBasis>();
                b->basis = std::move(*basis);
                b->params = g.params;
                found->emplace_back(want[k].key, std::move(b));
            }
        },
        [this, found, n = want.size()](Job* job) {
            m_basisJob = nullptr;
            // Keep the bases of the scene's species (the new ones and those still in it).
            std::map<std::string, BasisPtr> keep;
            for (const SpeciesDesc& sp : m_doc->scene().species) {
                const std::string key = speciesFingerprint(sp);
                if (auto it = m_bases.find(key); it != m_bases.end()) keep.insert(*it);
            }
            for (auto& [key, b] : *found) keep[key] = b;
            m_bases = std::move(keep);
            const bool ok = job->state() == Job::State::Succeeded && found->size() == n;
            if (job->state() == Job::State::Failed) fail(tr("Relighting basis failed"), job->error());
            updateViewport();
            Q_EMIT basisFinished(ok);
        });
    return m_basisJob;
}

} // namespace sylva
