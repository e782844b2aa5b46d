// Lighting grids compared value by value (every channel of every node). sylva_core only, so the CORE tests use it too.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>

#include "core/grid/grid.h"

namespace sylva::test {

// The relative L2 distance of a from the reference b: |a - b| / |b| over all values.
inline double relL2(const LightingGrid& a, const LightingGrid& b)
{
    double d = 0.0, n = 0.0;
    for (size_t i = 0; i < a.rgb.size(); ++i) {
        d += double(a.rgb[i] - b.rgb[i]) * double(a.rgb[i] - b.rgb[i]);
        n += double(b.rgb[i]) * double(b.rgb[i]);
    }
    return std::sqrt(d / n);
}

// The largest |a - b| over all values.
inline double maxAbs(const LightingGrid& a, const LightingGrid& b)
{
    double m = 0.0;
    for (size_t i = 0; i < a.rgb.size(); ++i) m = std::max(m, double(std::fabs(a.rgb[i] - b.rgb[i])));
    return m;
}

} // namespace sylva::test
