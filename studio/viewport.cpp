// Viewport: film texture on a quad, overlay text and selection, mouse navigation feeding undoable camera
// edits, picking by one traced ray.
#include "studio/viewport.h"

#include <algorithm>
#include <cmath>

#include <QApplication>
#include <QDateTime>
#include <QKeyEvent>
#include <QMouseEvent>
#include <QOpenGLContext>
#include <QOpenGLShaderProgram>
#include <QOpenGLTexture>
#include <QPainter>
#include <QSettings>
#include <QWheelEvent>

#include "core/backend/backend.h"
#include "pipeline/backend_select.h"
#include "pipeline/render/render_job.h"
#include "pipeline/scene/scene_fields.h"
#include "studio/camera_nav.h"
#include "studio/render_worker.h"
#include "studio/scene_document.h"
#include "studio/words.h"

namespace sylva {
namespace {

// GLSL 1.10/1.20 (compatibility contexts, what Qt asks for by default on desktop GL).
const char* kVertexShader = R"(
attribute vec2 position;
attribute vec2 texCoord;
varying vec2 uv;
void main() { uv = texCoord; gl_Position = vec4(position, 0.0, 1.0); }
)";
const char* kFragmentShader = R"(
#ifdef GL_ES
precision mediump float;
#endif
uniform sampler2D film;
varying vec2 uv;
void main() { gl_FragColor = vec4(texture2D(film, uv).rgb, 1.0); }
)";

// How long a pan or a wheel notch waits for the worker's frame to pick what is under the cursor (the worker
// holds it only to build, update or re-place it): past that it goes by the target, the GUI does not stall.
constexpr int kNavigationPickMs = 20;

} // namespace

Viewport::Viewport(QWidget* parent) : QOpenGLWidget(parent), m_worker(new RenderWorker(this)), m_quad(QOpenGLBuffer::VertexBuffer)
{
    setFocusPolicy(Qt::StrongFocus);
    setMinimumSize(160, 90);
    m_sampleLimit = std::max(0, QSettings().value("viewport/sampleLimit", finalPresetSamples()).toInt());
    m_worker->setRefineSettings({m_sampleLimit, true});
    connect(m_worker, &RenderWorker::imageReady, this, &Viewport::onImage);
    connect(m_worker, &RenderWorker::failed, this, [this](const QString& message) {
        setStatus(message);
        Q_EMIT renderFailed(message);
    });
    connect(m_worker, &RenderWorker::gpuFrameReady, this, [this](const GpuFramePtr& frame) {
        if (!m_interop || frame->assets != m_assets) return;   // stale: the assets changed again meanwhile
        m_gpuFrame = frame;
        m_gpuPlacedAt = frame->built.camera.position;   // the worker placed it at the scene's camera
        m_gpuPass = 0;
        update();
    });
    connect(m_worker, &RenderWorker::gpuFailed, this, [this](const QString& message) {
        // The worker is back on the CPU and renders this request there.
        if (m_interop) {
            makeCurrent();
            disableGpu(message);
            doneCurrent();
        }
    });
}

Viewport::~Viewport()
{
    // Stop the worker before the GL context goes (it only emits queued images, but be tidy).
    delete m_worker;
    m_worker = nullptr;
    // ~QOpenGLWidget destroys the context after this object's members are gone: the context's
    // aboutToBeDestroyed must not reach cleanupGL then (it would touch the destroyed m_quad).
    if (context()) disconnect(context(), &QOpenGLContext::aboutToBeDestroyed, this, &Viewport::cleanupGL);
    makeCurrent();
    cleanupGL();
    doneCurrent();
}

QSize Viewport::renderSize() const
{
    const qreal dpr = devicePixelRatioF();
    return QSize(std::max(1, int(width() * dpr)), std::max(1, int(height() * dpr)));
}

void Viewport::setScene(const Scene& scene, std::vector<AssetsPtr> assets, Relighting relight)
{
    if (assets != m_assets || m_speciesBoxes.size() != scene.species.size()) {
        m_speciesBoxes.assign(scene.species.size(), Bounds3{});
        for (size_t k = 0; k < assets.size() && k < m_speciesBoxes.size(); ++k)
            if (assets[k]) m_speciesBoxes[k] = meshBounds(assets[k]->mesh);
    }
    m_scene = scene;
    m_assets = std::move(assets);
    m_relight = std::move(relight);
    requestRender();
}

void Viewport::setStatus(const QString& status)
{
    if (m_status == status) return;
    m_status = status;
    update();
}

void Viewport::requestRender()
{
    // Every species' assets (none in a scene of ground, terrain, sky and volumes alone, which renders too).
    if (m_assets.size() != m_scene.species.size()) {
        m_worker->clear();
        return;
    }
    setStatus(QString());
    m_awaitingFirst = true;
    m_sinceRequest.start();
    if (m_interop) {
        // The device traces in paintGL; the worker only builds and uploads frames for new assets.
        m_gpuPass = 0;
        if (!m_gpuFrame || m_gpuFrame->assets != m_assets || !viewFrameFits(m_gpuFrame->frame, m_scene) ||
            viewFrameUpdate(m_gpuFrame->built, m_scene).any())
            m_worker->request(viewScene(), m_assets, renderSize(), m_compare);
        update();
        return;
    }
    m_worker->request(viewScene(), m_assets, renderSize(), m_compare, m_relight);
}

void Viewport::setSampleLimit(int samples)
{
    samples = std::clamp(samples, 0, kMaxViewportSamples);
    QSettings().setValue("viewport/sampleLimit", samples);
    if (samples == m_sampleLimit) return;
    m_sampleLimit = samples;
    m_worker->setRefineSettings({m_sampleLimit, true});
    requestRender();
}

void Viewport::setSampleCounter(bool on)
{
    if (m_sampleCounter == on) return;
    m_sampleCounter = on;
    update();
}

QString Viewport::sampleCounterText() const
{
    if (m_samplesShown <= 0) return QString();
    return tr("Samples %1 / %2").arg(m_samplesShown).arg(std::max(m_samplesShown, m_sampleTarget));
}

QRectF Viewport::progressBarRect() const
{
    if (m_samplesShown <= 0) return {};
    const double f = m_sampleTarget > 0 ? std::min(1.0, double(m_samplesShown) / double(m_sampleTarget)) : 1.0;
    const double h = 3.0;
    return {0.0, double(height()) - h, std::round(f * double(width())), h};
}

void Viewport::drawProgress()
{
    const QString text = sampleCounterText();
    if (!m_sampleCounter || text.isEmpty()) return;
    QPainter p(this);
    const QRectF bar = progressBarRect();
    p.fillRect(QRectF(0.0, bar.top(), double(width()), bar.height()), QColor(0, 0, 0, 140));   // the track
    p.fillRect(bar, progressBarColor());
    QFont f = p.font();
    f.setPixelSize(11);
    p.setFont(f);
    const QRect box = p.fontMetrics().boundingRect(text).adjusted(-4, -2, 4, 2);
    const QRect at(6, int(bar.top()) - 4 - box.height(), box.width(), box.height());
    p.fillRect(at, QColor(0, 0, 0, 120));
    p.setPen(QColor(235, 235, 235));
    p.drawText(at, Qt::AlignCenter, text);
}

void Viewport::onImage(const QImage& image, int pass, bool last, double seconds, quint64 serial, int samples, int target,
                       double exposure)
{
    m_samplesShown = samples;
    m_sampleTarget = target;
    m_exposureShown = exposure;
    // An image queued before a newer request (an edit while its signal waited in the event loop) is
    // shown, so a drag still moves the picture, but it is not the current scene's final image.
    if (serial != m_worker->latestRequest()) last = false;
    m_image = image;
    m_imageDirty = true;
    m_lastPass = pass;
    m_lastFinal = last;
    if (m_awaitingFirst) {
        m_firstImageSeconds = seconds;
        m_awaitingFirst = false;
    }
    update();
    Q_EMIT imageShown(pass, last, seconds);
}

void Viewport::initializeGL()
{
    connect(context(), &QOpenGLContext::aboutToBeDestroyed, this, &Viewport::cleanupGL, Qt::UniqueConnection);
    initializeOpenGLFunctions();
    m_program = new QOpenGLShaderProgram;
    m_program->addShaderFromSourceCode(QOpenGLShader::Vertex, kVertexShader);
    m_program->addShaderFromSourceCode(QOpenGLShader::Fragment, kFragmentShader);
    m_program->bindAttributeLocation("position", 0);
    m_program->bindAttributeLocation("texCoord", 1);
    if (!m_program->link()) qWarning("viewport shader: %s", qPrintable(m_program->log()));
    // Full-window quad as a strip: position xy, texture uv (image rows top first, so v flips).
    const GLfloat quad[] = {-1, -1, 0, 1, 1, -1, 1, 1, -1, 1, 0, 0, 1, 1, 1, 0};
    m_quad.create();
    m_quad.bind();
    m_quad.allocate(quad, sizeof quad);
    m_quad.release();
    m_imageDirty = true;
    setupGpu();
}

void Viewport::setupGpu()
{
    if (m_interop) return;
    if (qEnvironmentVariable("SYLVA_VIEWPORT") == QLatin1String("cpu")) {
        m_backendNote = tr("CPU viewport (SYLVA_VIEWPORT=cpu)");
        return;
    }
    std::string why;
    std::unique_ptr<DeviceDisplay> interop = makeDeviceDisplay(&why);
    if (!interop) {
        m_backendNote = tr("CPU viewport: %1").arg(QString::fromStdString(why));
        return;
    }
    // Interop needs this GL context to run on the CUDA device: registering a buffer tells.
    GLuint probe = 0;
    glGenBuffers(1, &probe);
    glBindBuffer(GL_PIXEL_UNPACK_BUFFER, probe);
    glBufferData(GL_PIXEL_UNPACK_BUFFER, 4, nullptr, GL_STREAM_DRAW);
    glBindBuffer(GL_PIXEL_UNPACK_BUFFER, 0);
    try {
        interop->setPixelBuffer(probe, 1, 1);
    } catch (const BackendError& e) {
        glDeleteBuffers(1, &probe);
        m_backendNote = tr("CPU viewport: this OpenGL (%1) cannot share buffers with CUDA (%2)")
                            .arg(QString::fromLatin1(reinterpret_cast<const char*>(glGetString(GL_RENDERER))),
                                 QString::fromStdString(e.what()));
        return;
    }
    m_interop = std::move(interop);
    m_pbo = probe;
    m_pboSize = QSize(1, 1);
    m_backendNote = tr("GPU viewport: CUDA-GL interop on %1").arg(QString::fromStdString(m_interop->deviceName()));
    m_worker->setGpuMode(true);
    requestRender();
}

void Viewport::disableGpu(const QString& why)
{
    // The GL context is current. Unregister before the buffer goes.
    m_interop.reset();
    m_gpuFrame.reset();
    if (m_pbo) glDeleteBuffers(1, &m_pbo);
    m_pbo = 0;
    m_pboSize = QSize();
    m_backendNote = tr("CPU viewport: the GPU path stopped (%1)").arg(why);
    m_worker->setGpuMode(false);
    qWarning("viewport: %s", qPrintable(m_backendNote));
    Q_EMIT gpuDisabled(why);
    requestRender();
}

void Viewport::cleanupGL()
{
    if (!m_program && !m_texture && !m_quad.isCreated() && !m_interop) return;
    makeCurrent();
    m_interop.reset();   // unregisters the pixel buffer while it still exists
    m_gpuFrame.reset();
    if (m_pbo) glDeleteBuffers(1, &m_pbo);
    m_pbo = 0;
    m_pboSize = QSize();
    delete m_texture;
    m_texture = nullptr;
    delete m_program;
    m_program = nullptr;
    m_quad.destroy();
    doneCurrent();
}

void Viewport::resizeGL(int, int) { requestRender(); }

void Viewport::paintGL()
{
    glClearColor(0.12f, 0.12f, 0.13f, 1.0f);
    glClear(GL_COLOR_BUFFER_BIT);
    bool gpuDrawn = false;
    if (m_interop) {
        try {
            gpuDrawn = paintGpu();
        } catch (const std::exception& e) {
            disableGpu(QString::fromStdString(e.what()));
        }
    }
    if (!gpuDrawn && m_imageDirty && !m_image.isNull()) {
        delete m_texture;
        m_texture = new QOpenGLTexture(m_image, QOpenGLTexture::DontGenerateMipMaps);
        m_texture->setMinificationFilter(QOpenGLTexture::Linear);
        m_texture->setMagnificationFilter(QOpenGLTexture::Linear);
        m_texture->setWrapMode(QOpenGLTexture::ClampToEdge);
        m_imageDirty = false;
    }
    drawTexture();
    drawCameraFrame();
    drawSelection();
    drawProgress();
    if (m_compare && m_texture && m_texture->width() > 0) {
        // The split the renderer made (column width / 2 of the picture), and which mode is where.
        QPainter p(this);
        const int iw = m_texture->width();
        const int x = int(double(width()) * double(iw / 2) / double(iw));
        p.setPen(QColor(255, 255, 255, 200));
        p.drawLine(x, 0, x, height());
        p.drawText(QRect(8, 8, x - 16, 20), Qt::AlignLeft | Qt::AlignTop, renderModeLabel(m_scene.render.mode));
        p.drawText(QRect(x + 8, 8, width() - x - 16, 20), Qt::AlignLeft | Qt::AlignTop, renderModeLabel(*m_compare));
    }
    if (!m_status.isEmpty()) {
        QPainter p(this);
        p.setPen(QColor(230, 230, 230));
        p.drawText(rect().adjusted(12, 12, -12, -12), Qt::AlignLeft | Qt::AlignTop | Qt::TextWordWrap, m_status);
    }
}

void Viewport::drawTexture()
{
    if (!m_texture || !m_program || !m_program->isLinked()) return;
    m_program->bind();
    m_program->setUniformValue("film", 0);
    m_texture->bind(0);
    m_quad.bind();
    m_program->enableAttributeArray(0);
    m_program->enableAttributeArray(1);
    m_program->setAttributeBuffer(0, GL_FLOAT, 0, 2, 4 * sizeof(GLfloat));
    m_program->setAttributeBuffer(1, GL_FLOAT, 2 * sizeof(GLfloat), 2, 4 * sizeof(GLfloat));
    glDrawArrays(GL_TRIANGLE_STRIP, 0, 4);
    m_program->disableAttributeArray(0);
    m_program->disableAttributeArray(1);
    m_quad.release();
    m_texture->release();
    m_program->release();
}

// One pass of the GPU schedule (the worker's full-size passes, e.g. 1 then 4 samples per pixel): place
// the frame at the current camera, trace and tone-map into the pixel buffer, copy it into the texture
// on the GPU. Passes after the first follow while nothing changes.
bool Viewport::paintGpu()
{
    if (!m_gpuFrame || m_gpuFrame->assets != m_assets) return false;
    if (viewFrameUpdate(m_gpuFrame->built, m_scene).any()) return false;   // a landscape or volume edit: the worker builds it
    if (!viewFrameFits(m_gpuFrame->frame, m_scene)) return false;   // pruning turned on: the worker builds the levels
    std::vector<int> spps;
    for (const RenderPass& p : m_worker->passes())
        if (p.divisor == 1) spps.push_back(p.spp);
    if (spps.empty()) spps.push_back(1);
    // Progressive refinement on the device, as the worker does it on the CPU: the schedule's
    // passes light with the sun's shadow ray alone, then one full-size frame of every sample and sky-light
    // subset (refinementFor's count: the picture the worker accumulates, `sylva render --spp` at that count).
    RenderScene& rs = m_gpuFrame->frame.rs;
    const Refinement refine = refinementFor(rs.view(), m_scene.render.spp, spps.back());
    if (refine.frames > 0) spps.push_back(refine.samples);
    m_gpuPass = std::min(m_gpuPass, spps.size() - 1);
    const QSize size = renderSize();
    const int w = size.width(), h = size.height();
    if (m_pboSize != size || !m_texture || m_texture->width() != w || m_texture->height() != h) {
        m_interop->releasePixelBuffer();   // before the buffer is reallocated
        glBindBuffer(GL_PIXEL_UNPACK_BUFFER, m_pbo);
        glBufferData(GL_PIXEL_UNPACK_BUFFER, GLsizeiptr(w) * h * 4, nullptr, GL_STREAM_DRAW);
        glBindBuffer(GL_PIXEL_UNPACK_BUFFER, 0);
        m_interop->setPixelBuffer(m_pbo, w, h);
        m_pboSize = size;
        delete m_texture;
        m_texture = new QOpenGLTexture(QOpenGLTexture::Target2D);
        m_texture->setSize(w, h);
        m_texture->setFormat(QOpenGLTexture::RGBA8_UNorm);
        m_texture->setMipLevels(1);
        m_texture->allocateStorage(QOpenGLTexture::RGBA, QOpenGLTexture::UInt8);
        m_texture->setMinificationFilter(QOpenGLTexture::Linear);
        m_texture->setMagnificationFilter(QOpenGLTexture::Linear);
        m_texture->setWrapMode(QOpenGLTexture::ClampToEdge);
    }
    const size_t pass = m_gpuPass;
    const bool last = pass + 1 == spps.size();
    placeViewFrame(m_gpuFrame->frame, viewScene(), sunRadiance(m_scene.sun), w, h, spps[pass]);
    m_gpuPlacedAt = m_scene.camera.position;
    const uint32_t skyLights = rs.frame.sky.lightCount;
    if (refine.frames > 0 && !last) rs.frame.sky.lightCount = 0;   // moving: the sun alone
    m_gpuFrame->device->place(rs);
    rs.frame.sky.lightCount = skyLights;
    // The last pass is also kept on the host (lastImage(), tests, export of what is shown).
    QImage picture;
    if (last) picture = QImage(w, h, QImage::Format_RGBX8888);
    m_interop->render(*m_gpuFrame->device, m_scene.render.mode, m_scene.render.exposureKey, m_compare,
                      last ? reinterpret_cast<uint32_t*>(picture.bits()) : nullptr);
    glBindBuffer(GL_PIXEL_UNPACK_BUFFER, m_pbo);
    m_texture->bind(0);
    glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
    glTexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, w, h, GL_RGBA, GL_UNSIGNED_BYTE, nullptr);
    m_texture->release();
    glBindBuffer(GL_PIXEL_UNPACK_BUFFER, 0);
    m_imageDirty = false;

    const double seconds = m_sinceRequest.isValid() ? double(m_sinceRequest.nsecsElapsed()) * 1e-9 : 0.0;
    if (last) m_image = picture;
    m_samplesShown = spps[pass];
    m_sampleTarget = spps.back();
    m_lastPass = int(pass);
    m_lastFinal = last;
    if (m_awaitingFirst) {
        m_firstImageSeconds = seconds;
        m_awaitingFirst = false;
    }
    if (!last) {
        ++m_gpuPass;
        update();   // the next pass, unless something changes first (requestRender restarts at pass 0)
    }
    Q_EMIT imageShown(int(pass), last, seconds);
    return true;
}

void Viewport::mousePressEvent(QMouseEvent* event)
{
    const bool pan = event->button() == Qt::MiddleButton ||
                     (event->button() == Qt::LeftButton && (event->modifiers() & Qt::ShiftModifier));
    // Ctrl + drag on an instance slides it over the ground (selected first).
    if (event->button() == Qt::LeftButton && (event->modifiers() & Qt::ControlModifier) && !pan) {
        const std::optional<ViewPick> hit = pickAt(event->position());
        if (hit && hit->instance >= 0 && size_t(hit->instance) < m_scene.instances.size()) {
            m_drag = Drag::Move;
            m_dragStart = event->position().toPoint();
            m_dragMoved = false;
            m_moveInstance = hit->instance;
            m_moveFrom = m_scene.instances[size_t(hit->instance)];
            m_moveGrab = hit->point;
            // Looking down on the point by 3 degrees or more: its horizontal plane (the point follows the cursor
            // exactly); nearer eye level the horizontal plane runs off toward the horizon, so the vertical plane
            // facing the camera (the point follows the cursor sideways).
            const CameraDesc eye = viewCamera();
            const glm::dvec3 ray = glm::normalize(hit->point - eye.position);
            glm::dvec3 facing(eye.target.x - eye.position.x, 0.0, eye.target.z - eye.position.z);
            if (ray.y < -std::sin(3.0 * 3.14159265358979323846 / 180.0) || !(glm::length(facing) > 0.0)) m_movePlane = glm::dvec3(0.0, 1.0, 0.0);
            else m_movePlane = glm::normalize(facing);
            m_moveKey = SceneDocument::newMergeKey();
            Q_EMIT instancePicked(hit->instance);
            event->accept();
            return;
        }
    }
    if (pan) m_drag = Drag::Pan;
    else if (event->button() == Qt::LeftButton) m_drag = m_fly ? Drag::Look : Drag::Orbit;
    else return;
    m_dragStart = event->position().toPoint();
    m_dragCamera = m_scene.camera;
    m_dragMoved = false;
    m_panDepth = 0.0;
    m_orbitPivot.reset();
    if (m_drag == Drag::Orbit) {
        // Orbit about what is under the cursor (the target without a hit).
        if (const std::optional<ViewPick> hit = pickAt(event->position(), kNavigationPickMs); hit && hit->kind != SurfaceKind::None)
            m_orbitPivot = hit->point;
    }
    if (pan) {
        // Grab what is under the cursor: it follows the cursor at its own depth (the target's without a hit).
        if (const std::optional<ViewPick> hit = pickAt(event->position(), kNavigationPickMs); hit && hit->kind != SurfaceKind::None) {
            const glm::dvec3 view = m_scene.camera.target - m_scene.camera.position;
            if (glm::length(view) > 0.0) m_panDepth = glm::dot(hit->point - m_scene.camera.position, glm::normalize(view));
        }
    }
    event->accept();
}

void Viewport::mouseMoveEvent(QMouseEvent* event)
{
    if (m_drag == Drag::None) return;
    const QPoint d = event->position().toPoint() - m_dragStart;
    // A press is a click until the cursor has moved the platform's drag distance: a click changes no camera.
    if (!m_dragMoved && d.manhattanLength() < QApplication::startDragDistance()) return;
    m_dragMoved = true;
    if (m_drag == Drag::Move) {
        // The grabbed point follows the cursor over the horizontal plane through it (m_movePlane; seen at eye
        // level or above, the camera-facing vertical plane through it, its height change dropped): the instance
        // keeps its height (on the ground plane, or its height above the terrain), only x and z change.
        glm::dvec3 p;
        if (viewRayOnPlane(viewCamera(), width(), height(), glm::dvec2(event->position().x(), event->position().y()), m_moveGrab,
                           m_movePlane, &p)) {
            InstanceDesc moved = m_moveFrom;
            moved.position.x += p.x - m_moveGrab.x;
            moved.position.z += p.z - m_moveGrab.z;
            Q_EMIT instanceEdited(m_moveInstance, moved, tr("Move instance"), m_moveKey);
        }
        event->accept();
        return;
    }
    CameraDesc c;
    switch (m_drag) {
    case Drag::Orbit:
        c = m_orbitPivot ? orbitCameraAbout(m_dragCamera, -0.4 * d.x(), 0.4 * d.y(), *m_orbitPivot)
                         : orbitCamera(m_dragCamera, -0.4 * d.x(), 0.4 * d.y());
        break;
    case Drag::Look: c = flyLook(m_dragCamera, 0.3 * d.x(), -0.3 * d.y()); break;
    default: {
        // At the viewport's field of view (the grabbed point follows the cursor); the scene's is kept.
        CameraDesc seen = m_dragCamera;
        seen.fovY = viewCamera().fovY;
        c = panCamera(seen, d.x(), d.y(), height(), m_panDepth);
        c.fovY = m_dragCamera.fovY;
        break;
    }
    }
    Q_EMIT navigated(c);
    event->accept();
}

void Viewport::mouseReleaseEvent(QMouseEvent* event)
{
    if (m_drag == Drag::None) return;
    mouseMoveEvent(event);
    const Drag drag = m_drag;
    m_drag = Drag::None;
    if (m_dragMoved || drag == Drag::Pan || drag == Drag::Move || event->button() != Qt::LeftButton) return;
    // A click: select what is under the cursor (nothing: clear the selection).
    const std::optional<ViewPick> hit = pickAt(event->position());
    if (!hit) return;   // no frame yet to pick in
    Q_EMIT instancePicked(hit->instance);
}

void Viewport::wheelEvent(QWheelEvent* event)
{
    // Some platforms turn a wheel held with Shift into a horizontal one.
    const QPoint angle = event->angleDelta();
    const double steps = (angle.y() != 0 ? angle.y() : angle.x()) / 120.0;
    if (steps == 0.0) return;
    if ((event->modifiers() & Qt::ControlModifier) && m_selected >= 0 && size_t(m_selected) < m_scene.instances.size()) {
        // Ctrl + wheel turns the selected instance about the up axis (15 degrees a notch), Ctrl + Shift + wheel
        // scales it (10% a notch); the turns of one burst (less than half a second apart) are one undo step.
        const bool scale = (event->modifiers() & Qt::ShiftModifier) != 0;
        const qint64 now = QDateTime::currentMSecsSinceEpoch();
        if (m_wheelEditKey == 0 || m_wheelEditScale != scale || now - m_lastWheelEditMs > 500)
            m_wheelEditKey = SceneDocument::newMergeKey();
        m_wheelEditScale = scale;
        m_lastWheelEditMs = now;
        InstanceDesc in = m_scene.instances[size_t(m_selected)];
        if (scale) {
            const json::Bounds range = sceneFieldRange("instances[i].scale");
            in.scale = float(std::clamp(double(in.scale) * std::pow(1.1, steps), std::max(range.lo, 1e-3), std::min(range.hi, 1e3)));
        } else {
            in.rotationDeg.y = float(std::fmod(double(in.rotationDeg.y) + 15.0 * steps + 360.0 * 8.0, 360.0));
        }
        Q_EMIT instanceEdited(m_selected, in, scale ? tr("Scale instance") : tr("Rotate instance"), m_wheelEditKey);
        event->accept();
        return;
    }
    // Toward what is under the cursor (its distance sets the step), else toward the target.
    const std::optional<ViewPick> hit = pickAt(event->position(), kNavigationPickMs);
    const CameraDesc c = hit && hit->kind != SurfaceKind::None ? zoomCameraAbout(m_scene.camera, steps, hit->point)
                                                              : zoomCamera(m_scene.camera, steps);
    Q_EMIT navigated(c);
    event->accept();
}

std::optional<ViewPick> Viewport::pickAt(QPointF pos, int waitMs) const
{
    const QSize size = renderSize();
    const QPointF pixel(pos.x() * double(size.width()) / double(std::max(1, width())),
                        pos.y() * double(size.height()) / double(std::max(1, height())));
    if (m_interop && m_gpuFrame) {
        try {
            return pickViewFrame(m_gpuFrame->frame, m_gpuPlacedAt, viewCamera(), size.width(), size.height(), pixel.x(), pixel.y());
        } catch (const std::exception&) {
            return std::nullopt;
        }
    }
    return m_worker->pick(viewCamera(), size, pixel, waitMs);
}

void Viewport::setSelectedInstance(int instance)
{
    if (m_selected == instance) return;
    m_selected = instance;
    update();   // the overlay only: the picture is not traced again
}

Bounds3 Viewport::selectionBounds() const
{
    if (m_selected < 0 || size_t(m_selected) >= m_scene.instances.size()) return {};
    const InstanceDesc& in = m_scene.instances[size_t(m_selected)];
    if (in.group != kNoGroup || in.species >= m_speciesBoxes.size() || !m_speciesBoxes[in.species].valid()) return {};
    return instanceBounds(m_scene, in, m_speciesBoxes[in.species]);
}

QRectF Viewport::selectionRect() const
{
    const Bounds3 b = selectionBounds();
    if (!b.valid()) return {};
    double x0 = 1e300, y0 = 1e300, x1 = -1e300, y1 = -1e300;
    for (int k = 0; k < 8; ++k) {
        glm::dvec2 px;
        const glm::dvec3 corner((k & 1) ? b.hi.x : b.lo.x, (k & 2) ? b.hi.y : b.lo.y, (k & 4) ? b.hi.z : b.lo.z);
        if (!projectToView(viewCamera(), width(), height(), corner, &px)) return {};
        x0 = std::min(x0, px.x);
        y0 = std::min(y0, px.y);
        x1 = std::max(x1, px.x);
        y1 = std::max(y1, px.y);
    }
    return QRectF(QPointF(x0, y0), QPointF(x1, y1));
}

void Viewport::drawSelection()
{
    const Bounds3 b = selectionBounds();
    if (!b.valid()) return;
    // The box's twelve edges, each drawn when both its ends are in front of the eye.
    glm::dvec2 px[8];
    bool front[8];
    for (int k = 0; k < 8; ++k) {
        const glm::dvec3 corner((k & 1) ? b.hi.x : b.lo.x, (k & 2) ? b.hi.y : b.lo.y, (k & 4) ? b.hi.z : b.lo.z);
        front[k] = projectToView(viewCamera(), width(), height(), corner, &px[k]);
    }
    QPainter p(this);
    p.setRenderHint(QPainter::Antialiasing, false);
    p.setPen(QPen(QColor(255, 160, 32), 2.0));   // Blender's selection orange
    for (int k = 0; k < 8; ++k)
        for (int bit = 1; bit < 8; bit <<= 1) {
            const int j = k | bit;
            if (j == k || !front[k] || !front[j]) continue;
            p.drawLine(QPointF(px[k].x, px[k].y), QPointF(px[j].x, px[j].y));
        }
}

bool Viewport::frameBox(const Bounds3& box)
{
    if (!box.valid()) return false;
    // Into the render's frame when it is shown (what is exported is framed), else the viewport.
    const double aspect = m_cameraFrame ? double(std::max(1, m_scene.render.width)) / double(std::max(1, m_scene.render.height))
                                        : double(std::max(1, width())) / double(std::max(1, height()));
    const CameraDesc c = frameBoxCamera(m_scene.camera, box, aspect);
    Q_EMIT navigated(c);
    return true;
}

void Viewport::setCameraFrame(bool on)
{
    if (m_cameraFrame == on) return;
    m_cameraFrame = on;
    requestRender();   // the field of view may change
    update();
}

CameraDesc Viewport::viewCamera() const
{
    CameraDesc c = m_scene.camera;
    if (!m_cameraFrame || width() <= 0 || height() <= 0 || m_scene.render.width <= 0 || m_scene.render.height <= 0) return c;
    const double render = double(m_scene.render.width) / double(m_scene.render.height);
    const double view = double(width()) / double(height());
    if (render <= view) return c;
    constexpr double kDegToRad = 3.14159265358979323846 / 180.0;
    const double tanY = std::tan(double(c.fovY) * 0.5 * kDegToRad) * render / view;
    c.fovY = float(2.0 * std::atan(tanY) / kDegToRad);
    return c;
}

Scene Viewport::viewScene() const
{
    Scene s = m_scene;
    s.camera = viewCamera();
    return s;
}

QRectF Viewport::cameraFrameRect() const
{
    if (!m_cameraFrame || m_scene.render.width <= 0 || m_scene.render.height <= 0 || width() <= 0 || height() <= 0) return {};
    const double render = double(m_scene.render.width) / double(m_scene.render.height);
    const double w = width(), h = height();
    if (render <= w / h) return QRectF(0.5 * (w - h * render), 0.0, h * render, h);   // the full height
    return QRectF(0.0, 0.5 * (h - w / render), w, w / render);                        // the full width
}

void Viewport::drawCameraFrame()
{
    const QRectF frame = cameraFrameRect();
    if (frame.isEmpty()) return;
    QPainter p(this);
    const QColor shade(0, 0, 0, 120);
    const QRectF all(rect());
    p.fillRect(QRectF(all.left(), all.top(), all.width(), frame.top() - all.top()), shade);
    p.fillRect(QRectF(all.left(), frame.bottom(), all.width(), all.bottom() + 1.0 - frame.bottom()), shade);
    p.fillRect(QRectF(all.left(), frame.top(), frame.left() - all.left(), frame.height()), shade);
    p.fillRect(QRectF(frame.right(), frame.top(), all.right() + 1.0 - frame.right(), frame.height()), shade);
    p.setPen(QPen(QColor(255, 255, 255, 140), 1.0));
    p.drawRect(frame.adjusted(0.5, 0.5, -0.5, -0.5));
}

bool Viewport::frameAll() { return frameBox(sceneBounds(m_scene, m_speciesBoxes)); }

bool Viewport::frameSelected()
{
    if (m_selected < 0 || size_t(m_selected) >= m_scene.instances.size()) return false;
    Bounds3 b = selectionBounds();
    if (!b.valid()) {
        // The species is not loaded yet: its position, a metre around it.
        const InstanceDesc& in = m_scene.instances[size_t(m_selected)];
        b = instanceBounds(m_scene, in, Bounds3{});
        b.lo -= glm::vec3(1.0f);
        b.hi += glm::vec3(1.0f);
    }
    return frameBox(b);
}

} // namespace sylva

namespace sylva {

void Viewport::setFlyMode(bool on)
{
    if (m_fly == on) return;
    m_fly = on;
    Q_EMIT flyModeChanged(on);
}

void Viewport::setCompare(std::optional<RenderMode> mode)
{
    if (m_compare == mode) return;
    m_compare = mode;
    requestRender();
}

double Viewport::flyStep() const { return flyStepFor(m_scene, m_speciesBoxes); }

void Viewport::keyPressEvent(QKeyEvent* event)
{
    const Qt::KeyboardModifiers mods = event->modifiers() & ~(Qt::KeypadModifier | Qt::ShiftModifier);
    if (event->key() == Qt::Key_F && mods == Qt::NoModifier && !event->isAutoRepeat()) {
        setFlyMode(!m_fly);
        event->accept();
        return;
    }
    double right = 0.0, up = 0.0, forward = 0.0;
    switch (event->key()) {
    case Qt::Key_W: forward = 1.0; break;
    case Qt::Key_S: forward = -1.0; break;
    case Qt::Key_D: right = 1.0; break;
    case Qt::Key_A: right = -1.0; break;
    case Qt::Key_E: up = 1.0; break;
    case Qt::Key_Q: up = -1.0; break;
    default: break;
    }
    if (!m_fly || mods != Qt::NoModifier || (right == 0.0 && up == 0.0 && forward == 0.0)) {
        QOpenGLWidget::keyPressEvent(event);
        return;
    }
    const double step = flyStep() * ((event->modifiers() & Qt::ShiftModifier) ? 5.0 : 1.0);
    Q_EMIT navigated(flyMove(m_scene.camera, right * step, up * step, forward * step));
    event->accept();
}

} // namespace sylva
