// Regular 3D grids of the LB model: node placement, density (+ wood fraction) and RGB lighting.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

namespace sylva {

// Node (i,j,k) sits at origin + spacing * (i,j,k), world metres. 32 bytes.
struct GridGeometry {
    glm::ivec3 dims{0};        // nodes per axis, each >= 3
    glm::dvec3 origin{0.0};    // world position of node (0,0,0), metres
    double spacing = 1.0;      // node distance, metres

    size_t nodeCount() const { return size_t(dims.x) * size_t(dims.y) * size_t(dims.z); }
    // Linear node index, z fastest (the storage order of every grid and of the .npy files).
    size_t index(int i, int j, int k) const { return (size_t(i) * size_t(dims.y) + size_t(j)) * size_t(dims.z) + size_t(k); }
    int longestEdge() const { return glm::max(dims.x, glm::max(dims.y, dims.z)); }
    bool operator==(const GridGeometry&) const = default;
};

// Medium density rho in [0,1] and wood fraction in [0,1] per node (z fastest).
struct DensityGrid {
    GridGeometry geometry;
    std::vector<float> density;
    std::vector<float> woodFraction;   // share of the node's marked sub-cells touched by wood
};

// Total photon density per node and channel: index = node * 3 + channel (shape X,Y,Z,3).
struct LightingGrid {
    GridGeometry geometry;
    std::vector<float> rgb;
    float at(int i, int j, int k, int c) const { return rgb[geometry.index(i, j, k) * 3 + size_t(c)]; }
};

} // namespace sylva
