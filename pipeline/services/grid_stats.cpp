// Statistics of grids and value arrays (grid_stats.h).
#include "pipeline/services/grid_stats.h"

#include <algorithm>
#include <limits>

namespace sylva {

std::string gridDimsText(const GridGeometry& geometry)
{
    return std::to_string(geometry.dims.x) + "x" + std::to_string(geometry.dims.y) + "x" + std::to_string(geometry.dims.z);
}

DensityStats densityStats(const DensityGrid& grid)
{
    DensityStats s;
    s.nodes = grid.density.size();
    const bool wood = grid.woodFraction.size() == grid.density.size();
    double sum = 0.0;
    for (size_t n = 0; n < grid.density.size(); ++n) {
        const float d = grid.density[n];
        sum += d;
        s.occupied += d > 0.0f;
        s.brown += wood && d > 0.0f && grid.woodFraction[n] > 0.5f;
    }
    s.mean = s.nodes ? sum / double(s.nodes) : 0.0;
    return s;
}

ChannelStats channelStats(const LightingGrid& grid)
{
    ChannelStats s;
    s.nodes = grid.rgb.size() / 3;
    if (s.nodes == 0) return s;
    glm::dvec3 sum(0.0), hi(-std::numeric_limits<double>::infinity());
    for (size_t n = 0; n < s.nodes; ++n)
        for (int c = 0; c < 3; ++c) {
            const double v = grid.rgb[n * 3 + size_t(c)];
            sum[c] += v;
            hi[c] = std::max(hi[c], v);
        }
    s.mean = sum / double(s.nodes);
    s.max = hi;
    return s;
}

ValueStats valueStats(const std::vector<float>& values)
{
    ValueStats s;
    s.count = values.size();
    s.min = std::numeric_limits<double>::infinity();
    s.max = -std::numeric_limits<double>::infinity();
    double sum = 0.0;
    for (float v : values) {
        s.min = std::min(s.min, double(v));
        s.max = std::max(s.max, double(v));
        sum += v;
    }
    s.mean = s.count ? sum / double(s.count) : 0.0;
    return s;
}

} // namespace sylva
