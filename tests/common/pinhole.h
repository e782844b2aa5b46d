// A pinhole camera (square pixels) computed from its definition alone, for tests that check the renderer's rays
// and the studio's navigation against their own: the direction through an image position and where a world
// point lands.
#pragma once

#include <cmath>

#include <glm/glm.hpp>

#include "core/scene/scene.h"

namespace sylva::test {

// Unit direction through image position (x, y) in pixels (y down; pixel centres at + 0.5).
inline glm::dvec3 pinholeDirection(const Scene& s, double x, double y)
{
    const glm::dvec3 f = glm::normalize(s.camera.target - s.camera.position);
    const glm::dvec3 right = glm::normalize(glm::cross(f, glm::dvec3(s.camera.up)));
    const glm::dvec3 up = glm::cross(right, f);
    const double ty = std::tan(double(s.camera.fovY) * 3.14159265358979323846 / 360.0), tx = ty * s.render.width / s.render.height;
    return glm::normalize(f + (2.0 * x / s.render.width - 1.0) * tx * right + (1.0 - 2.0 * y / s.render.height) * ty * up);
}

// Where world point p lands in a w x h picture of camera c (pixels, y down).
inline glm::dvec2 pinholeProject(const CameraDesc& c, double w, double h, const glm::dvec3& p)
{
    const glm::dvec3 f = glm::normalize(c.target - c.position);
    const glm::dvec3 r = glm::normalize(glm::cross(f, glm::dvec3(c.up)));
    const glm::dvec3 u = glm::cross(r, f);
    const glm::dvec3 q = p - c.position;
    const double z = glm::dot(q, f);
    const double tanY = std::tan(double(c.fovY) * 3.14159265358979323846 / 360.0), tanX = tanY * w / h;
    return {(glm::dot(q, r) / (z * tanX) + 1.0) * 0.5 * w, (1.0 - glm::dot(q, u) / (z * tanY)) * 0.5 * h};
}

} // namespace sylva::test
