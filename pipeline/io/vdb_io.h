// OpenVDB (.vdb) files of density, wood fraction and lighting grids. OpenVDB's headers stay in
// vdb_io.cpp (they are slow to compile); this header only names the grids and the calls.
//
// Layout (docs/FILES.md, "OpenVDB grids"): node (i,j,k) of a Sylva grid is voxel (i,j,k) of every VDB
// grid in the file, whose centre OpenVDB places at world origin + spacing * (i,j,k): a linear
// transform of uniform scale `spacing` translated by `origin`, so Sylva's node centres are the VDB
// voxel centres and a voxel covers half a spacing either side of its node. Zero is the background:
// zero-valued nodes are inactive (sparse), and inactive voxels read as 0.
#pragma once

#include <string>

#include "core/grid/grid.h"

namespace sylva {

// Grid names in the files Sylva writes.
inline constexpr const char* kVdbDensityGrid = "density";          // float, class fog volume
inline constexpr const char* kVdbWoodGrid = "wood_fraction";       // float
inline constexpr const char* kVdbLightingGrid = "lighting";        // vec3s, vector type invariant (a colour)
inline constexpr const char* kVdbLightingChannelGrids[3] = {"lighting_r", "lighting_g", "lighting_b"};   // float

// The most nodes a grid read from a .vdb may span (its index box): 512^3, the largest grid `sylva
// voxelize --grid` makes (a float density of 512 MiB).
inline constexpr size_t kVdbMaxNodes = size_t(512) * 512 * 512;

// Writes PATH (atomic: temporary file, then rename) with the grids given (at least one; both must
// then share their geometry): for `density` the grids "density" and "wood_fraction" (zeros when it
// has none), for `lighting` "lighting" (RGB as one vec3 grid) and "lighting_r/_g/_b" (one float grid
// per channel). Every grid carries the metadata sylva_dims (nodes per axis, so empty borders survive
// the round trip), sylva_kind ("density" or "lighting"), sylva_version and, when parametersJson is a
// non-empty JSON object (lightingParamsJson), one entry sylva_KEY per member (numbers double, booleans
// bool, strings string, three numbers vec3d, anything else its JSON text) and sylva_parameters (the
// whole object as JSON text). Throws Error naming PATH.
void writeVdbFile(const std::string& path, const DensityGrid* density, const LightingGrid* lighting,
                  const std::string& parametersJson = {});

// The density of a .vdb: the float grid named "density" (another type under that name is an error),
// else the first float grid in OpenVDB's listing of the file (by name); with a float "wood_fraction" grid of the same transform when the file has
// one (else zeros). Active voxels (and active tiles) give the values, inactive ones 0. The nodes are
// voxels 0 .. sylva_dims-1 for a file Sylva wrote, else the active voxels' bounding box grown by one
// node of zeros on every side (the LB boundary). Throws Error naming PATH for: no such file, not a VDB
// file (or empty, or damaged), no float grid (listing the grids it has), a level set (a distance, not
// a density), a frustum, rotated, sheared, mirrored or non-uniformly scaled transform, no active
// voxel, more than kVdbMaxNodes nodes.
DensityGrid readVdbDensity(const std::string& path);

// The lighting of a .vdb: the vec3s grid "lighting", else the float grids "lighting_r/_g/_b"; placed
// and checked as readVdbDensity. Throws Error naming PATH.
LightingGrid readVdbLighting(const std::string& path);

// What `sylva info` prints for a .vdb: per grid its name, type, class, active voxels, index box, voxel
// size and origin, value range, and its sylva_* metadata; then what readVdbDensity makes of the file
// (its nodes, or why it cannot read it). Lines end in '\n'. Throws Error naming PATH when it is not a
// readable OpenVDB file.
std::string describeVdbFile(const std::string& path);

} // namespace sylva
