// RenderWorker: progressive passes with restart, the species part of the frame kept across camera moves.
#include "studio/render_worker.h"

#include <algorithm>
#include <cmath>
#include <string>

#include <QMutexLocker>
#include <QReadWriteLock>

#include "core/backend/backend.h"
#include "core/base/error.h"
#include "core/base/parallel.h"
#include "core/render/tonemap_film.h"
#include "core/scene/quality.h"
#include "pipeline/backend_select.h"
#include "pipeline/render/render_job.h"
#include "studio/background_priority.h"
#include "studio/scene_document.h"
#include "studio/view_transform.h"

namespace sylva {

QImage filmImage(const Film& film, RenderMode mode, const glm::vec3& sky, float exposureKey)
{
    return compareImage(film, mode, mode, sky, exposureKey);
}

QImage compareImage(const Film& film, RenderMode left, RenderMode right, const glm::vec3& sky, float exposureKey)
{
    if (film.width <= 0 || film.height <= 0) return {};
    if (!std::isfinite(exposureKey) || !(exposureKey > 0.0f))
        throw Error("tone map key " + std::to_string(exposureKey) + " must be finite and > 0");
    QImage out(film.width, film.height, QImage::Format_RGBX8888);   // bytes R, G, B, 255, rows packed
    double acc[kToneSums];
    toneMapFilm(HostExec{}, film.pixels.data(), film.width, film.height, left, right, sky, exposureKey, acc,
                reinterpret_cast<uint32_t*>(out.bits()));
    return out;
}

QImage heldExposureImage(const Film& film, const Film& exposure, RenderMode left, RenderMode right, const glm::vec3& sky,
                         float exposureKey, float* scaleOut)
{
    if (film.width <= 0 || film.height <= 0) return {};
    if (!std::isfinite(exposureKey) || !(exposureKey > 0.0f))
        throw Error("tone map key " + std::to_string(exposureKey) + " must be finite and > 0");
    // toneMapFilm's reductions over the exposure's film, its per-pixel pass over this film.
    const HostExec exec;
    double acc[kToneSums] = {};
    const size_t ne = size_t(exposure.width) * size_t(exposure.height);
    const bool ambient = left == RenderMode::Ambient || right == RenderMode::Ambient;
    exec.sum<2>(ambient ? ne : 0, tone_detail::AmbientTerms{exposure.pixels.data()}, acc);
    exec.sum<2>(ne, tone_detail::LogTerms{exposure.pixels.data(), left, sky, acc}, acc + 2);
    exec.sum<2>(right != left ? ne : 0, tone_detail::LogTerms{exposure.pixels.data(), right, sky, acc}, acc + 4);
    QImage out(film.width, film.height, QImage::Format_RGBX8888);   // bytes R, G, B, 255, rows packed
    exec.forEach(size_t(film.width) * size_t(film.height),
                 tone_detail::MapPixel{film.pixels.data(), film.width, left, right, sky, exposureKey, acc,
                                       reinterpret_cast<uint32_t*>(out.bits())});
    if (scaleOut) *scaleOut = exposureScale(exposureKey, logAverageOf(acc[2], acc[3]));
    return out;
}

int finalPresetSamples()
{
    const QualityPreset* q = findQualityPreset("final");
    return q ? q->spp : 64;
}

namespace {

// The picture of `film` for the request's scene; exposed as `exposure` (steady) or as itself.
QImage picture(const Film& film, const Film& exposure, const Scene& scene, const std::optional<RenderMode>& compare,
               float* scale)
{
    // The scene's view (view_transform.h), at the held exposure: Sylva Reinhard through the tone map's own
    // reductions, an OpenColorIO view through scenePicture with the exposure film.
    const Film& held = exposure.width > 0 ? exposure : film;
    if (!viewTransformOf(scene).isReinhard()) return scenePicture(film, scene, compare, &held, scale);
    const RenderMode left = scene.render.mode, right = compare ? *compare : left;
    return heldExposureImage(film, held, left, right, composeSky(scene), scene.render.exposureKey, scale);
}

} // namespace

RenderWorker::RenderWorker(QObject* parent) : QThread(parent), m_passes(defaultPasses())
{
    qRegisterMetaType<sylva::GpuFramePtr>();
}

RenderWorker::~RenderWorker()
{
    {
        QMutexLocker lock(&m_mutex);
        m_abort = true;
        m_condition.wakeOne();
    }
    wait();
}

std::vector<RenderPass> RenderWorker::defaultPasses() { return {{4, 1}, {1, 1}, {1, 4}}; }

void RenderWorker::setPasses(std::vector<RenderPass> passes)
{
    QMutexLocker lock(&m_mutex);
    m_passes = std::move(passes);
}

std::vector<RenderPass> RenderWorker::passes() const
{
    QMutexLocker lock(&m_mutex);
    return m_passes;
}

void RenderWorker::setRefineSettings(RefineSettings settings)
{
    QMutexLocker lock(&m_mutex);
    m_refine = settings;
}

RefineSettings RenderWorker::refineSettings() const
{
    QMutexLocker lock(&m_mutex);
    return m_refine;
}

void RenderWorker::request(const Scene& scene, std::vector<AssetsPtr> assets, QSize size, std::optional<RenderMode> compare,
                           Relighting relight)
{
    QMutexLocker lock(&m_mutex);
    m_request.scene = scene;
    m_request.assets = std::move(assets);
    m_request.size = size;
    m_request.compare = compare;
    m_request.relight = std::move(relight);
    ++m_request.serial;
    m_latestRequest = m_request.serial;
    m_hasRequest = true;
    m_sinceRequest.start();
    m_restart = true;
    if (!isRunning()) start(QThread::LowPriority);
    else m_condition.wakeOne();
}

void RenderWorker::clear()
{
    QMutexLocker lock(&m_mutex);
    m_hasRequest = false;
    m_restart = true;
}

void RenderWorker::setGpuMode(bool on)
{
    m_gpu = on;
    m_gpuForget = true;
}

void RenderWorker::run()
{
    lowerCurrentThreadPriority();
    quint64 done = 0;
    for (;;) {
        Request req;
        {
            QMutexLocker lock(&m_mutex);
            while (!m_abort && !(m_hasRequest && m_request.serial != done)) m_condition.wait(&m_mutex);
            if (m_abort) return;
            req = m_request;
            done = req.serial;
            m_restart = false;
        }
        Progress progress;
        progress.setCallback([this, &progress](double, const std::string&) {
            if (m_abort.load() || (m_restart.load() && !m_shieldPass.load())) progress.cancel();
        });
        try {
            process(req, progress);
        } catch (const Cancelled&) {
        } catch (const std::exception& e) {
            {
                QWriteLocker lock(&m_frameLock);
                m_frame.reset();
            }
            m_frameAssets.clear();
            Q_EMIT failed(QString::fromStdString(e.what()));
        }
    }
}

void RenderWorker::process(const Request& req, Progress& progress)
{
    const Scene& scene = req.scene;
    if (req.assets.size() != scene.species.size())
        throw Error("the render has " + std::to_string(req.assets.size()) + " species' assets for the scene's " +
                    std::to_string(scene.species.size()) + " species");
    const int w = std::max(1, req.size.width()), h = std::max(1, req.size.height());
    std::vector<RenderPass> passes;
    RefineSettings refineSettings;
    {
        QMutexLocker lock(&m_mutex);
        passes = m_passes;
        refineSettings = m_refine;
    }
    auto elapsed = [this] {
        QMutexLocker lock(&m_mutex);
        return double(m_sinceRequest.nsecsElapsed()) * 1e-9;
    };

    if (m_gpu) {
        if (m_gpuForget.exchange(false)) m_gpuAssets.clear();
        // The viewport has this frame and traces it itself (a frame built while the scene pruned has every
        // level of detail; one built without pruning is built again when pruning is turned on).
        if (m_gpuAssets == req.assets && !viewFrameUpdate(m_gpuScene, scene).any() &&
            (!(scene.render.pruneDistance > 0.0f) || m_gpuPruned))
            return;
        try {
            std::vector<SpeciesAssets> copies;
            copies.reserve(req.assets.size());
            for (const AssetsPtr& a : req.assets) copies.push_back(*a);
            const glm::vec3 sun = sunRadiance(scene.sun);
            auto g = std::make_shared<GpuFrame>();
            g->frame = buildViewFrame(scene, copies, sun);
            ++m_frameBuilds;
            if (interrupted()) throw Cancelled();
            placeViewFrame(g->frame, scene, sun, w, h, 1);
            g->device = uploadDeviceFrame(g->frame.rs);
            g->assets = req.assets;
            g->built = scene;
            m_gpuAssets = req.assets;
            m_gpuScene = scene;
            m_gpuPruned = scene.render.pruneDistance > 0.0f;
            Q_EMIT gpuFrameReady(g);
            return;
        } catch (const BackendError& e) {
            m_gpu = false;
            m_gpuAssets.clear();
            Q_EMIT gpuFailed(QString::fromStdString(e.what()));
        }
    }

    // A change of mode, compare mode, exposure or view alone (the refinement's settings unchanged): the film already
    // holds every mode's parts, and a steady picture keeps its exposure film.
    if (m_lastScene && m_frameAssets == req.assets && m_frameRelight == req.relight && m_lastSize == req.size &&
        m_lastPass == int(passes.size()) - 1 && m_lastRefine.sampleLimit == refineSettings.sampleLimit &&
        m_lastRefine.steady == refineSettings.steady) {
        Scene a = *m_lastScene, b = scene;
        a.render.mode = b.render.mode;
        a.render.exposureKey = b.render.exposureKey;
        a.render.view = b.render.view;
        a.render.display = b.render.display;
        if (changedParts(a, b) == ScenePart::None) {
            // A request cancelled since may have re-placed the frame for its own scene (an instance deleted, then
            // the delete undone before its first picture): the frame is placed for this scene again, as what the
            // viewport picks in must hold the instances shown.
            if (m_frame && !viewFrameUpdate(m_frameScene, scene).any() && viewFrameFits(*m_frame, scene))
                place(scene, sunRadiance(scene.sun), std::max(1, req.size.width()), std::max(1, req.size.height()),
                      passes.empty() ? 1 : passes.back().spp);
            float scale = 0.0f;
            const QImage img = picture(m_lastFilm, m_exposureFilm, scene, req.compare, &scale);
            m_lastScene = scene;
            Q_EMIT imageReady(img, m_lastPass, true, elapsed(), req.serial, m_lastSamples, m_lastTarget, scale);
            return;
        }
    }

    // The species' structures are kept while the assets stay; an edit of the landscape or the volumes
    // updates only its part (viewFrameUpdate), anything else the build reads (a sky edit among them: another
    // built sky, light count, interleave, or the ground plane under it) builds the frame again.
    const ViewFrameUpdate update = m_frame ? viewFrameUpdate(m_frameScene, scene) : ViewFrameUpdate{};
    if (!m_frame || m_frameAssets != req.assets || !viewFrameFits(*m_frame, scene) || update.rebuild) {
        {
            QWriteLocker lock(&m_frameLock);
            m_frame.reset();
        }
        std::vector<SpeciesAssets> copies;
        copies.reserve(req.assets.size());
        for (const AssetsPtr& a : req.assets) copies.push_back(*a);
        ViewFrame built = buildViewFrame(scene, copies, sunRadiance(scene.sun));
        {
            QWriteLocker lock(&m_frameLock);
            m_frame = std::move(built);
            m_placedAt = scene.camera.position;   // buildViewFrame places it at the scene's camera
        }
        m_frameAssets = req.assets;
        m_frameRelight = {};
        m_frameScene = scene;
        ++m_frameBuilds;
        if (interrupted()) throw Cancelled();
    } else if (update.any()) {
        QWriteLocker lock(&m_frameLock);
        try {
            updateViewFrame(*m_frame, scene, update);
        } catch (...) {
            m_frame.reset();   // half updated: build it whole next time
            throw;
        }
        m_frameScene = scene;
        ++m_frameUpdates;
        if (interrupted()) throw Cancelled();
    }
    bool relit = false;
    if (!(m_frameRelight == req.relight)) {
        // A sun change relit from the species' bases: the composed grids into the kept frame (not
        // interrupted: a frame half relit would have to be built again).
        {
            QWriteLocker lock(&m_frameLock);
            applyRelighting(m_frame->rs, req.assets, req.relight);
        }
        m_frameRelight = req.relight;
        relit = req.relight.active();
        if (relit) ++m_relitFrames;
    }
    const glm::vec3 sun = sunRadiance(scene.sun);
    // Progressive refinement: the schedule's frames (while the camera moves every request
    // restarts them) light with the sun's one shadow ray alone; then, at full size, frames of new sample
    // positions and sky-light subsets are accumulated up to the samples `sylva render` traces.
    // Steady: every pass lit alike (the sky's lights too) and exposed as the first.
    const Refinement refine = refinementFor(m_frame->rs.view(),   // the sky's lights are the frame's (built, not placed)
                                             scene.render.spp, passes.empty() ? 0 : passes.back().spp, refineSettings.sampleLimit);
    const bool steady = refineSettings.steady;
    const int target = refine.frames > 0 ? refine.samples : passes.empty() ? 0 : passes.back().spp;
    bool exposureSet = false;   // m_exposureFilm is this request's (set with its first picture)
    for (size_t p = 0; p < passes.size(); ++p) {
        const int pw = std::max(1, w / passes[p].divisor), ph = std::max(1, h / passes[p].divisor);
        place(scene, sun, pw, ph, passes[p].spp);
        RenderView view = m_frame->rs.view();
        if (refine.frames > 0 && !steady) view.sky.lightCount = 0;   // moving: the sun alone
        // The first pass of a relit frame runs to its end even when the next sun is already asked for:
        // a sun drag shows every relit sun it can (one preview each) instead of restarting before any.
        const bool shield = relit && p == 0;
        m_shieldPass = shield;
        Film film = renderFilm(view, &progress);
        m_shieldPass = false;
        if (m_abort.load() || (interrupted() && !shield)) throw Cancelled();
        if (!exposureSet) {
            m_exposureFilm = steady ? film : Film{};
            exposureSet = true;
        }
        float scale = 0.0f;
        const QImage img = picture(film, m_exposureFilm, scene, req.compare, &scale);
        const bool last = p + 1 == passes.size() && refine.frames == 0;
        m_lastFilm = std::move(film);
        m_lastScene = scene;
        m_lastSize = req.size;
        m_lastPass = last ? int(passes.size()) - 1 : -1;
        m_lastSamples = passes[p].spp;
        m_lastTarget = target;
        m_lastRefine = refineSettings;
        Q_EMIT imageReady(img, int(p), last, elapsed(), req.serial, passes[p].spp, target, scale);
    }
    if (refine.frames == 0) return;
    place(scene, sun, w, h, refine.samples);
    Film sum;
    int done = 0;
    for (int f = 0; f < refine.frames; ++f) {
        RenderView view = m_frame->rs.view();
        view.sampleBegin = done;
        view.sampleEnd = std::min(refine.samples, done + refine.perFrame);
        const Film part = renderFilm(view, &progress);
        if (interrupted()) throw Cancelled();
        accumulateFilm(sum, done, part, view.sampleEnd - view.sampleBegin);
        done = view.sampleEnd;
        const bool last = done >= refine.samples;
        if (!exposureSet) {
            m_exposureFilm = steady ? sum : Film{};
            exposureSet = true;
        }
        float scale = 0.0f;
        const QImage img = picture(sum, m_exposureFilm, scene, req.compare, &scale);
        m_lastFilm = sum;
        m_lastScene = scene;
        m_lastSize = req.size;
        m_lastPass = last ? int(passes.size()) - 1 : -1;
        m_lastSamples = done;
        m_lastTarget = target;
        m_lastRefine = refineSettings;
        Q_EMIT imageReady(img, int(passes.size()) + f, last, elapsed(), req.serial, done, target, scale);
    }
}

void RenderWorker::place(const Scene& scene, const glm::vec3& sun, int width, int height, int spp)
{
    QWriteLocker lock(&m_frameLock);
    placeViewFrame(*m_frame, scene, sun, width, height, spp);
    m_placedAt = scene.camera.position;
}

std::optional<ViewPick> RenderWorker::pick(const CameraDesc& camera, QSize size, QPointF pixel, int waitMs) const
{
    if (!m_frameLock.tryLockForRead(waitMs)) return std::nullopt;
    std::optional<ViewPick> hit;
    try {
        if (m_frame) hit = pickViewFrame(*m_frame, m_placedAt, camera, size.width(), size.height(), pixel.x(), pixel.y());
    } catch (const std::exception&) {
        hit.reset();   // a degenerate camera: nothing to pick
    }
    m_frameLock.unlock();
    return hit;
}

Refinement refinementFor(const RenderView& view, int sceneSpp, int lastPassSpp, int sampleLimit)
{
    Refinement r;
    const int want = std::clamp(sampleLimit > 0 ? sampleLimit : sceneSpp, 1, kMaxViewportSamples);
    if (view.sky.lightCount == 0 && want <= lastPassSpp) return r;   // the constant sky: the schedule as before
    const int subsets = std::max(1, view.sky.interleave.subsets);
    r.samples = std::max(want, subsets);
    r.perFrame = subsets * std::max(1, (std::max(1, lastPassSpp) + subsets - 1) / subsets);
    r.frames = (r.samples + r.perFrame - 1) / r.perFrame;
    return r;
}

} // namespace sylva
