// Viewport navigation on a scene camera: orbit about the target, pan in the image plane, dolly zoom, fly, framing.
#pragma once

#include <vector>

#include "core/mesh/triangle_mesh.h"
#include "core/scene/scene.h"

namespace sylva {

// Whether the scene file accepts the camera (camera.target, camera.up): the target away from the eye, a finite view
// direction, not along a non-zero up. A navigation or an edit that gives any other camera is not applied.
bool cameraUsable(const CameraDesc& camera);

// Rotates the eye about the target: yaw about world +Y, pitch about the camera's right axis (degrees),
// pitch kept within 1 degree of the poles. The target stays put.
CameraDesc orbitCamera(const CameraDesc& camera, double yawDeg, double pitchDeg);

// Orbit about a point (what was under the cursor when the drag began): the view turns as orbitCamera turns it
// (yaw about world +Y, pitch about the camera's right axis, kept short of the poles), and eye and target move
// with it rigidly about `pivot`, so the pivot keeps its place in the camera's frame and stays on the same pixel.
// Up becomes world +Y. No turn (0, 0) returns the camera unchanged.
CameraDesc orbitCameraAbout(const CameraDesc& camera, double yawDeg, double pitchDeg, const glm::dvec3& pivot);

// Moves eye and target together by (dx, dy) pixels of an image `viewHeight` pixels tall, so a point at
// `depth` metres ahead of the eye (along the view axis; 0: the target's distance) follows the cursor: grab
// what is under the cursor and it stays under it. No movement (dx = dy = 0) returns the camera unchanged.
CameraDesc panCamera(const CameraDesc& camera, double dx, double dy, double viewHeight, double depth = 0.0);

// Moves the eye toward the target by factor^steps of the distance (steps > 0: closer); the distance
// stays above 1 cm.
CameraDesc zoomCamera(const CameraDesc& camera, double steps, double factor = 0.85);

// Zoom toward a world point (what is under the cursor): eye and target scaled about `about` by
// factor^steps, so the view direction stays, `about` stays on the same pixel and each step covers the same
// fraction of the distance to it (near things zoom finely, far ones fast). The eye stays at least 1 cm
// from `about`. zoomCameraAbout(c, s, c.target) is zoomCamera(c, s).
CameraDesc zoomCameraAbout(const CameraDesc& camera, double steps, const glm::dvec3& about, double factor = 0.85);

// Fly navigation: turns the view about the eye. yawDeg > 0 turns toward the camera's right (about
// world +Y), pitchDeg > 0 looks up; the pitch stays within 1 degree of the poles. The eye stays put,
// the target stays at the same distance ahead of it.
CameraDesc flyLook(const CameraDesc& camera, double yawDeg, double pitchDeg);

// Fly navigation: moves eye and target together by `right` metres along the camera's right axis
// (horizontal), `up` metres along world +Y and `forward` metres along the view direction.
CameraDesc flyMove(const CameraDesc& camera, double right, double up, double forward);

// Metres a fly key press moves in `scene`: over a terrain 0.5% of its longer side (100 m over a 20 km DEM,
// so crossing it takes a couple of hundred presses, or a fifth with Shift's 5x), else 5% of the eye-target
// distance but at least 0.5% of the longest side of the plants' box (sceneBounds with the species' mesh boxes:
// a forest 2 km wide is crossed in 200 presses however close the target is); at least 5 cm.
double flyStepFor(const Scene& scene, const std::vector<Bounds3>& speciesBoxes = {});

// A camera that shows world box b whole, from the front-left and a little above (current's field of
// view; up is world +Y): what the studio frames the first instances of a scene with.
CameraDesc framingCamera(const CameraDesc& current, const Bounds3& b);

// The world box of an instance of a species whose mesh has box `speciesBox` (species frame): the eight
// corners turned, scaled and moved as the renderer places the instance. An instance standing on the terrain
// (onTerrain) is lifted by the terrain's height under it when the scene has one.
Bounds3 instanceBounds(const Scene& scene, const InstanceDesc& instance, const Bounds3& speciesBox);

// The box of what a scene shows: its instances (speciesBoxes[k]: species k's mesh box; an instance whose
// species has no valid box, or of a group, counts as its position) and its terrain. Not valid when the
// scene has neither.
Bounds3 sceneBounds(const Scene& scene, const std::vector<Bounds3>& speciesBoxes);

// Frames box b in a view `aspect` (width / height) wide: keeps the view direction and field of view, aims at
// the box's centre and moves the eye back (or forward) until the farthest of the box's projected corners
// lies at `fill` of the way from the centre to the picture's edge (horizontally or vertically, whichever is
// reached first). Blender's View All / View Selected.
CameraDesc frameBoxCamera(const CameraDesc& current, const Bounds3& b, double aspect, double fill = 0.9);

// Where world point p lands in a width x height picture of `camera` (pixels, y down, the renderer's
// pinhole); false when p is not in front of the eye.
bool projectToView(const CameraDesc& camera, double width, double height, const glm::dvec3& p, glm::dvec2* pixel);

// The direction (unit) of the camera ray through `pixel` (x right, y down) of a width x height picture of
// `camera`: the inverse of projectToView. Zero for a degenerate camera or picture.
glm::dvec3 viewRayDirection(const CameraDesc& camera, double width, double height, const glm::dvec2& pixel);

// Where that ray meets the plane through `planePoint` with normal `planeNormal`; false when it runs parallel
// to the plane or meets it behind the eye.
bool viewRayOnPlane(const CameraDesc& camera, double width, double height, const glm::dvec2& pixel, const glm::dvec3& planePoint,
                    const glm::dvec3& planeNormal, glm::dvec3* point);

// Elevation and azimuth (degrees, scene.h's convention) of a direction toward the sun.
void sunAngles(const glm::vec3& direction, double* elevationDeg, double* azimuthDeg);

} // namespace sylva
