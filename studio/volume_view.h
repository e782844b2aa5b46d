// The inspector's 3D view: a species' density grid as a 3D texture, ray marched in a fragment shader
// with single scattering of the sun (as in the graphics-blog post "In-Scattering Demo": march the view ray
// through the volume, at each sample march toward the light for its transmittance), or lit by the LB lighting
// grid instead.
#pragma once

#include <memory>
#include <optional>

#include <QOpenGLBuffer>
#include <QOpenGLFunctions>
#include <QOpenGLWidget>
#include <QPoint>

#include "pipeline/render/render_job.h"

class QOpenGLShaderProgram;
class QOpenGLTexture;

namespace sylva {

class VolumeView : public QOpenGLWidget, protected QOpenGLFunctions {
    Q_OBJECT

public:
    enum class Lighting { SingleScattering, Lb };

    explicit VolumeView(QWidget* parent = nullptr);
    ~VolumeView() override;

    // What to draw (null: nothing, background only). Kept while shown.
    void setGrids(std::shared_ptr<const SpeciesGrids> grids);
    // SingleScattering: the sun (grids->params.sun, the direction the grid was solved for) through
    // the density; Lb: each sample lit by the LB grid's luminance (normalized to its maximum).
    void setLighting(Lighting lighting);
    Lighting lighting() const { return m_lighting; }
    // Extinction of density 1 per grid length (the longest edge): how opaque the foliage looks.
    void setExtinction(float perGridLength);
    // Direction toward the light for single scattering, grid frame; default: the grids' sun.
    void setSunDirection(const glm::vec3& direction);
    // Orbit camera about the grid's centre (degrees); drags and the wheel change it.
    void setView(float yawDeg, float pitchDeg, float distance);

    // Why nothing can be drawn (no 3D textures in this GL), else empty.
    QString problem() const { return m_problem; }
    static QColor background() { return QColor(28, 30, 36); }
    QSize sizeHint() const override { return {360, 360}; }

protected:
    void initializeGL() override;
    void paintGL() override;
    void mousePressEvent(QMouseEvent* event) override;
    void mouseMoveEvent(QMouseEvent* event) override;
    void wheelEvent(QWheelEvent* event) override;

private:
    void cleanupGL();
    void uploadTextures();

    std::shared_ptr<const SpeciesGrids> m_grids;
    bool m_dirty = false;
    Lighting m_lighting = Lighting::SingleScattering;
    float m_extinction = 12.0f;
    std::optional<glm::vec3> m_sun;
    float m_yaw = 35.0f, m_pitch = 20.0f, m_distance = 2.6f;
    QPoint m_lastMouse;
    QString m_problem;

    QOpenGLShaderProgram* m_program = nullptr;
    QOpenGLTexture* m_density = nullptr;
    QOpenGLTexture* m_light = nullptr;
    QOpenGLBuffer m_quad;
};

} // namespace sylva
