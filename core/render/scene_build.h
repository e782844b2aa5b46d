// The scene build's parts (render_scene.cpp's buildSceneGeometry is their table of contents): each kind's
// builder. Internal to core/render.
#pragma once

#include <cstdint>
#include <vector>

#include "core/render/render_scene.h"

namespace sylva::scene_build {

// The terrain's heights and min/max pyramid (core/render/surfaces/terrain_build.cpp).
void buildTerrainArrays(RenderScene& rs, const Scene& scene);
// Species meshes and their pruned levels of detail: shading arrays, materials, lighting grids, triangle blocks
// under BVHs (or kd-trees), the mesh geometry records (core/render/surfaces/mesh_build.cpp).
void buildMeshGeometry(RenderScene& rs, const Scene& scene, const std::vector<SpeciesAssets>& assets, LodLevels lod, Progress* progress);
// Instance groups in `order` (each after the groups it places): their instances in their own frames under a
// BVH each (core/render/surfaces/group_build.cpp).
void buildGroupGeometry(RenderScene& rs, const Scene& scene, const std::vector<uint32_t>& order);
// The volumes' grids, bricks, lighting and temperatures (core/render/surfaces/volumes_build.cpp) from
// scene.volumes (each with its data loaded: pipeline/scene loadSceneVolumes). Throws Error naming the volume
// when its data is missing or inconsistent (lighting or temperature of other dims).
void buildVolumeGrids(RenderScene& rs, const Scene& scene);
// rs.volumeInstances for the camera at `eye` (world metres, double): each volume's placements mapped from the
// camera-relative frame to its grid's node coordinates.
void placeVolumes(RenderScene& rs, const Scene& scene, const glm::dvec3& eye);
// Brick maxima of a density grid (what buildVolumeGrids stores): per brick of kVolumeBrick nodes, the largest
// density over the nodes a trilinear lookup inside it reads.
std::vector<float> volumeBrickMaxima(const std::vector<float>& density, const glm::ivec3& dims, glm::ivec3* bricks);

// An instance's box in the frame whose origin is frameOrigin, from its geometry's bounds b.
Bounds3 instanceBox(const InstanceDesc& d, const Bounds3& b, const glm::dvec3& frameOrigin);
// The level of detail each top-level instance gets from the scene's camera.
std::vector<int> instanceLevels(const Scene& scene, const std::vector<RenderScene::MeshLevels>& ml);
} // namespace sylva::scene_build
