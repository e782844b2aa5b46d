// Host side of the volumes of a frame: grids, bricks, lighting and temperatures into the flat arrays
// (once per set of assets), the placed instances camera-relative (per camera).
#pragma once

#include <glm/glm.hpp>

#include "core/render/render_scene.h"
#include "core/scene/scene.h"

namespace sylva {

// Fills rs.volumeGrids, volumeDensity, volumeBricks, volumeLight, volumeTemperature, volumeBlackbody
// from scene.volumes (each must have its data loaded: pipeline/scene loadSceneVolumes). Throws Error
// naming the volume when its data is missing or inconsistent (lighting or temperature of other dims).
void buildVolumeGrids(RenderScene& rs, const Scene& scene);

// rs.volumeInstances for the camera at `eye` (world metres, double): each volume's placements mapped
// from the camera-relative frame to its grid's node coordinates.
void placeVolumes(RenderScene& rs, const Scene& scene, const glm::dvec3& eye);

// Brick maxima of a density grid (what buildVolumeGrids stores): per brick of kVolumeBrick nodes, the
// largest density over the nodes a trilinear lookup inside it reads. Exposed for the tests.
std::vector<float> volumeBrickMaxima(const std::vector<float>& density, const glm::ivec3& dims, glm::ivec3* bricks);

} // namespace sylva
