// The scene build's parts (render_scene.cpp's buildSceneGeometry is their table of contents): each surface
// kind's builder and the frame's LB solves. Internal to core/render.
#pragma once

#include <cstdint>
#include <cmath>
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
// The LB solves a frame triggers (core/render/scene_lighting.cpp): the forest-level grid over the top level's
// instances, and its share over the landscape's plants.
void buildForestGrid(RenderScene& rs, const Scene& scene);
void buildLandscapeLight(RenderScene& rs, const Scene& scene);

// An instance's box in the frame whose origin is frameOrigin, from its geometry's bounds b.
Bounds3 instanceBox(const InstanceDesc& d, const Bounds3& b, const glm::dvec3& frameOrigin);
// The level of detail each top-level instance gets from the scene's camera.
std::vector<int> instanceLevels(const Scene& scene, const std::vector<RenderScene::MeshLevels>& ml);
// The byte statistics of the arrays (AccelStats).
void countBytes(RenderScene& rs);
// The terrain-frame height above which the ground is snow (> any height: none), and the cosine below which
// a normal is rock: the shader's colour rule and the landscape's masks (TerrainRecord::snowY, rockCos).
inline float terrainSnowY(const TerrainDesc& t) { return t.snowLine > 0.0f ? float(double(t.snowLine) - t.origin.y) : 3.0e38f; }
inline float terrainRockCos(const TerrainDesc& t) { return float(std::cos(double(t.rockSlope) * 3.14159265358979323846 / 180.0)); }

} // namespace sylva::scene_build
