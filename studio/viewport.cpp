// Viewport: film texture on a quad, overlay text, mouse navigation feeding undoable camera edits.
#include "studio/viewport.h"

#include <QDateTime>
#include <QKeyEvent>
#include <QMouseEvent>
#include <QOpenGLContext>
#include <QOpenGLShaderProgram>
#include <QOpenGLTexture>
#include <QPainter>
#include <QWheelEvent>

#include "studio/camera_nav.h"
#include "studio/render_worker.h"
#include "studio/scene_document.h"

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

} // namespace

Viewport::Viewport(QWidget* parent) : QOpenGLWidget(parent), m_worker(new RenderWorker(this)), m_quad(QOpenGLBuffer::VertexBuffer)
{
    setFocusPolicy(Qt::StrongFocus);
    setMinimumSize(160, 90);
    connect(m_worker, &RenderWorker::imageReady, this, &Viewport::onImage);
    connect(m_worker, &RenderWorker::failed, this, [this](const QString& message) {
        setStatus(message);
        Q_EMIT renderFailed(message);
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

void Viewport::setScene(const Scene& scene, std::vector<AssetsPtr> assets)
{
    m_scene = scene;
    m_assets = std::move(assets);
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
    if (m_assets.empty() || m_assets.size() != m_scene.species.size() || m_scene.instances.empty()) {
        m_worker->clear();
        if (m_scene.instances.empty()) setStatus(tr("Empty scene: import a mesh or grow a species"));
        return;
    }
    setStatus(QString());
    m_awaitingFirst = true;
    m_worker->request(m_scene, m_assets, renderSize(), m_compare);
}

void Viewport::onImage(const QImage& image, int pass, bool last, double seconds)
{
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
}

void Viewport::cleanupGL()
{
    if (!m_program && !m_texture && !m_quad.isCreated()) return;
    makeCurrent();
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
    if (m_imageDirty && !m_image.isNull()) {
        delete m_texture;
        m_texture = new QOpenGLTexture(m_image, QOpenGLTexture::DontGenerateMipMaps);
        m_texture->setMinificationFilter(QOpenGLTexture::Linear);
        m_texture->setMagnificationFilter(QOpenGLTexture::Linear);
        m_texture->setWrapMode(QOpenGLTexture::ClampToEdge);
        m_imageDirty = false;
    }
    if (m_texture && m_program && m_program->isLinked()) {
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
    if (m_compare && m_texture && !m_image.isNull()) {
        // The split the worker made (column width / 2 of the picture), and which mode is where.
        QPainter p(this);
        const int x = int(double(width()) * double(m_image.width() / 2) / double(m_image.width()));
        p.setPen(QColor(255, 255, 255, 200));
        p.drawLine(x, 0, x, height());
        p.drawText(QRect(8, 8, x - 16, 20), Qt::AlignLeft | Qt::AlignTop, QString::fromLatin1(renderModeName(m_scene.render.mode)));
        p.drawText(QRect(x + 8, 8, width() - x - 16, 20), Qt::AlignLeft | Qt::AlignTop, QString::fromLatin1(renderModeName(*m_compare)));
    }
    if (!m_status.isEmpty()) {
        QPainter p(this);
        p.setPen(QColor(230, 230, 230));
        p.drawText(rect().adjusted(12, 12, -12, -12), Qt::AlignLeft | Qt::AlignTop | Qt::TextWordWrap, m_status);
    }
}

void Viewport::mousePressEvent(QMouseEvent* event)
{
    const bool pan = event->button() == Qt::MiddleButton ||
                     (event->button() == Qt::LeftButton && (event->modifiers() & Qt::ShiftModifier));
    if (pan) m_drag = Drag::Pan;
    else if (event->button() == Qt::LeftButton) m_drag = m_fly ? Drag::Look : Drag::Orbit;
    else return;
    m_dragStart = event->position().toPoint();
    m_dragCamera = m_scene.camera;
    m_dragKey = SceneDocument::newMergeKey();
    event->accept();
}

void Viewport::mouseMoveEvent(QMouseEvent* event)
{
    if (m_drag == Drag::None) return;
    const QPoint d = event->position().toPoint() - m_dragStart;
    CameraDesc c;
    switch (m_drag) {
    case Drag::Orbit: c = orbitCamera(m_dragCamera, -0.4 * d.x(), 0.4 * d.y()); break;
    case Drag::Look: c = flyLook(m_dragCamera, 0.3 * d.x(), -0.3 * d.y()); break;
    default: c = panCamera(m_dragCamera, d.x(), d.y(), height()); break;
    }
    Q_EMIT cameraEdited(c, m_dragKey);
    event->accept();
}

void Viewport::mouseReleaseEvent(QMouseEvent* event)
{
    if (m_drag == Drag::None) return;
    mouseMoveEvent(event);
    m_drag = Drag::None;
}

void Viewport::wheelEvent(QWheelEvent* event)
{
    const double steps = event->angleDelta().y() / 120.0;
    if (steps == 0.0) return;
    // Wheel turns less than half a second apart are one undo step.
    const qint64 now = QDateTime::currentMSecsSinceEpoch();
    if (m_wheelKey == 0 || now - m_lastWheelMs > 500) m_wheelKey = SceneDocument::newMergeKey();
    m_lastWheelMs = now;
    Q_EMIT cameraEdited(zoomCamera(m_scene.camera, steps), m_wheelKey);
    event->accept();
}

} // namespace sylva

namespace sylva {

void Viewport::setFlyMode(bool on)
{
    if (m_fly == on) return;
    m_fly = on;
    m_flyKey = 0;
    Q_EMIT flyModeChanged(on);
}

void Viewport::setCompare(std::optional<RenderMode> mode)
{
    if (m_compare == mode) return;
    m_compare = mode;
    requestRender();
}

double Viewport::flyStep() const { return std::max(0.05, 0.05 * glm::length(m_scene.camera.target - m_scene.camera.position)); }

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
    // Presses (and auto-repeats) less than half a second apart are one undo step.
    const qint64 now = QDateTime::currentMSecsSinceEpoch();
    if (m_flyKey == 0 || now - m_lastFlyMs > 500) m_flyKey = SceneDocument::newMergeKey();
    m_lastFlyMs = now;
    Q_EMIT cameraEdited(flyMove(m_scene.camera, right * step, up * step, forward * step), m_flyKey);
    event->accept();
}

} // namespace sylva
