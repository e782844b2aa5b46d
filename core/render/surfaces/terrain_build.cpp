// The terrain surface kind's builder: its heights and min/max pyramid into the frame's arrays.
#include "core/render/scene_build.h"

#include "core/terrain/height_field.h"

namespace sylva::scene_build {

void buildTerrainArrays(RenderScene& rs, const Scene& scene)
{
    if (!scene.terrain.enabled()) return;
    const HeightField& hf = *scene.terrain.field;
    rs.terrainHeights = hf.heights;
    rs.terrainRanges = hf.ranges;
    rs.frame.terrain.layout = hf.layout;
    rs.buildStats.terrainSamplesX = hf.layout.nx;
    rs.buildStats.terrainSamplesZ = hf.layout.nz;
}

} // namespace sylva::scene_build
