// Pyroclastic cloud volumes (the graphics-blog post "Adventures in Fluid Simulation",
// its "CreatePyroclasticVolume"): a sphere's distance field displaced
// outward by |fBm Perlin noise|. Public API for the CLI (`sylva volume cloud`) and for scenes that build
// a cloud in place of reading a grid.
#pragma once

#include <cstdint>

#include <glm/glm.hpp>

#include "core/grid/grid.h"

namespace sylva::volume {

inline constexpr int kCloudMinNodes = 8;
inline constexpr int kCloudMaxNodes = 512;
// Bump when a change alters the grids makePyroclasticCloud returns (for cache keys).
inline constexpr int kPyroclasticVersion = 1;

// 36 bytes.
struct PyroclasticParams {
    float radius = 1.0f;        // R: radius of the undisplaced sphere, metres (> 0)
    float amplitude = 0.5f;     // A: largest outward displacement, metres (>= 0); surface radius in [R, R + A]
    float frequency = 1.5f;     // noise lattice cells per metre of the first octave (> 0)
    int octaves = 4;            // fBm octaves (1..12), lacunarity 2, gain 0.5
    int resolution = 128;       // nodes per axis of the cubic grid (8..512)
    float density = 1.0f;       // density inside the cloud, in (0, 1]
    uint64_t seed = 1;          // noise permutation
    glm::vec3 centre{0.0f};     // world position of the sphere's centre, metres
};

// The cloud's surface radius toward world point p (relative to the centre):
//   r_s(p) = R + A * |fbm(p * frequency, octaves)|, p inside where |p| < r_s(p).
// Exposed so tests (and a renderer that wants an analytic cloud) evaluate the published formula.
float pyroclasticSurfaceRadius(const PyroclasticParams& params, const glm::vec3& offsetFromCentre);

// Grid geometry of the cloud: resolution^3 nodes, node 0 and resolution-1 an empty margin on every
// axis, the interior cells covering the cube of half side R + A around the centre.
GridGeometry pyroclasticGeometry(const PyroclasticParams& params);

// The density grid: density * clamp(0.5 + (r_s(p) - |p|) / spacing, 0, 1) at every node p (a one-node
// anti-aliased edge), 0 on the margin; woodFraction all 0 (a medium, not biomass). Deterministic: the
// same parameters give the same bits for any thread count. Throws sylva::Error naming the parameter
// for values out of range (NaN included).
DensityGrid makePyroclasticCloud(const PyroclasticParams& params);

// Throws sylva::Error for parameters out of range (as makePyroclasticCloud).
void validatePyroclastic(const PyroclasticParams& params);

} // namespace sylva::volume
