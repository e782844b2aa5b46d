// Lighting scheduling: which species assets the viewport needs, the background job that grows/imports,
// voxelizes and lights the missing ones (ensureAssets: debounced, one at a time, restarted when the
// scene moves on), and the result into the viewport.
#pragma once

#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <QPointer>
#include <QTimer>

#include "studio/relight.h"
#include "studio/studio_controller.h"
#include "studio/volume_lighting.h"

namespace sylva {

class AssetStore;
class Backend;
class GridCache;
class Job;
class JobManager;
class SceneDocument;
class Viewport;

class LightingScheduler : public StudioController {
    Q_OBJECT

public:
    // Fills assets through cache in jobs of jobs, solving on backend (null = the CPU); hands the
    // document's scene and its assets to viewport.
    LightingScheduler(SceneDocument* doc, JobManager* jobs, AssetStore* assets, GridCache* cache, Backend* backend,
                      Viewport* viewport, QObject* parent = nullptr);
    ~LightingScheduler() override;

    // Lighting starts by itself (debounced) when the viewport lacks assets; off: computeLighting by hand.
    void setAutoLighting(bool on);
    bool autoLighting() const { return m_autoLighting; }

    // Loads/grows, voxelizes and lights what the viewport needs (reload: drop the in-memory assets
    // first, so the grid cache answers). Returns the job, or null when everything is in memory (or a
    // running job was cancelled to run again when it ends).
    Job* computeLighting(bool reload = false);
    // Gives the viewport the scene with its assets, or (assets missing) a status line and, with
    // automatic lighting, a lighting job a quarter second later.
    void updateViewport();
    // Whether the scene's mode (or the viewport's compare mode) needs lighting grids.
    bool viewNeedsLighting() const;
    // A lighting job runs or is about to start.
    bool isPending() const { return m_job || m_timer.isActive(); }
    // Cancels the running lighting job (New: the old scene's grids are not needed).
    void cancel();

    // Relighting from bases. Each species' basis (one LB solve per lattice direction,
    // lightingBasisFor) held in memory lets a sun change relight the viewport's kept frame with no LB
    // solve and no job (updateViewport). buildRelightingBasis solves what the grid cache lacks (18 solves
    // a species) and loads the rest; a basis already in the cache (`sylva light --basis`, an earlier
    // session) is loaded by itself after a lighting job that relit from it.
    Job* buildRelightingBasis();
    // Every species of the scene has its basis in memory (the CPU viewport relights from it).
    bool hasBases(const Scene& scene) const;
    // The relighting updateViewport hands the viewport for `scene`, if every species has a basis and
    // the viewport traces on the CPU.
    std::optional<Relighting> relightingFor(const Scene& scene) const;
    // Counters for tests and the bench: sun changes served from bases (no job), lighting jobs started.
    int relights() const { return m_relights; }
    int lightingJobs() const { return m_lightingJobs; }
    // The volumes' lit data the lighting jobs made (the viewport's scene carries it).
    VolumeLightStore* volumeLights() { return &m_volumes; }

Q_SIGNALS:
    void autoLightingChanged(bool on);
    // A lighting job ended, or computeLighting found everything in memory: who waits for the job's
    // grids may look again (isPending() says whether another job follows).
    void settled();
    void lightingFinished(bool succeeded);
    // A relighting-basis job ended; ok: every species it was asked for has its basis in memory.
    void basisFinished(bool ok);

private:
    SceneDocument* m_doc;
    JobManager* m_jobs;
    AssetStore* m_assets;
    GridCache* m_cache;
    Backend* m_backend;
    Viewport* m_viewport;
    bool m_autoLighting = true;
    QTimer m_timer;
    QPointer<Job> m_job;
    std::vector<std::string> m_target;   // asset keys (then volume keys) the running lighting job produces
    VolumeLightStore m_volumes;
    bool m_again = false;

    Job* startBasisJob(bool solve);
    std::map<std::string, BasisPtr> m_bases;   // by speciesFingerprint (a basis does not depend on the sun)
    QPointer<Job> m_basisJob;
    bool m_cachedBasisSeen = false;            // the running lighting job relit a species from a cached basis
    int m_relights = 0, m_lightingJobs = 0;
};

} // namespace sylva
