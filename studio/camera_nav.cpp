// Orbit, pan and zoom on CameraDesc in doubles.
#include "studio/camera_nav.h"

#include <algorithm>
#include <cmath>

#include "core/render/render_scene.h"
#include "core/terrain/height_field.h"

namespace sylva {
namespace {

constexpr double kDegToRad = 3.14159265358979323846 / 180.0;

// v turned by yawDeg about +Y and pitchDeg toward +Y, keeping its length: spherical angles with yaw
// from +Z toward +X and pitch above the horizon, pitch clamped to +-89 degrees. v must not be zero.
glm::dvec3 turned(const glm::dvec3& v, double yawDeg, double pitchDeg)
{
    if (yawDeg == 0.0 && pitchDeg == 0.0) return v;   // exactly unchanged (no rounding of the angles' round trip)
    const double dist = glm::length(v);
    const double yaw = std::atan2(v.x, v.z) + yawDeg * kDegToRad;
    const double pitch = std::clamp(std::asin(std::clamp(v.y / dist, -1.0, 1.0)) + pitchDeg * kDegToRad, -89.0 * kDegToRad, 89.0 * kDegToRad);
    return dist * glm::dvec3(std::cos(pitch) * std::sin(yaw), std::sin(pitch), std::cos(pitch) * std::cos(yaw));
}

} // namespace

bool cameraUsable(const CameraDesc& camera)
{
    const glm::dvec3 view = camera.target - camera.position;
    const double length = glm::length(view);
    const glm::dvec3 up(camera.up);
    const double upLength = glm::length(up);
    if (!(length > 0.0) || !std::isfinite(length) || !(upLength >= 1e-12)) return false;
    return glm::length(glm::cross(view / length, up / upLength)) >= 1e-6;
}

CameraDesc orbitCamera(const CameraDesc& camera, double yawDeg, double pitchDeg)
{
    CameraDesc c = camera;
    if (!(glm::length(c.position - c.target) > 0.0)) return c;
    c.position = c.target + turned(c.position - c.target, yawDeg, pitchDeg);
    c.up = glm::vec3(0.0f, 1.0f, 0.0f);
    return c;
}

CameraDesc orbitCameraAbout(const CameraDesc& camera, double yawDeg, double pitchDeg, const glm::dvec3& pivot)
{
    if (yawDeg == 0.0 && pitchDeg == 0.0) return camera;
    const glm::dvec3 view = camera.target - camera.position;
    const double dist = glm::length(view);
    if (!(dist > 0.0)) return camera;
    // The camera's frame before (its own up) and after (orbitCamera's view direction, up +Y), as the renderer
    // builds it: right = forward x up, up' = right x forward.
    auto frame = [](const glm::dvec3& forward, const glm::dvec3& up, glm::dmat3* m) {
        const glm::dvec3 f = glm::normalize(forward);
        const glm::dvec3 x = glm::cross(f, up);
        if (!(glm::length(x) > 1e-12)) return false;
        const glm::dvec3 r = glm::normalize(x);
        *m = glm::dmat3(r, glm::cross(r, f), f);   // columns
        return true;
    };
    const CameraDesc turnedCam = orbitCamera(camera, yawDeg, pitchDeg);
    glm::dmat3 before, after;
    if (!frame(view, glm::dvec3(camera.up), &before) || !frame(turnedCam.target - turnedCam.position, glm::dvec3(0.0, 1.0, 0.0), &after))
        return turnedCam;
    const glm::dmat3 turn = after * glm::transpose(before);   // the old frame onto the new
    CameraDesc c = camera;
    c.position = pivot + turn * (camera.position - pivot);
    c.target = c.position + turn * view;
    c.up = glm::vec3(0.0f, 1.0f, 0.0f);
    return c;
}

CameraDesc panCamera(const CameraDesc& camera, double dx, double dy, double viewHeight, double depth)
{
    CameraDesc c = camera;
    const glm::dvec3 fwd = c.target - c.position;
    const double dist = depth > 0.0 ? depth : glm::length(fwd);
    if (!(glm::length(fwd) > 0.0) || !(dist > 0.0) || !(viewHeight > 0.0) || (dx == 0.0 && dy == 0.0)) return c;
    const glm::dvec3 f = fwd / glm::length(fwd);
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

CameraDesc zoomCameraAbout(const CameraDesc& camera, double steps, const glm::dvec3& about, double factor)
{
    CameraDesc c = camera;
    const double dist = glm::length(c.position - about);
    if (!(dist > 0.0) || steps == 0.0) return c;
    const double k = std::max(0.01, dist * std::pow(factor, steps)) / dist;
    c.position = about + (c.position - about) * k;
    c.target = about + (c.target - about) * k;
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

double flyStepFor(const Scene& scene, const std::vector<Bounds3>& speciesBoxes)
{
    const TerrainDesc& t = scene.terrain;
    if (t.enabled() && t.field) {
        const HeightFieldLayout& L = t.field->layout;
        const double side = std::max(double(L.nx - 1) * double(L.dx), double(L.nz - 1) * double(L.dz));
        return std::max(0.05, 0.005 * side);
    }
    double step = 0.05 * glm::length(scene.camera.target - scene.camera.position);
    if (const Bounds3 b = sceneBounds(scene, speciesBoxes); b.valid()) {
        const glm::vec3 e = b.extent();
        step = std::max(step, 0.005 * double(std::max({e.x, e.y, e.z})));
    }
    return std::max(0.05, step);
}

Bounds3 instanceBounds(const Scene& scene, const InstanceDesc& instance, const Bounds3& speciesBox)
{
    glm::dvec3 p = instance.position;
    const TerrainDesc& t = scene.terrain;
    if (instance.onTerrain && t.enabled() && t.field) {
        const double h = surfaceHeight(*t.field, p.x - t.origin.x, p.z - t.origin.z);
        if (std::isfinite(h)) p.y += t.origin.y + h;
    }
    Bounds3 out;
    if (!speciesBox.valid()) {
        out.extend(glm::vec3(p));
        return out;
    }
    // world = R (s x) + p, the renderer's instance map (makeInstance).
    const glm::dmat3 r = rotationDeg(instance.rotationDeg);
    for (int k = 0; k < 8; ++k) {
        const glm::dvec3 corner((k & 1) ? speciesBox.hi.x : speciesBox.lo.x, (k & 2) ? speciesBox.hi.y : speciesBox.lo.y,
                                (k & 4) ? speciesBox.hi.z : speciesBox.lo.z);
        out.extend(glm::vec3(r * (double(instance.scale) * corner) + p));
    }
    return out;
}

Bounds3 sceneBounds(const Scene& scene, const std::vector<Bounds3>& speciesBoxes)
{
    Bounds3 out;
    for (const InstanceDesc& in : scene.instances) {
        const Bounds3 none;
        const Bounds3& box = in.group == kNoGroup && in.species < speciesBoxes.size() ? speciesBoxes[in.species] : none;
        const Bounds3 b = instanceBounds(scene, in, box);
        out.extend(b.lo);
        out.extend(b.hi);
    }
    const TerrainDesc& t = scene.terrain;
    if (t.enabled() && t.field && !t.field->heights.empty()) {
        const HeightFieldLayout& L = t.field->layout;
        const auto [lo, hi] = std::minmax_element(t.field->heights.begin(), t.field->heights.end());
        out.extend(glm::vec3(t.origin + glm::dvec3(0.0, double(*lo), 0.0)));
        out.extend(glm::vec3(t.origin + glm::dvec3(double(L.nx - 1) * double(L.dx), double(*hi), double(L.nz - 1) * double(L.dz))));
    }
    return out;
}

CameraDesc frameBoxCamera(const CameraDesc& current, const Bounds3& b, double aspect, double fill)
{
    CameraDesc c = current;
    if (!b.valid() || !(aspect > 0.0) || !(fill > 0.0)) return c;
    glm::dvec3 f = c.target - c.position;
    if (!(glm::length(f) > 0.0)) f = glm::dvec3(0.0, 0.0, 1.0);
    f = glm::normalize(f);
    glm::dvec3 right = glm::cross(f, glm::dvec3(c.up));
    if (!(glm::length(right) > 1e-9)) return c;
    right = glm::normalize(right);
    const glm::dvec3 up = glm::cross(right, f);
    const double tanY = std::tan(double(c.fovY) * 0.5 * kDegToRad) * fill, tanX = tanY * aspect;
    const glm::dvec3 centre = glm::dvec3(b.center());
    // A corner q (from the centre) seen from centre - D f lies at depth D + q.f; it is inside the framed part
    // when |q.right| <= tanX (D + q.f) and |q.up| <= tanY (D + q.f): D is the largest such bound.
    double dist = 0.0, nearest = 0.0;
    for (int k = 0; k < 8; ++k) {
        const glm::dvec3 q = glm::dvec3((k & 1) ? b.hi.x : b.lo.x, (k & 2) ? b.hi.y : b.lo.y, (k & 4) ? b.hi.z : b.lo.z) - centre;
        const double along = glm::dot(q, f);
        dist = std::max({dist, std::abs(glm::dot(q, right)) / tanX - along, std::abs(glm::dot(q, up)) / tanY - along});
        nearest = std::max(nearest, -along);
    }
    // The eye stays in front of every corner (a flat box seen edge-on) and 1 cm from the centre.
    dist = std::max({dist, nearest + 0.01, 0.01});
    c.target = centre;
    c.position = centre - dist * f;
    return c;
}

bool projectToView(const CameraDesc& camera, double width, double height, const glm::dvec3& p, glm::dvec2* pixel)
{
    glm::dvec3 f = camera.target - camera.position;
    if (!(glm::length(f) > 0.0) || !(width > 0.0) || !(height > 0.0)) return false;
    f = glm::normalize(f);
    glm::dvec3 right = glm::cross(f, glm::dvec3(camera.up));
    if (!(glm::length(right) > 1e-9)) return false;
    right = glm::normalize(right);
    const glm::dvec3 up = glm::cross(right, f);
    const glm::dvec3 q = p - camera.position;
    const double depth = glm::dot(q, f);
    if (!(depth > 1e-9)) return false;
    const double tanY = std::tan(double(camera.fovY) * 0.5 * kDegToRad), tanX = tanY * width / height;
    const double sx = glm::dot(q, right) / (depth * tanX), sy = glm::dot(q, up) / (depth * tanY);
    // The inverse of cameraRay (core/render/shade.h): sx = 2x/w - 1, sy = 1 - 2y/h.
    *pixel = glm::dvec2(0.5 * (sx + 1.0) * width, 0.5 * (1.0 - sy) * height);
    return true;
}

glm::dvec3 viewRayDirection(const CameraDesc& camera, double width, double height, const glm::dvec2& pixel)
{
    glm::dvec3 f = camera.target - camera.position;
    if (!(glm::length(f) > 0.0) || !(width > 0.0) || !(height > 0.0)) return glm::dvec3(0.0);
    f = glm::normalize(f);
    glm::dvec3 right = glm::cross(f, glm::dvec3(camera.up));
    if (!(glm::length(right) > 1e-9)) return glm::dvec3(0.0);
    right = glm::normalize(right);
    const glm::dvec3 up = glm::cross(right, f);
    const double tanY = std::tan(double(camera.fovY) * 0.5 * kDegToRad), tanX = tanY * width / height;
    const double sx = 2.0 * pixel.x / width - 1.0, sy = 1.0 - 2.0 * pixel.y / height;
    return glm::normalize(f + sx * tanX * right + sy * tanY * up);
}

bool viewRayOnPlane(const CameraDesc& camera, double width, double height, const glm::dvec2& pixel, const glm::dvec3& planePoint,
                    const glm::dvec3& planeNormal, glm::dvec3* point)
{
    const glm::dvec3 d = viewRayDirection(camera, width, height, pixel);
    const double dn = glm::dot(d, planeNormal);
    if (!(std::abs(dn) > 1e-12)) return false;
    const double t = glm::dot(planePoint - camera.position, planeNormal) / dn;
    if (!(t > 0.0)) return false;
    *point = camera.position + t * d;
    return true;
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
