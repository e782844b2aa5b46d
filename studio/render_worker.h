// The viewport's progressive CPU renderer on its own thread: restarts on every request, emits images
// from a quarter-resolution preview up to a refined frame (Qt's mandelbrot RenderThread pattern). In
// GPU mode it builds and uploads the species part of the frame instead, and the viewport traces on
// the device through CUDA-GL interop.
#pragma once

#include <atomic>
#include <memory>
#include <optional>
#include <vector>

#include <QElapsedTimer>
#include <QImage>
#include <QMutex>
#include <QPointF>
#include <QReadWriteLock>
#include <QSize>
#include <QThread>
#include <QWaitCondition>

#include "core/backend/device_display.h"
#include "core/render/render_cpu.h"
#include "core/scene/scene.h"
#include "pipeline/render/view_frame.h"
#include "studio/asset_store.h"
#include "studio/relight.h"

namespace sylva {

// One pass of the progressive schedule: image size divisor and samples per pixel.
struct RenderPass {
    int divisor;
    int spp;
};

// The viewport's refinement once the schedule is done: `frames` full-size frames of `perFrame` samples each
// (whole cycles of the K sky-light subsets, at least the schedule's last pass's samples, so no frame shows
// more noise than the pass before it), accumulated (accumulateFilm) into the frame of `samples` samples per
// pixel: the sample limit (0: the scene's spp; then it is `sylva render`'s picture), at least K, at most
// kMaxViewportSamples. None (frames 0) for a constant sky whose samples the schedule's last pass already reaches.
struct Refinement {
    int samples = 0, perFrame = 0, frames = 0;
};
Refinement refinementFor(const RenderView& view, int sceneSpp, int lastPassSpp, int sampleLimit = 0);
inline constexpr int kMaxViewportSamples = 4096;   // render.spp's bound

// How the viewport refines a view that stays still (RenderWorker::setRefineSettings).
struct RefineSettings {
    // Samples per pixel the refinement accumulates to while nothing changes; 0: the scene's render.spp.
    int sampleLimit = 0;
    // One exposure for every picture of a request: the tone map's log-average (and the flat-ambient constant)
    // taken from the request's first pass and kept for its later passes and recompositions, and every pass lit
    // by the sky's lights (no sun-only preview), so refinement only removes noise. Off: each picture is exposed
    // as its own film (filmImage) and the schedule's passes light with the sun alone while a sky is refined.
    bool steady = false;
};

// The samples per pixel of the `final` quality preset (core/scene/quality.h): the viewport's default limit.
int finalPresetSamples();

// Tone-mapped sRGB picture of a film in a render mode (composeMode + toneMapped), as a QImage.
QImage filmImage(const Film& film, RenderMode mode, const glm::vec3& sky, float exposureKey);

// Side-by-side compare (Geist & Steele, "A Lighting Model for Fast Rendering of Forest Ecosystems", Figure 2)
// of one film: columns [0, width/2) from filmImage(film, left), the rest from filmImage(film, right); each half
// is exactly that mode's own picture.
QImage compareImage(const Film& film, RenderMode left, RenderMode right, const glm::vec3& sky, float exposureKey);

// compareImage of `film` exposed as `exposure` is: the log-average luminance of each half's mode (and the flat
// ambient constant) read from the film `exposure`, not from `film` (the viewport's one exposure for all passes of
// a view; `exposure` may have another size). scaleOut (optional): the left mode's exposure scale, key / log-average.
QImage heldExposureImage(const Film& film, const Film& exposure, RenderMode left, RenderMode right, const glm::vec3& sky,
                         float exposureKey, float* scaleOut = nullptr);

// The GPU viewport's frame: the species part built and uploaded on the worker thread, then handed to
// the viewport, which re-places it for every camera move (placeViewFrame, DeviceFrame::place).
struct GpuFrame {
    ViewFrame frame;
    std::unique_ptr<DeviceFrame> device;
    std::vector<AssetsPtr> assets;   // what it was built from
    Scene built;                     // ... and for which scene (viewFrameUpdate says when it is stale)
};
using GpuFramePtr = std::shared_ptr<GpuFrame>;

class RenderWorker : public QThread {
    Q_OBJECT

public:
    explicit RenderWorker(QObject* parent = nullptr);
    ~RenderWorker() override;

    // The default schedule: 1/4 size at 1 spp, full size at 1 spp, full size at 4 spp. A sky with virtual
    // lights (or a scene spp above the last pass's) is then refined (refinementFor); the schedule's frames
    // then light with the sun alone.
    static std::vector<RenderPass> defaultPasses();
    void setPasses(std::vector<RenderPass> passes);
    std::vector<RenderPass> passes() const;
    // How a still view refines (RefineSettings; default: to the scene's spp, each picture its own exposure).
    // Takes effect with the next request.
    void setRefineSettings(RefineSettings settings);
    RefineSettings refineSettings() const;

    // Renders `scene` with `assets` (one per species, in order) at `size` pixels. Cancels the frame in
    // progress. Same assets as the last request: only the top level is re-placed (fast); a change of
    // the render mode alone recomposes the last film without tracing.
    // compare: a second mode for the right half of the picture (compareImage); a change of it alone
    // recomposes like a mode change.
    // relight (active): the species' lighting composed from their bases for relight.sun replaces the
    // assets' grids in the kept frame (applyRelighting; a sun change then costs no build; CPU mode only).
    void request(const Scene& scene, std::vector<AssetsPtr> assets, QSize size,
                 std::optional<RenderMode> compare = std::nullopt, Relighting relight = {});
    // Stops the frame in progress and forgets the request (e.g. assets are being recomputed).
    void clear();

    // GPU mode: a request with new assets builds the frame, uploads it and emits gpuFrameReady instead
    // of tracing; a request with the assets of the last GPU frame does nothing (the viewport traces).
    // Switching (either way) forgets the last GPU frame.
    void setGpuMode(bool on);
    bool gpuMode() const { return m_gpu.load(); }

    // How often a request relit the kept frame from bases (applyRelighting) instead of building it.
    int relitFrames() const { return m_relitFrames.load(); }

    // How often the frame's camera-independent part was built whole (buildViewFrame), and how often an
    // edit was taken in by updating it in place (viewFrameUpdate: a landscape density, tile or tiling edit,
    // a volume edit) instead: what the studio's tests read to see that an edit rebuilt only its part.
    // The serial of the newest request (request() counts them from 1).
    quint64 latestRequest() const { return m_latestRequest.load(); }
    int frameBuilds() const { return m_frameBuilds.load(); }
    int frameUpdates() const { return m_frameUpdates.load(); }

    // What the camera ray through `pixel` (render pixels, y down) of a `size` picture of `camera` hits in the
    // kept frame (pickViewFrame): read from the GUI thread while the worker traces (reads only; the worker's
    // writes to the frame wait for it). Nothing when no frame is kept yet, or the worker is writing it
    // (building, re-placing) for longer than `waitMs`.
    std::optional<ViewPick> pick(const CameraDesc& camera, QSize size, QPointF pixel, int waitMs = 200) const;

Q_SIGNALS:
    // pass: index into the schedule (then the refinement's frames); last: the refinement is done; seconds: since the
    // request; serial: the request the image is for (latestRequest() says whether a newer one was made since);
    // samples: per pixel in this image; target: what the view settles at; exposure: the tone map's scale (key /
    // log-average luminance) of the image's (left) mode.
    void imageReady(const QImage& image, int pass, bool last, double seconds, quint64 serial, int samples, int target,
                    double exposure);
    void failed(const QString& message);
    // GPU mode: the frame for the requested assets is on the device.
    void gpuFrameReady(const sylva::GpuFramePtr& frame);
    // GPU mode failed (e.g. out of device memory): the worker is back in CPU mode and rendered on the CPU.
    void gpuFailed(const QString& message);

protected:
    void run() override;

private:
    struct Request {
        Scene scene;
        std::vector<AssetsPtr> assets;
        QSize size;
        std::optional<RenderMode> compare;
        Relighting relight;
        quint64 serial = 0;
    };
    void process(const Request& req, Progress& progress);
    // placeViewFrame on m_frame under m_frameLock, remembering the eye.
    void place(const Scene& scene, const glm::vec3& sun, int width, int height, int spp);
    bool interrupted() const { return m_restart.load() || m_abort.load(); }

    mutable QMutex m_mutex;
    QWaitCondition m_condition;
    Request m_request;
    std::vector<RenderPass> m_passes;
    RefineSettings m_refine;
    QElapsedTimer m_sinceRequest;
    std::atomic<bool> m_restart{false}, m_abort{false}, m_gpu{false}, m_gpuForget{false};
    bool m_hasRequest = false;

    // Worker-thread state. m_frame and m_placedAt change (on the worker thread) only under m_frameLock
    // written; pick reads them under it read.
    mutable QReadWriteLock m_frameLock;
    std::optional<ViewFrame> m_frame;
    glm::dvec3 m_placedAt{0.0};          // the eye m_frame was last placed for (its camera-relative origin)
    std::vector<AssetsPtr> m_frameAssets;
    Relighting m_frameRelight;            // the relighting m_frame's lighting array holds (inactive: the assets')
    std::atomic<int> m_relitFrames{0};
    std::atomic<quint64> m_latestRequest{0};
    std::atomic<bool> m_shieldPass{false};   // the pass in progress is not restarted by a new request
    Scene m_frameScene;                   // the scene m_frame's camera-independent part holds
    std::atomic<int> m_frameBuilds{0}, m_frameUpdates{0};
    std::optional<Scene> m_lastScene;     // what m_lastFilm shows
    QSize m_lastSize;
    Film m_lastFilm;
    Film m_exposureFilm;                  // steady: the first pass of m_lastFilm's request (its exposure)
    int m_lastPass = -1;
    int m_lastSamples = 0, m_lastTarget = 0;
    RefineSettings m_lastRefine;          // what m_lastFilm was refined with
    std::vector<AssetsPtr> m_gpuAssets;   // what the last GPU frame was built from
    Scene m_gpuScene;                     // ... and for which scene
    bool m_gpuPruned = false;             // ... and whether with every level of detail (the scene pruned)
};

} // namespace sylva

Q_DECLARE_METATYPE(sylva::GpuFramePtr)
