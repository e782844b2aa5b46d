// Moving a built RenderScene to a new camera, instance placement or environment without rebuilding the
// species BVHs: the studio's fast path for camera moves and instance edits.
#pragma once

#include <vector>

#include "core/render/render_scene.h"
#include "core/scene/scene.h"

namespace sylva {

// A RenderScene built once per set of species assets, plus what the fast path needs.
struct ViewFrame {
    RenderScene rs;
    std::vector<Bounds3> speciesBounds;   // per species, species frame
};

// Builds the species part (buildRenderScene with the scene's BVH accel) and records species bounds.
// Throws Error (e.g. a scene without instances).
ViewFrame buildViewFrame(const Scene& scene, const std::vector<SpeciesAssets>& assets, const glm::vec3& sunRadiance);

// Re-places the frame for `scene` at width x height: instance records and the instance BVH in the
// camera-relative frame of scene.camera, ground, sun, sky, camera and settings, exactly as
// buildRenderScene lays them out. The species (list and assets) must be those the frame was built with.
// Costs O(instances); throws Error on a degenerate camera or a missing species.
void placeViewFrame(ViewFrame& frame, const Scene& scene, const glm::vec3& sunRadiance, int width, int height, int spp);

} // namespace sylva
