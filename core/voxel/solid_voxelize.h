// Solid voxelization (Geist & Westall, "Lattice-Boltzmann Lighting Models", section 3.2.3, the PMMA teapot):
// the interior of a mesh filled, robust to open edges and gaps through the generalized winding number
// (winding_number.h). Public API for `sylva voxelize --solid`, scenes and the renderer.
#pragma once

#include "core/grid/grid.h"
#include "core/mesh/triangle_mesh.h"
#include "core/voxel/voxelize.h"

namespace sylva {

class Progress;

// Bump when a change alters the grids voxelizeSolid returns (cache keys include it with `solid`).
inline constexpr int kSolidVoxelizerVersion = 1;

// The inside threshold: a point is inside where |w| >= 1/2 (|w|: a mesh oriented inward fills too).
inline constexpr double kSolidInsideThreshold = 0.5;

// Density = the share of the node's subcells^3 sub-cell centres that lie inside, on the grid of
// gridForMesh(meshBounds(mesh), settings) (the surface voxelizer's grid: same origin, spacing, dims).
// Nodes whose cell no triangle meets (the surface voxelizer marks none of their sub-cells) take the
// winding number of their centre for the whole cell (exact for a closed mesh: w is constant off the
// surface); the others are sampled per sub-cell centre. Margin nodes stay 0. woodFraction is 0 everywhere
// (a solid is a medium, not biomass: no node turns brown in the LB solve). Deterministic for any thread
// count; reports progress and honours cancel; the same errors as voxelize.
DensityGrid voxelizeSolid(const TriangleMesh& mesh, const VoxelizeSettings& settings, Progress* progress = nullptr);

} // namespace sylva
