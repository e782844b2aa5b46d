// The lighting pipeline for one species: mesh -> density grid -> LB lighting grid, with the grid cache.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "core/base/progress.h"
#include "core/grid/grid.h"
#include "core/lb/lb_basis.h"
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

// The lighting for a boundary given per channel (params' sun, intensity and boundary replaced by w): a
// boundary that is one distribution x a factor per channel is one lightingFor; any other (the sun plus a
// coloured sky) is one single-optics lightingFor per channel (its optics in all three, so each is one channel
// solve: as many as params' own). Each is cached (or relit from a cached basis) like lightingFor. A channel
// whose weights are all 0 is 0 without a solve.
LightingGrid lightingForWeights(const DensityGrid& density, const lb::LbParams& params, const lb::BoundaryWeights& w,
                                GridCache* cache, Progress* progress = nullptr, JobLog* log = nullptr, Backend* backend = nullptr);

// Relighting by linearity: the lighting of a species for unit boundaries e_m, one grid
// per moving lattice direction (18: every sun, above or below the horizon), each cached like a lighting
// grid (key: the grid, the optics, steps and storage, the boundary e_m; not the sun). lightingFor uses a
// complete cached basis of the same grid and optics when the exact solve is not cached.
struct LightingBasis {
    std::vector<int> directions;     // lattice directions m
    std::vector<LightingGrid> grids;   // the solve for boundary e_m at unit intensity, per direction
};
// Solves (or loads) every basis grid. Throws Error in tolerance mode (not linear in the boundary).
LightingBasis lightingBasisFor(const DensityGrid& density, const lb::LbParams& params, GridCache* cache,
                               Progress* progress = nullptr, JobLog* log = nullptr, Backend* backend = nullptr);
// The basis from the cache when every grid of it is there (same grid, optics, steps, storage), else nullopt.
std::optional<LightingBasis> cachedLightingBasis(const DensityGrid& density, const lb::LbParams& params, GridCache& cache,
                                                 JobLog* log = nullptr);
// The weights of a solve's boundary: params.boundary (or the sun's) x the intensity per channel.
lb::BoundaryWeights boundaryWeightsOf(const lb::LbParams& params);
// The lighting for a boundary as the weighted sum of the basis grids: no solve.
LightingGrid relight(const LightingBasis& basis, const lb::BoundaryWeights& weights);
LightingGrid relight(const LightingBasis& basis, const lb::LbParams& params);
// Memory the basis holds (fp32 grids).
double basisBytes(const LightingBasis& basis);

// The LB parameters of a solve as the JSON object a lighting sidecar stores under "parameters"
// (`sylva light` and the studio's grid export): preset, per-channel sigma_a, sigma_s, g, intensity,
// sun, zero_f0, storage, tolerance (or steps, the default for dims when params.steps is 0),
// warm_start, and coarse_start when set.
std::string lightingParamsJson(const lb::LbParams& params, const std::string& preset, const glm::ivec3& dims);
// The optics part of it, as JSON members without braces (preset, sigma_a, sigma_s, g, sun, intensity,
// zero_f0): what `sylva reference` records too.
std::string opticsJsonMembers(const lb::LbParams& params, const std::string& preset);

} // namespace sylva
