// Viewport navigation on a scene camera: orbit about the target, pan in the image plane, dolly zoom, fly, framing.
#pragma once

#include "core/mesh/triangle_mesh.h"
#include "core/scene/scene.h"

namespace sylva {

// Rotates the eye about the target: yaw about world +Y, pitch about the camera's right axis (degrees),
// pitch kept within 1 degree of the poles. The target stays put.
CameraDesc orbitCamera(const CameraDesc& camera, double yawDeg, double pitchDeg);

// Moves eye and target together by (dx, dy) pixels of an image `viewHeight` pixels tall, so the point
// under the cursor at the target's distance follows the cursor.
CameraDesc panCamera(const CameraDesc& camera, double dx, double dy, double viewHeight);

// Moves the eye toward the target by factor^steps of the distance (steps > 0: closer); the distance
// stays above 1 cm.
CameraDesc zoomCamera(const CameraDesc& camera, double steps, double factor = 0.85);

// Fly navigation: turns the view about the eye. yawDeg > 0 turns toward the camera's right (about
// world +Y), pitchDeg > 0 looks up; the pitch stays within 1 degree of the poles. The eye stays put,
// the target stays at the same distance ahead of it.
CameraDesc flyLook(const CameraDesc& camera, double yawDeg, double pitchDeg);

// Fly navigation: moves eye and target together by `right` metres along the camera's right axis
// (horizontal), `up` metres along world +Y and `forward` metres along the view direction.
CameraDesc flyMove(const CameraDesc& camera, double right, double up, double forward);

// Metres a fly key press moves in `scene`: over a terrain 0.5% of its longer side (100 m over a 20 km DEM,
// so crossing it takes a couple of hundred presses, or a fifth with Shift's 5x), else 5% of the eye-target
// distance; at least 5 cm.
double flyStepFor(const Scene& scene);

// A camera that shows world box b whole, from the front-left and a little above (current's field of
// view; up is world +Y): what the studio frames the first instances of a scene with.
CameraDesc framingCamera(const CameraDesc& current, const Bounds3& b);

// Elevation and azimuth (degrees, scene.h's convention) of a direction toward the sun.
void sunAngles(const glm::vec3& direction, double* elevationDeg, double* azimuthDeg);

} // namespace sylva
