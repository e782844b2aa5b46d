// The studio's frame: the camera-independent part of a RenderScene built once per set of species assets,
// the top level re-placed for every camera move or instance edit, through the same two steps as sylva render.
#pragma once

#include <vector>

#include "core/render/render_scene.h"
#include "core/render/surfaces/surface_list.h"
#include "core/scene/scene.h"

namespace sylva {

// A RenderScene whose meshes, every level of detail (when the scene prunes) and groups are built once.
struct ViewFrame {
    RenderScene rs;
};

// buildSceneGeometry with the BVH and every level of detail (the camera moves after the build), then
// placeTopLevel at the scene's camera and size. Throws Error (e.g. a scene without instances).
ViewFrame buildViewFrame(const Scene& scene, const std::vector<SpeciesAssets>& assets, const glm::vec3& sunRadiance);

// Whether `frame` can be re-placed for `scene` (the same species and groups assumed): false when the
// scene prunes and the frame was built without its levels of detail (then build it again).
bool viewFrameFits(const ViewFrame& frame, const Scene& scene);

// placeTopLevel for `scene` at width x height and spp: exactly the top level sylva render builds for the
// same camera (the levels of detail included). The species (list and assets) and groups must be those the
// frame was built with. Costs O(instances); throws Error on a degenerate camera, a missing species, or a
// frame that does not fit (viewFrameFits).
void placeViewFrame(ViewFrame& frame, const Scene& scene, const glm::vec3& sunRadiance, int width, int height, int spp);

// What one camera ray hits: the ray through image position (x, y) (pixels, y down) of a width x height
// picture of `camera` (cameraRay's ray, traced by traceScene as the renderer traces a pixel's first hit) in a
// frame last placed (placeViewFrame) for a camera at `placedAt` (the frame is camera-relative to that eye;
// `camera` may have moved since, the instances must not). kind None: the ray left the scene (the sky).
struct ViewPick {
    SurfaceKind kind = SurfaceKind::None;
    int instance = -1;            // kind Instances: the index into Scene::instances of the top-level instance hit
    double distance = 0.0;        // metres from the eye along the ray
    glm::dvec3 point{0.0};        // world metres
};
ViewPick pickViewFrame(const ViewFrame& frame, const glm::dvec3& placedAt, const CameraDesc& camera, int width, int height,
                       double x, double y);

// Parts of two scenes that the frame's camera-independent build reads (what placeViewFrame does not redo).
bool sameTerrainHeights(const TerrainDesc& a, const TerrainDesc& b);      // DEM, its heights, origin, spacing, scale
bool sameLandscapeTiles(const TerrainDesc& a, const TerrainDesc& b);      // cells, tile set and populations, tiling
bool sameLandscapeDensity(const TerrainDesc& a, const TerrainDesc& b);    // the density rule (eq. 2, 3, masks)
bool sameVolumes(const std::vector<VolumeDesc>& a, const std::vector<VolumeDesc>& b);   // grids, optics, placements

// What a frame built for `built` needs to show `next` (same species assets), cheapest first: nothing
// (placeViewFrame re-places the top level: camera, instances, sun, colours), the density rule's fields,
// the landscape's arrays, the volumes' arrays, or a whole build (terrain heights, groups, sky lights,
// acceleration kind or leaf tint changed). Pruning is viewFrameFits' question.
struct ViewFrameUpdate {
    bool density = false, landscape = false, volumes = false, rebuild = false;
    bool any() const { return density || landscape || volumes || rebuild; }
};
ViewFrameUpdate viewFrameUpdate(const Scene& built, const Scene& next);

// Applies an update short of a rebuild to `frame` for `next` (setLandscapeDensity or buildLandscapeArrays, then
// lightLandscape; rebuildVolumeGrids); placeViewFrame follows. Throws Error as those do.
void updateViewFrame(ViewFrame& frame, const Scene& next, const ViewFrameUpdate& update);

} // namespace sylva
