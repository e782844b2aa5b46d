// Mesh to density grid (docs/LB_MODEL.md "Voxelization"): exact triangle / sub-cell marking, parallel, deterministic.
#pragma once

#include <glm/glm.hpp>

#include "core/grid/grid.h"
#include "core/mesh/triangle_mesh.h"

namespace sylva {

class Progress;

inline constexpr int kVoxelMinNodes = 3;      // nodes per axis: one interior node between two margin nodes
inline constexpr int kVoxelMaxNodes = 512;
// Bump whenever a change alters the grids voxelize returns (cache keys include it).
inline constexpr int kVoxelizerVersion = 1;
inline constexpr int kVoxelMaxSubcells = 16;  // sub-cells per cell edge; 16^3 = 4096 density levels

// How to size the grid and refine its cells. 24 bytes.
struct VoxelizeSettings {
    glm::ivec3 dims{0};          // nodes per axis (each 3..512) when all three are > 0; else automatic
    int longestAxisNodes = 128;  // automatic sizing: nodes along the longest axis of the mesh bounds (3..512)
    int subcells = 3;            // each cell is split into subcells^3 sub-cells (1..16)
    bool solid = false;          // fill the interior (voxelizeSolid, solid_voxelize.h) instead of marking the surface
};

// Grid placement for mesh bounds (metres). Each node owns a cube cell of side `spacing` centred on
// it; the cells of the interior nodes (1..dims-2) cover the bounds, so the boundary nodes are an
// empty margin. spacing = max over axes of extent / (dims - 2); the mesh is centred on every axis.
// Automatic dims: the longest axis gets longestAxisNodes nodes, the others the fewest nodes (>= 3)
// whose interior cells cover the extent. A zero extent on one or two axes (a flat mesh) is fine.
// Throws sylva::Error for dims or longestAxisNodes outside 3..512, empty or non-finite bounds and
// bounds of zero extent on all axes.
GridGeometry gridForMesh(const Bounds3& bounds, const VoxelizeSettings& settings);

// Density and wood fraction of the mesh on gridForMesh(meshBounds(mesh), settings).
// A sub-cell is marked when a triangle meets it (exact overlap test, closed sub-cells: a triangle on
// a face shared by two sub-cells marks both, one touching an edge or corner marks all sharing it),
// except that margin sub-cells are never marked (the mesh bounds touch them only on their faces).
// The test runs in float sub-cell units (computed in double, rounded once): a contact closer than
// about 1e-4 sub-cell may go either way, but a coordinate within double rounding of a sub-cell plane
// (an axis-aligned face at the mesh bounds, for one) lands exactly on it and counts as touching.
// density = marked / subcells^3 in [0,1]. woodFraction = (sub-cells touched by a wood triangle) /
// (marked sub-cells), 0 where nothing is marked; triangles whose material is not a leaf (and all
// triangles of a mesh without materials) count as wood. Zero-area triangles mark what they touch.
// Output is identical for any thread count. Reports progress every 2% and honours cancel
// (throws Cancelled). Throws sylva::Error for bad settings (see gridForMesh, subcells outside
// 1..16), an empty mesh, non-finite coordinates, vertex or material indices out of range.
// With settings.solid, returns voxelizeSolid(mesh, settings, progress) instead (solid_voxelize.h).
DensityGrid voxelize(const TriangleMesh& mesh, const VoxelizeSettings& settings, Progress* progress = nullptr);

} // namespace sylva
