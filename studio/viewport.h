// The 3D view: a QOpenGLWidget showing the ray-traced forest as a texture, with orbit/pan/zoom and fly
// navigation. On an NVIDIA GPU the frame is traced on the device in paintGL and reaches the texture
// through a CUDA-GL pixel buffer (the picture never leaves the GPU); otherwise the render worker
// traces on the CPU and the film is uploaded.
#pragma once

#include <memory>
#include <optional>

#include <QElapsedTimer>
#include <QImage>
#include <QOpenGLBuffer>
#include <QOpenGLFunctions>
#include <QOpenGLWidget>
#include <QPoint>

#include "core/scene/scene.h"
#include "studio/asset_store.h"
#include "studio/render_worker.h"

class QOpenGLShaderProgram;
class QOpenGLTexture;

namespace sylva {

class Viewport : public QOpenGLWidget, protected QOpenGLFunctions {
    Q_OBJECT

public:
    explicit Viewport(QWidget* parent = nullptr);
    ~Viewport() override;

    // What to draw. assets: one per species, in order; empty = not ready (status says why). relight
    // (active): the species' lighting composed from bases for the scene's sun (RenderWorker::request).
    void setScene(const Scene& scene, std::vector<AssetsPtr> assets, Relighting relight = {});
    void setStatus(const QString& status);
    QString status() const { return m_status; }

    // The last image the renderer delivered (tone-mapped sRGB), its pass and whether it was the last.
    QImage lastImage() const { return m_image; }
    int lastPass() const { return m_lastPass; }
    bool lastImageFinal() const { return m_lastFinal; }
    // Seconds from the request to its first image, for the latest request that produced one.
    double firstImageSeconds() const { return m_firstImageSeconds; }

    // Progressive refinement: while nothing changes the viewport accumulates samples per pixel up to its sample
    // limit (setting viewport/sampleLimit; default finalPresetSamples(), the `final` quality preset's; 0: the
    // scene's render.spp, the picture `sylva render` gives), every pass at one exposure (RefineSettings::steady).
    // The count is drawn over the picture's lower left corner ("Samples 12 / 64", sampleCounterText) above a
    // progress bar along its lower edge (progressBarRect: the filled part, samples / target of the width).
    void setSampleLimit(int samples);
    int sampleLimit() const { return m_sampleLimit; }
    int samplesShown() const { return m_samplesShown; }   // per pixel in the picture shown (0: none yet)
    int sampleTarget() const { return m_sampleTarget; }   // what it settles at
    double exposureShown() const { return m_exposureShown; }   // the tone map's scale of the picture shown
    // View > Sample Counter: the counter and the bar drawn (on by default; sampleCounterText() says the count either way).
    void setSampleCounter(bool on);
    bool sampleCounter() const { return m_sampleCounter; }
    QString sampleCounterText() const;
    QRectF progressBarRect() const;
    static QColor progressBarColor() { return {90, 170, 255}; }
    // Render size in pixels (widget size x device pixel ratio).
    QSize renderSize() const;
    RenderWorker* worker() const { return m_worker; }

    // Where frames are traced: "cuda-gl" (device, interop) or "cpu"; set when the GL context is made.
    // Environment SYLVA_VIEWPORT=cpu keeps the CPU path. backendNote(): why the GPU path is off, or
    // the device it runs on.
    QString backend() const { return m_interop ? QStringLiteral("cuda-gl") : QStringLiteral("cpu"); }
    QString backendNote() const { return m_backendNote; }

    QSize sizeHint() const override { return {800, 450}; }

    // Side-by-side compare: the right half of the picture in a second mode, from the same trace.
    void setCompare(std::optional<RenderMode> mode);
    std::optional<RenderMode> compare() const { return m_compare; }

    // Orbit (left drag): about the surface under the cursor when the drag began (it stays on its pixel,
    // orbitCameraAbout), or about the target when the cursor is over the sky.
    // Fly navigation (toggle: F in the viewport): W/S forward/back, A/D left/right, Q/E down/up, each
    // press flyStep() metres (Shift: 5x); left drag looks around the eye. Off: left drag orbits.
    bool flyMode() const { return m_fly; }
    void setFlyMode(bool on);
    // Metres per key press (flyStepFor): over a terrain 0.5% of its size, else 5% of the eye-target distance but at
    // least 0.5% of the plants' extent.
    double flyStep() const;

    // Picking: what the camera ray through widget position `pos` (logical pixels) hits, traced in the frame
    // the picture is drawn from (the worker's on the CPU, the viewport's on the GPU); nothing before a frame
    // exists, or when the worker holds its frame to write it for longer than waitMs. A click (press and release
    // of the left button without a drag) picks and emits instancePicked.
    std::optional<ViewPick> pickAt(QPointF pos, int waitMs = 200) const;

    // The selected instance (index into Scene::instances; -1: none), outlined over the picture by its box's
    // twelve edges projected with the scene's camera (an overlay: the render does not restart).
    void setSelectedInstance(int instance);
    int selectedInstance() const { return m_selected; }
    // The selected instance's world box (invalid: none, or its species' mesh is not loaded yet) and the
    // bounding rectangle of its projected corners in widget pixels (empty when a corner is behind the eye).
    Bounds3 selectionBounds() const;
    QRectF selectionRect() const;
    // The species' mesh boxes (species frame) from the assets the viewport draws (invalid until loaded).
    const std::vector<Bounds3>& speciesBoxes() const { return m_speciesBoxes; }

    // The render camera's frame (View > Camera Frame): the part of the viewport that the render (render.width x
    // render.height) shows, the rest darkened. On, the viewport's camera is the scene's with its field of view
    // widened when the render is wider than the viewport (viewCamera), so the whole rendered picture lies
    // inside the viewport, centred: what is exported is what is framed. Off (the default), the viewport
    // shows the scene's camera at its own aspect.
    void setCameraFrame(bool on);
    bool cameraFrame() const { return m_cameraFrame; }
    // The render's frame in widget pixels (empty when the camera frame is off).
    QRectF cameraFrameRect() const;
    // The camera the viewport traces, picks and projects with: the scene's, its vertical field of view
    // widened by the render's aspect over the viewport's when the camera frame is on and the render is wider.
    CameraDesc viewCamera() const;

    // View > Frame All / Frame Selected: the scene's box (sceneBounds) or the selected instance's, framed
    // from the current view direction (frameBoxCamera); a navigation (no undo step). false (nothing moved) when there is
    // nothing to frame.
    bool frameAll();
    bool frameSelected();

Q_SIGNALS:
    // Navigation moved the camera (SceneDocument::navigate: no undo step, the scene not marked modified).
    void navigated(const sylva::CameraDesc& camera);
    void imageShown(int pass, bool last, double seconds);
    void renderFailed(const QString& message);
    void flyModeChanged(bool on);
    // A click picked this instance (index into Scene::instances), or -1: the sky, the ground, the terrain.
    void instancePicked(int instance);
    // A drag or wheel placed instance `instance` anew (Ctrl + drag: moved over the ground; Ctrl + wheel: turned;
    // Ctrl + Shift + wheel: scaled); `text` names the undo step, edits of one gesture share mergeKey.
    void instanceEdited(int instance, const sylva::InstanceDesc& placed, const QString& text, int mergeKey);
    // The GPU path was switched off (why); rendering goes on on the CPU.
    void gpuDisabled(const QString& message);

protected:
    void initializeGL() override;
    void paintGL() override;
    void resizeGL(int w, int h) override;
    void mousePressEvent(QMouseEvent* event) override;
    void mouseMoveEvent(QMouseEvent* event) override;
    void mouseReleaseEvent(QMouseEvent* event) override;
    void wheelEvent(QWheelEvent* event) override;
    void keyPressEvent(QKeyEvent* event) override;

private:
    void cleanupGL();
    void requestRender();
    void onImage(const QImage& image, int pass, bool last, double seconds, quint64 serial, int samples, int target,
                 double exposure);
    void drawProgress();
    void setupGpu();
    bool paintGpu();   // false: no GPU frame to show yet
    void disableGpu(const QString& why);
    void drawSelection();
    bool frameBox(const Bounds3& box);
    void drawCameraFrame();
    Scene viewScene() const;   // m_scene with viewCamera()

    RenderWorker* m_worker;
    Scene m_scene;
    std::vector<AssetsPtr> m_assets;
    std::vector<Bounds3> m_speciesBoxes;   // meshBounds of m_assets' meshes
    int m_selected = -1;
    Relighting m_relight;
    QString m_status;

    QImage m_image;
    bool m_imageDirty = false;
    int m_lastPass = -1;
    bool m_lastFinal = false;
    double m_firstImageSeconds = -1.0;
    bool m_awaitingFirst = false;
    int m_sampleLimit = 0;
    bool m_sampleCounter = true;
    int m_samplesShown = 0, m_sampleTarget = 0;
    double m_exposureShown = 0.0;

    // navigation
    enum class Drag { None, Orbit, Pan, Look, Move };
    Drag m_drag = Drag::None;
    bool m_dragMoved = false;   // past the drag distance: a drag, not a click
    double m_panDepth = 0.0;    // metres along the view to what the pan grabbed (0: the target's distance)
    std::optional<glm::dvec3> m_orbitPivot;   // what the orbit drag turns about (none: the target)
    QPoint m_dragStart;
    CameraDesc m_dragCamera;
    // instance edits in the viewport
    int m_moveInstance = -1;
    InstanceDesc m_moveFrom;     // the instance as the move drag found it
    glm::dvec3 m_moveGrab{0.0};  // the point of it the cursor grabbed (world metres)
    glm::dvec3 m_movePlane{0.0, 1.0, 0.0};   // the normal of the plane through m_moveGrab the drag slides it over
    int m_moveKey = 0;
    int m_wheelEditKey = 0;
    bool m_wheelEditScale = false;
    qint64 m_lastWheelEditMs = 0;
    bool m_fly = false;
    bool m_cameraFrame = false;
    std::optional<RenderMode> m_compare;

    // GL (hellogl2 pattern: created in initializeGL, freed on aboutToBeDestroyed)
    QOpenGLShaderProgram* m_program = nullptr;
    QOpenGLTexture* m_texture = nullptr;
    QOpenGLBuffer m_quad;
    void drawTexture();

    // GPU path: the device's display (null: CPU path)
    std::unique_ptr<DeviceDisplay> m_interop;
    GpuFramePtr m_gpuFrame;
    glm::dvec3 m_gpuPlacedAt{0.0};   // the eye m_gpuFrame was last placed for
    GLuint m_pbo = 0;
    QSize m_pboSize;
    size_t m_gpuPass = 0;   // index into the full-size passes of the worker's schedule
    QElapsedTimer m_sinceRequest;
    QString m_backendNote;
};

} // namespace sylva
