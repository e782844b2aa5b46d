// The studio's frame through the renderer's one builder (buildSceneGeometry + placeTopLevel).
#include "pipeline/render/view_frame.h"

namespace sylva {

ViewFrame buildViewFrame(const Scene& scene, const std::vector<SpeciesAssets>& assets, const glm::vec3& sunRadiance)
{
    Scene s = scene;
    s.render.accel = AccelKind::Bvh;   // the viewport traces BVHs
    ViewFrame f;
    f.rs = buildSceneGeometry(s, assets, LodLevels::All);
    placeTopLevel(f.rs, s, sunRadiance, s.render.width, s.render.height, s.render.spp);
    return f;
}

bool viewFrameFits(const ViewFrame& frame, const Scene& scene) { return hasLevelsFor(frame.rs, scene); }

void placeViewFrame(ViewFrame& frame, const Scene& scene, const glm::vec3& sunRadiance, int width, int height, int spp)
{
    placeTopLevel(frame.rs, scene, sunRadiance, width, height, spp);
}

} // namespace sylva
