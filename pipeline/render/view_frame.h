// The studio's frame: the camera-independent part of a RenderScene built once per set of species assets,
// the top level re-placed for every camera move or instance edit, through the same two steps as sylva render.
#pragma once

#include <vector>

#include "core/render/render_scene.h"
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

} // namespace sylva
