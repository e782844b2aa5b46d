// The lighting pipeline for one species: mesh -> density grid -> LB lighting grid, with the grid cache.
#pragma once

#include <string>
#include <vector>

#include "core/base/progress.h"
#include "core/grid/grid.h"
#include "core/lb/lb_params.h"
#include "core/voxel/voxelize.h"
#include "pipeline/import/mesh_import.h"

namespace sylva {

class Backend;
class GridCache;

// What ran, in order: "import", "voxelize", "voxelize (cache hit)", "light", "light (cache hit)", and
// cache warnings. Tests and the studio read it.
struct JobLog {
    std::vector<std::string> stages;
    std::vector<std::string> warnings;
};

struct DensityJob {
    std::string meshPath;
    ImportOptions import;
    VoxelizeSettings voxel;
};

// Imports and voxelizes a mesh, or loads the grid from the cache (key: imported geometry and materials,
// voxelizer settings, cache format). cache may be null (no caching).
DensityGrid densityForMesh(const DensityJob& job, GridCache* cache, Progress* progress = nullptr, JobLog* log = nullptr);

// As densityForMesh for a mesh already in memory (grown species): voxelizes or loads from the cache.
DensityGrid densityForTriangles(const TriangleMesh& mesh, const VoxelizeSettings& voxel, GridCache* cache,
                                Progress* progress = nullptr, JobLog* log = nullptr);

// Hash of a density grid's content and placement, for lighting cache keys.
std::string densityHash(const DensityGrid& density);

// Solves (or loads from the cache) the lighting of a density grid. The key covers the density content,
// every LB parameter that changes the answer, the sun, steps/tolerance, storage and the format version.
// backend: where the solve runs (null = the CPU); backends agree to float rounding, so the cache
// key does not name the backend.
LightingGrid lightingFor(const DensityGrid& density, const lb::LbParams& params, GridCache* cache,
                         Progress* progress = nullptr, JobLog* log = nullptr, Backend* backend = nullptr);

// The LB parameters of a solve as the JSON object a lighting sidecar stores under "parameters"
// (`sylva light` and the studio's grid export): preset, per-channel sigma_a, sigma_s, g, intensity,
// sun, zero_f0, storage, tolerance (or steps, the default for dims when params.steps is 0),
// warm_start, and coarse_start when set.
std::string lightingParamsJson(const lb::LbParams& params, const std::string& preset, const glm::ivec3& dims);
// The optics part of it, as JSON members without braces (preset, sigma_a, sigma_s, g, sun, intensity,
// zero_f0): what `sylva reference` records too.
std::string opticsJsonMembers(const lb::LbParams& params, const std::string& preset);

} // namespace sylva
