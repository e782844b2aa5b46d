// Statistics of grids and value arrays: the numbers `sylva voxelize/light/reference/info` print and the
// studio can show. Plain functions over the grids; nothing is printed here.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "core/grid/grid.h"

namespace sylva {

// "XxYxZ", e.g. "24x31x24".
std::string gridDimsText(const GridGeometry& geometry);

struct DensityStats {
    size_t nodes = 0;      // all nodes of the grid
    size_t occupied = 0;   // nodes with density > 0
    size_t brown = 0;      // occupied nodes whose wood fraction is > 0.5 (none without a wood fraction)
    double mean = 0.0;     // mean density over all nodes (0 for an empty grid)
    double occupiedPercent() const { return nodes ? 100.0 * double(occupied) / double(nodes) : 0.0; }
};
DensityStats densityStats(const DensityGrid& grid);

// Per channel (R, G, B) over all nodes of a lighting grid. An empty grid gives zeros.
struct ChannelStats {
    size_t nodes = 0;
    glm::dvec3 mean{0.0};
    glm::dvec3 max{0.0};
};
ChannelStats channelStats(const LightingGrid& grid);

// Minimum, maximum and mean of a flat array (count 0: min +inf, max -inf, mean 0).
struct ValueStats {
    size_t count = 0;
    double min = 0.0, max = 0.0, mean = 0.0;
};
ValueStats valueStats(const std::vector<float>& values);

} // namespace sylva
