// Orbit, pan and zoom on CameraDesc in doubles.
#include "studio/camera_nav.h"

#include <algorithm>
#include <cmath>

#include "core/terrain/height_field.h"

namespace sylva {
namespace {

constexpr double kDegToRad = 3.14159265358979323846 / 180.0;

// v turned by yawDeg about +Y and pitchDeg toward +Y, keeping its length: spherical angles with yaw
// from +Z toward +X and pitch above the horizon, pitch clamped to +-89 degrees. v must not be zero.
glm::dvec3 turned(const glm::dvec3& v, double yawDeg, double pitchDeg)
{
    const double dist = glm::length(v);
    const double yaw = std::atan2(v.x, v.z) + yawDeg * kDegToRad;
    const double pitch = std::clamp(std::asin(std::clamp(v.y / dist, -1.0, 1.0)) + pitchDeg * kDegToRad, -89.0 * kDegToRad, 89.0 * kDegToRad);
    return dist * glm::dvec3(std::cos(pitch) * std::sin(yaw), std::sin(pitch), std::cos(pitch) * std::cos(yaw));
}

} // namespace

CameraDesc orbitCamera(const CameraDesc& camera, double yawDeg, double pitchDeg)
{
    CameraDesc c = camera;
    if (!(glm::length(c.position - c.target) > 0.0)) return c;
    c.position = c.target + turned(c.position - c.target, yawDeg, pitchDeg);
    c.up = glm::vec3(0.0f, 1.0f, 0.0f);
    return c;
}

CameraDesc panCamera(const CameraDesc& camera, double dx, double dy, double viewHeight)
{
    CameraDesc c = camera;
    const glm::dvec3 fwd = c.target - c.position;
    const double dist = glm::length(fwd);
    if (!(dist > 0.0) || !(viewHeight > 0.0)) return c;
    const glm::dvec3 f = fwd / dist;
    glm::dvec3 right = glm::cross(f, glm::dvec3(c.up));
    if (!(glm::length(right) > 1e-9)) return c;
    right = glm::normalize(right);
    const glm::dvec3 up = glm::cross(right, f);
    const double metresPerPixel = 2.0 * dist * std::tan(double(c.fovY) * 0.5 * kDegToRad) / viewHeight;
    const glm::dvec3 move = (-dx * right + dy * up) * metresPerPixel;
    c.position += move;
    c.target += move;
    return c;
}

CameraDesc zoomCamera(const CameraDesc& camera, double steps, double factor)
{
    CameraDesc c = camera;
    const glm::dvec3 offset = c.position - c.target;
    const double dist = glm::length(offset);
    if (!(dist > 0.0)) return c;
    const double next = std::max(0.01, dist * std::pow(factor, steps));
    c.position = c.target + offset * (next / dist);
    return c;
}

CameraDesc flyLook(const CameraDesc& camera, double yawDeg, double pitchDeg)
{
    // The camera's right is cross(view, up), i.e. toward decreasing yaw.
    CameraDesc c = camera;
    if (!(glm::length(c.target - c.position) > 0.0)) return c;
    c.target = c.position + turned(c.target - c.position, -yawDeg, pitchDeg);
    c.up = glm::vec3(0.0f, 1.0f, 0.0f);
    return c;
}

CameraDesc flyMove(const CameraDesc& camera, double right, double up, double forward)
{
    CameraDesc c = camera;
    const glm::dvec3 view = c.target - c.position;
    const double dist = glm::length(view);
    if (!(dist > 0.0)) return c;
    const glm::dvec3 f = view / dist;
    glm::dvec3 r = glm::cross(f, glm::dvec3(0.0, 1.0, 0.0));
    // Looking straight up or down: the right axis from the camera's own up vector.
    if (!(glm::length(r) > 1e-9)) r = glm::cross(f, glm::dvec3(c.up));
    if (!(glm::length(r) > 1e-9)) return c;
    r = glm::normalize(r);
    const glm::dvec3 move = right * r + up * glm::dvec3(0.0, 1.0, 0.0) + forward * f;
    c.position += move;
    c.target += move;
    return c;
}

double flyStepFor(const Scene& scene)
{
    const TerrainDesc& t = scene.terrain;
    if (t.enabled() && t.field) {
        const HeightFieldLayout& L = t.field->layout;
        const double side = std::max(double(L.nx - 1) * double(L.dx), double(L.nz - 1) * double(L.dz));
        return std::max(0.05, 0.005 * side);
    }
    return std::max(0.05, 0.05 * glm::length(scene.camera.target - scene.camera.position));
}

void sunAngles(const glm::vec3& direction, double* elevationDeg, double* azimuthDeg)
{
    const glm::dvec3 d = glm::normalize(glm::dvec3(direction));
    *elevationDeg = std::asin(std::clamp(d.y, -1.0, 1.0)) / kDegToRad;
    double az = std::atan2(d.x, d.z) / kDegToRad;
    if (az < 0.0) az += 360.0;
    *azimuthDeg = az;
}

CameraDesc framingCamera(const CameraDesc& current, const Bounds3& b)
{
    CameraDesc c = current;
    const glm::dvec3 centre = glm::dvec3(b.center());
    const double radius = std::max(0.1, 0.5 * double(glm::length(b.extent())));
    const double dist = 1.15 * radius / std::sin(double(c.fovY) * 0.5 * 3.14159265358979323846 / 180.0);
    c.target = centre;
    c.position = centre + dist * glm::normalize(glm::dvec3(-0.35, 0.2, -1.0));
    c.up = glm::vec3(0.0f, 1.0f, 0.0f);
    return c;
}

} // namespace sylva
