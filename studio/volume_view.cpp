// VolumeView: 3D textures of density and LB luminance, a full-window quad, the ray marcher.
#include "studio/volume_view.h"

#include <algorithm>
#include <cmath>

#include <QMatrix4x4>
#include <QMouseEvent>
#include <QOpenGLContext>
#include <QOpenGLPixelTransferOptions>
#include <QOpenGLShaderProgram>
#include <QOpenGLTexture>
#include <QPainter>
#include <QWheelEvent>
#include <QtMath>

namespace sylva {
namespace {

const char* kVertexShader = R"(
attribute vec2 position;
varying vec2 ndc;
void main() { ndc = position; gl_Position = vec4(position, 0.0, 1.0); }
)";

// Box space: the grid spans [0, extent] (extent = dims / longest dim); texture coordinates p / extent.
// View ray: N samples between the box faces; at each, extinction sigma * density, in-scattered light
// (single scattering, isotropic, albedo 1) from the sun's transmittance (a march of M samples toward
// it, as in the graphics-blog post "In-Scattering Demo") or from the LB grid's luminance.
const char* kFragmentShader = R"(
uniform sampler3D density;
uniform sampler3D lighting;
uniform mat4 invViewProj;
uniform vec3 eye;
uniform vec3 extent;
uniform vec3 sunDir;
uniform float sigma;
uniform float lbMode;
uniform vec3 background;
varying vec2 ndc;
void main()
{
    vec4 farPoint = invViewProj * vec4(ndc, 1.0, 1.0);
    vec3 dir = normalize(farPoint.xyz / farPoint.w - eye);
    vec3 safe = vec3(abs(dir.x) < 1e-6 ? 1e-6 : dir.x, abs(dir.y) < 1e-6 ? 1e-6 : dir.y, abs(dir.z) < 1e-6 ? 1e-6 : dir.z);
    vec3 t0 = (vec3(0.0) - eye) / safe;
    vec3 t1 = (extent - eye) / safe;
    vec3 tmin = min(t0, t1);
    vec3 tmax = max(t0, t1);
    float tn = max(max(tmin.x, tmin.y), max(tmin.z, 0.0));
    float tf = min(min(tmax.x, tmax.y), tmax.z);
    vec3 colour = background;
    if (tf > tn) {
        const int N = 128;
        const int M = 32;
        float dt = (tf - tn) / float(N);
        float ds = length(extent) / float(M);
        float T = 1.0;
        vec3 L = vec3(0.0);
        for (int i = 0; i < N; ++i) {
            vec3 p = eye + dir * (tn + (float(i) + 0.5) * dt);
            float d = texture3D(density, p / extent).r;
            if (d > 0.0) {
                float a = sigma * d * dt;
                vec3 Li;
                if (lbMode > 0.5) {
                    Li = vec3(texture3D(lighting, p / extent).r);
                } else {
                    float Tl = 1.0;
                    for (int s = 1; s <= M; ++s) {
                        vec3 q = p + sunDir * (ds * float(s));
                        if (any(lessThan(q, vec3(0.0))) || any(greaterThan(q, extent))) break;
                        Tl *= exp(-sigma * ds * texture3D(density, q / extent).r);
                        if (Tl < 0.01) break;
                    }
                    Li = vec3(Tl);
                }
                L += Li * T * (1.0 - exp(-a));
                T *= exp(-a);
                if (T < 0.01) break;
            }
        }
        colour = L + T * background;
    }
    gl_FragColor = vec4(colour, 1.0);
}
)";

} // namespace

VolumeView::VolumeView(QWidget* parent) : QOpenGLWidget(parent), m_quad(QOpenGLBuffer::VertexBuffer)
{
    setObjectName("volumeView");
    setMinimumSize(120, 120);
}

VolumeView::~VolumeView()
{
    if (context()) disconnect(context(), &QOpenGLContext::aboutToBeDestroyed, this, &VolumeView::cleanupGL);
    makeCurrent();
    cleanupGL();
    doneCurrent();
}

void VolumeView::setGrids(std::shared_ptr<const SpeciesGrids> grids)
{
    m_grids = std::move(grids);
    m_dirty = true;
    update();
}

void VolumeView::setLighting(Lighting lighting)
{
    m_lighting = lighting;
    update();
}

void VolumeView::setExtinction(float perGridLength)
{
    m_extinction = std::max(0.0f, perGridLength);
    update();
}

void VolumeView::setSunDirection(const glm::vec3& direction)
{
    m_sun = direction;
    update();
}

void VolumeView::setView(float yawDeg, float pitchDeg, float distance)
{
    m_yaw = yawDeg;
    m_pitch = std::clamp(pitchDeg, -89.0f, 89.0f);
    m_distance = std::clamp(distance, 0.3f, 20.0f);
    update();
}

void VolumeView::initializeGL()
{
    connect(context(), &QOpenGLContext::aboutToBeDestroyed, this, &VolumeView::cleanupGL, Qt::UniqueConnection);
    initializeOpenGLFunctions();
    const QSurfaceFormat f = context()->format();
    if (context()->isOpenGLES() ? f.majorVersion() < 3 : f.version() < qMakePair(1, 2))
        m_problem = tr("This OpenGL (%1.%2) has no 3D textures.").arg(f.majorVersion()).arg(f.minorVersion());
    m_program = new QOpenGLShaderProgram;
    m_program->addShaderFromSourceCode(QOpenGLShader::Vertex, kVertexShader);
    m_program->addShaderFromSourceCode(QOpenGLShader::Fragment, kFragmentShader);
    m_program->bindAttributeLocation("position", 0);
    if (!m_program->link()) {
        m_problem = tr("The volume shader did not build: %1").arg(m_program->log());
        qWarning("volume shader: %s", qPrintable(m_program->log()));
    }
    const GLfloat quad[] = {-1, -1, 1, -1, -1, 1, 1, 1};
    m_quad.create();
    m_quad.bind();
    m_quad.allocate(quad, sizeof quad);
    m_quad.release();
    m_dirty = true;
}

void VolumeView::cleanupGL()
{
    if (!m_program && !m_density && !m_quad.isCreated()) return;
    makeCurrent();
    delete m_density;
    m_density = nullptr;
    delete m_light;
    m_light = nullptr;
    delete m_program;
    m_program = nullptr;
    m_quad.destroy();
    doneCurrent();
}

void VolumeView::uploadTextures()
{
    delete m_density;
    m_density = nullptr;
    delete m_light;
    m_light = nullptr;
    if (!m_grids || m_grids->density.density.empty()) return;
    const GridGeometry& g = m_grids->density.geometry;
    const size_t n = g.nodeCount();
    // Texture order: x fastest; the grids: z fastest.
    auto texel = [&](int i, int j, int k) { return (size_t(k) * size_t(g.dims.y) + size_t(j)) * size_t(g.dims.x) + size_t(i); };
    std::vector<uint8_t> rho(n), lum(n, 0);
    float maxLum = 0.0f;
    const bool lit = m_grids->lighting.rgb.size() == n * 3;
    if (lit)
        for (size_t v = 0; v < n; ++v) {
            const float* c = &m_grids->lighting.rgb[v * 3];
            maxLum = std::max(maxLum, 0.2126f * c[0] + 0.7152f * c[1] + 0.0722f * c[2]);
        }
    for (int i = 0; i < g.dims.x; ++i)
        for (int j = 0; j < g.dims.y; ++j)
            for (int k = 0; k < g.dims.z; ++k) {
                const size_t v = g.index(i, j, k);
                rho[texel(i, j, k)] = uint8_t(std::lround(std::clamp(m_grids->density.density[v], 0.0f, 1.0f) * 255.0f));
                if (lit && maxLum > 0.0f) {
                    const float* c = &m_grids->lighting.rgb[v * 3];
                    const float l = (0.2126f * c[0] + 0.7152f * c[1] + 0.0722f * c[2]) / maxLum;
                    lum[texel(i, j, k)] = uint8_t(std::lround(std::clamp(l, 0.0f, 1.0f) * 255.0f));
                }
            }
    QOpenGLPixelTransferOptions packing;
    packing.setAlignment(1);
    auto make = [&](const std::vector<uint8_t>& bytes) {
        auto* t = new QOpenGLTexture(QOpenGLTexture::Target3D);
        t->setSize(g.dims.x, g.dims.y, g.dims.z);
        t->setFormat(QOpenGLTexture::R8_UNorm);
        t->setMipLevels(1);
        t->allocateStorage(QOpenGLTexture::Red, QOpenGLTexture::UInt8);
        t->setData(QOpenGLTexture::Red, QOpenGLTexture::UInt8, bytes.data(), &packing);
        t->setMinificationFilter(QOpenGLTexture::Linear);
        t->setMagnificationFilter(QOpenGLTexture::Linear);
        t->setWrapMode(QOpenGLTexture::ClampToEdge);
        return t;
    };
    m_density = make(rho);
    m_light = make(lum);
}

void VolumeView::paintGL()
{
    const QColor bg = background();
    glClearColor(bg.redF(), bg.greenF(), bg.blueF(), 1.0f);
    glClear(GL_COLOR_BUFFER_BIT);
    if (m_dirty) {
        uploadTextures();
        m_dirty = false;
    }
    if (!m_problem.isEmpty() || !m_density || !m_program || !m_program->isLinked()) {
        if (!m_problem.isEmpty()) {
            QPainter p(this);
            p.setPen(QColor(230, 230, 230));
            p.drawText(rect().adjusted(10, 10, -10, -10), Qt::AlignLeft | Qt::AlignTop | Qt::TextWordWrap, m_problem);
        }
        return;
    }
    const GridGeometry& g = m_grids->density.geometry;
    const glm::vec3 ext = glm::vec3(g.dims) / float(g.longestEdge());
    const QVector3D extent(ext.x, ext.y, ext.z);
    const QVector3D centre = extent * 0.5f;
    const float yaw = qDegreesToRadians(m_yaw), pitch = qDegreesToRadians(m_pitch);
    const QVector3D eye = centre + m_distance * QVector3D(std::cos(pitch) * std::sin(yaw), std::sin(pitch), std::cos(pitch) * std::cos(yaw));
    QMatrix4x4 proj, view;
    proj.perspective(35.0f, float(std::max(1, width())) / float(std::max(1, height())), 0.01f, 100.0f);
    view.lookAt(eye, centre, QVector3D(0.0f, 1.0f, 0.0f));
    const glm::vec3 sunGrid = glm::normalize(m_sun ? *m_sun : m_grids->params.sun);

    m_program->bind();
    m_program->setUniformValue("density", 0);
    m_program->setUniformValue("lighting", 1);
    m_program->setUniformValue("invViewProj", (proj * view).inverted());
    m_program->setUniformValue("eye", eye);
    m_program->setUniformValue("extent", extent);
    m_program->setUniformValue("sunDir", QVector3D(sunGrid.x, sunGrid.y, sunGrid.z));
    m_program->setUniformValue("sigma", m_extinction);
    m_program->setUniformValue("lbMode", m_lighting == Lighting::Lb ? 1.0f : 0.0f);
    m_program->setUniformValue("background", QVector3D(bg.redF(), bg.greenF(), bg.blueF()));
    m_density->bind(0);
    m_light->bind(1);
    m_quad.bind();
    m_program->enableAttributeArray(0);
    m_program->setAttributeBuffer(0, GL_FLOAT, 0, 2, 2 * sizeof(GLfloat));
    glDrawArrays(GL_TRIANGLE_STRIP, 0, 4);
    m_program->disableAttributeArray(0);
    m_quad.release();
    m_light->release(1);
    m_density->release(0);
    m_program->release();
}

void VolumeView::mousePressEvent(QMouseEvent* event) { m_lastMouse = event->position().toPoint(); }

void VolumeView::mouseMoveEvent(QMouseEvent* event)
{
    if (!(event->buttons() & Qt::LeftButton)) return;
    const QPoint d = event->position().toPoint() - m_lastMouse;
    m_lastMouse = event->position().toPoint();
    setView(m_yaw - 0.4f * float(d.x()), m_pitch + 0.4f * float(d.y()), m_distance);
}

void VolumeView::wheelEvent(QWheelEvent* event)
{
    setView(m_yaw, m_pitch, m_distance * std::pow(0.9f, float(event->angleDelta().y()) / 120.0f));
    event->accept();
}

} // namespace sylva
