// Virtual directional lights from an environment map (Dietrich, Marmitt & Slusallek, "Terrain Guided
// Multi-Level Instancing of Highly Complex Plant Populations", section 5.1, after Agarwal et al. 2003 and
// Kollig & Keller 2003, simplified): the sphere cut into N regions of roughly equal power by recursive median
// splits of the cumulative luminance power in latitude-longitude, each region one directional light at its
// power-weighted centre carrying the region's power. And interleaved sampling (Keller & Heidrich 2001): which
// of those lights pixel (x, y) uses for its sample s.
#pragma once

#include <vector>

#include <glm/glm.hpp>

#include "core/base/defines.h"
#include "core/sky/env_map.h"

namespace sylva::sky {

// One directional light: `power` is the region's radiance integrated over its solid angle (RGB, the
// sky's unit x sr), i.e. the irradiance it gives a surface facing `direction` (the same meaning as
// SkySun::radiance()). A diffuse surface of albedo a and normal n receives a / pi x power x max(0, n.direction).
struct VirtualLight {
    glm::vec3 direction{0.0f, 1.0f, 0.0f};   // unit, toward the region (world: the map's rotation applied)
    glm::vec3 power{0.0f};
    float solidAngle = 0.0f;                 // sr, of the region
};

inline constexpr int kMinVirtualLights = 1, kMaxVirtualLights = 65536;

// Splits `map` (its sun already taken out, see extractSun) into `count` regions of about equal luminance
// power. A region is split across its longer angular side (width measured at its middle latitude) at the
// row or column where the cumulative power reaches its share (left n/2 of n lights, rounded down); a
// region of zero power splits in the middle; a single pixel is not split further, so fewer than `count`
// lights can come back (only for maps with single pixels holding more than 1/count of the power). The
// lights come back in the tree's order, so neighbours in the list are neighbours on the sphere; their
// powers sum to envMapIntegral(map) x intensity (up to float rounding). Rotation: about +Y, degrees, as
// envMapView. upperOnly: only the rows above the horizon (pixel centres with y > 0) are partitioned, so every
// light lies above it and the powers sum to the upper hemisphere's integral: the sky a scene with a ground
// plane can see (every direction below the horizon ends on the ground), all `count` lights spent on it; a map
// with no row above the horizon (height 1) is partitioned whole. Throws sylva::Error for count outside
// 1 .. 65536 or a bad map.
std::vector<VirtualLight> virtualLights(const EnvMap& map, int count, float rotationDeg = 0.0f, float intensity = 1.0f,
                                        bool upperOnly = false);

// Interleaved sampling over K subsets: subset j holds lights j, j + K, j + 2K, ... (every K-th in the
// tree's order, so each subset spreads over the whole sky). Pixels are grouped in blocks of
// blockWidth x blockHeight = K; the pixel at (x mod blockWidth, y mod blockHeight) of each block uses
// subset (that index + s) mod K for its sample s, so a block of K pixels uses all lights in every sample,
// and one pixel uses all of them over K successive samples (progressive refinement). Each light of a
// subset is weighted by K (weight()), which keeps the estimate unbiased: the mean over the K subsets of
// K x (sum over the subset) is the sum over all lights.
struct Interleave {
    int subsets = 1;                       // K >= 1
    int blockWidth = 1, blockHeight = 1;   // blockWidth x blockHeight == subsets
};

// K subsets in a block as square as K's divisors allow (blockWidth the largest divisor <= sqrt(K)).
// K is clamped to 1 .. lightCount (and to >= 1 when there are no lights).
Interleave makeInterleave(int subsets, int lightCount);

// The subset pixel (x, y) uses for its sample s (x, y, s >= 0).
SYLVA_HD inline int interleavedSubset(const Interleave& il, int x, int y, int s)
{
    const int bx = x % il.blockWidth, by = y % il.blockHeight;
    return (bx + by * il.blockWidth + s) % il.subsets;
}

// Number of lights in a subset, and the index (into the light list) of its k-th light.
SYLVA_HD inline int subsetSize(const Interleave& il, int subset, int lightCount)
{
    return subset < lightCount ? (lightCount - subset + il.subsets - 1) / il.subsets : 0;
}
SYLVA_HD inline int subsetLight(const Interleave& il, int subset, int k) { return subset + k * il.subsets; }
SYLVA_HD inline float interleaveWeight(const Interleave& il) { return float(il.subsets); }

} // namespace sylva::sky
