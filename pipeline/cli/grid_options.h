// Options of the grid commands (voxelize, light, reference): voxelizer settings, the density input,
// the LB optics and the slice picture.
#pragma once

#include <string>

#include "core/grid/grid.h"
#include "core/lb/lb_params.h"
#include "core/voxel/voxelize.h"
#include "pipeline/cache/grid_cache.h"
#include "pipeline/cli/args.h"
#include "pipeline/import/mesh_import.h"
#include "pipeline/lighting_job.h"

namespace sylva::cli {

inline const OptionSpec kLeafMaterials{"--leaf-materials", "A,B", "names of the leaf materials (override the automatic leaf/wood split)"};
inline const OptionSpec kGrid{"--grid", "N|X,Y,Z", "grid nodes on the longest axis, or per axis (3..512; default 128)"};
inline const OptionSpec kSubcells{"--subcells", "N", "sub-cells per cell edge for the density (default 3)"};
inline const OptionSpec kPicture{"--picture", "PNG", "also write a PNG montage of slices"};
inline const OptionSpec kSlices{"--slices", "N", "slices in the picture (default 8)"};
inline const OptionSpec kAxis{"--axis", "x|y|z", "slicing axis of the picture (default z)"};

// --grid, --subcells.
VoxelizeSettings voxelSettings(const Args& args);
// --leaf-materials.
ImportOptions importOptions(const Args& args);

struct PictureOptions {
    std::string path;   // empty: no picture
    int axis = 2;
    int slices = 8;
};
// --picture, --axis, --slices: parsed and checked before any work, so a bad picture option does not cost a solve.
PictureOptions pictureOptions(const Args& args);
// Writes the montage (nothing without --picture) and prints "picture: PATH".
void writePicture(const PictureOptions& options, const DensityGrid* density, const LightingGrid* light);

// The optics, sun and steps of `light` and `reference` (--preset, --sigma-a, ..., --coarse-start), validated.
lb::LbParams lightParams(const Args& args);
// UsageError when --grid, --subcells or --leaf-materials come with --density.
void rejectMeshOptionsWithDensity(const Args& args);
// The density grid of `light` and `reference`: --density FILE (checked), or --mesh voxelized through
// the cache with a progress bar.
DensityGrid loadDensityInput(const Args& args, const VoxelizeSettings& voxel, GridCache* cache, JobLog& log);
// Prints the "density grid ..." line (pipeline/services/grid_stats computes its numbers).
void printDensitySummary(const DensityGrid& density);

} // namespace sylva::cli
