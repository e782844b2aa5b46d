// Comparing lighting grids: the relative L2 difference used by tests, benchmarks and accuracy studies.
#pragma once

#include <cmath>

#include "core/grid/grid.h"

namespace sylva {

// ||a - b||_2 / ||b||_2 over all nodes and channels (b is the reference); 0 when both are zero.
inline double relativeL2(const LightingGrid& a, const LightingGrid& b)
{
    double diff = 0.0, norm = 0.0;
    for (size_t n = 0; n < a.rgb.size() && n < b.rgb.size(); ++n) {
        const double d = double(a.rgb[n]) - double(b.rgb[n]);
        diff += d * d;
        norm += double(b.rgb[n]) * double(b.rgb[n]);
    }
    return norm > 0.0 ? std::sqrt(diff / norm) : std::sqrt(diff);
}

} // namespace sylva
