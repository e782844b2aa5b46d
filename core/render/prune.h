// Stochastic pruning of leaves for distant plants (Cook et al. 2007, as the graphics-blog post
// "Stochastic Pruning for Real-Time LOD" applies it): area-preserving levels of detail.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "core/mesh/triangle_mesh.h"

namespace sylva {

// Levels 0 .. kMaxPruneLevels-1 keep the fractions U = 1, 1/2, 1/4, ..., 1/32 of a species' leaf elements.
inline constexpr int kMaxPruneLevels = 6;
// A level exists only while it keeps at least this many leaf elements (fewer would not look like foliage).
inline constexpr size_t kMinPrunedElements = 32;
// Seed of the fixed element order (the same mesh gives the same levels on every run and machine).
inline constexpr uint64_t kPruneSeed = 0x5eed0003ull;

// The leaf elements of a mesh: connected components of leaf triangles that share vertex indices (a
// grown leaf card is one element of 2 triangles). Element e owns tris[first[e] .. first[e+1]), in
// ascending triangle order; elements are numbered by their lowest triangle index.
struct LeafElements {
    std::vector<uint32_t> first;        // count() + 1 offsets into tris
    std::vector<uint32_t> tris;         // mesh triangle indices grouped by element
    std::vector<double> area;           // per element, m^2 (species frame)
    std::vector<glm::dvec3> centroid;   // per element, area-weighted (vertex mean for zero area), species frame
    double totalArea = 0.0;
    size_t count() const { return area.size(); }
};
LeafElements findLeafElements(const TriangleMesh& mesh);

// A fixed permutation of 0..n-1 (Fisher-Yates with a splitmix64 generator): the pruning order.
std::vector<uint32_t> pruneOrder(size_t n, uint64_t seed = kPruneSeed);

// Levels the mesh supports: 1 (only the full mesh) up to kMaxPruneLevels; level k exists when
// ceil(N 2^-k) >= kMinPrunedElements.
int pruneLevelCount(const LeafElements& elements);

// One level of detail of a species. Triangles keep their mesh index (shading data, materials and the
// lighting grid stay the species'); only the kept leaf elements' positions change.
struct PrunedLevel {
    int level = 0;                      // kept fraction U = 2^-level
    size_t elements = 0;                // leaf elements kept: the first ceil(N U) of the pruning order
    double areaScale = 1.0;             // factor on each kept element's area: total / kept leaf area (1/U on average)
    std::vector<uint32_t> tris;         // mesh triangle indices: every non-leaf triangle, then the kept leaf triangles
    std::vector<glm::vec3> corners;     // 3 per entry of tris: vertex positions, kept elements scaled about their centroid
};

// Builds level `level` (0 .. pruneLevelCount-1). The kept elements are scaled about their centroids by
// sqrt(areaScale), so the total leaf area equals the full mesh's (to float rounding).
PrunedLevel buildPrunedLevel(const TriangleMesh& mesh, const LeafElements& elements, const std::vector<uint32_t>& order,
                             int level);

// The level an instance at `distance` metres from the camera uses (as in that post): z = max(1, distance /
// start), kept fraction u = z^-log2(h) with h = 2 (half the leaves at twice the start distance), so
// u = 1/z; the level is the nearest kept fraction 2^-k in ratio, k = round(log2 z), at most levels - 1.
// start <= 0 turns pruning off (level 0).
int pruneLevelFor(double distance, double start, int levels);

} // namespace sylva
