// The direction through an image position of a scene's pinhole camera (square pixels), computed from the
// camera's definition for tests that check the renderer's rays against their own.
#pragma once

#include <cmath>

#include <glm/glm.hpp>

#include "core/scene/scene.h"

namespace sylva::test {

// Unit direction through image position (x, y) in pixels (y down; pixel centres at + 0.5), the camera's up +Y.
inline glm::dvec3 pinholeDirection(const Scene& s, double x, double y)
{
    const glm::dvec3 f = glm::normalize(s.camera.target - s.camera.position);
    const glm::dvec3 right = glm::normalize(glm::cross(f, glm::dvec3(0.0, 1.0, 0.0)));
    const glm::dvec3 up = glm::cross(right, f);
    const double ty = std::tan(double(s.camera.fovY) * 3.14159265358979323846 / 360.0), tx = ty * s.render.width / s.render.height;
    return glm::normalize(f + (2.0 * x / s.render.width - 1.0) * tx * right + (1.0 - 2.0 * y / s.render.height) * ty * up);
}

} // namespace sylva::test
