// scatterInstances: splitmix64 draws -> positions, rotations and scales.
#include "pipeline/scene/scatter.h"

#include <cmath>
#include <string>

#include "core/base/error.h"
#include "core/base/splitmix.h"

namespace sylva {

std::vector<InstanceDesc> scatterInstances(const ScatterSpec& spec)
{
    if (spec.count < 0) throw Error("scatter: count " + std::to_string(spec.count) + " is negative");
    if (!std::isfinite(spec.min.x) || !std::isfinite(spec.min.y) || !std::isfinite(spec.max.x) || !std::isfinite(spec.max.y) ||
        !std::isfinite(spec.height))
        throw Error("scatter: the area and height must be finite");
    if (spec.min.x > spec.max.x || spec.min.y > spec.max.y) throw Error("scatter: the area's min corner lies beyond its max corner");
    if (!(spec.scaleMin > 0.0f) || !(spec.scaleMax >= spec.scaleMin) || !std::isfinite(spec.scaleMax))
        throw Error("scatter: the scale range must satisfy 0 < min <= max");
    if (!std::isfinite(spec.clearRadius) || spec.clearRadius < 0.0 || !std::isfinite(spec.clearCentre.x) ||
        !std::isfinite(spec.clearCentre.y))
        throw Error("scatter: the clearance must be a finite radius >= 0 about a finite point");
    const double r2 = spec.clearRadius * spec.clearRadius;
    auto inClearance = [&](double x, double z) {
        const double dx = x - spec.clearCentre.x, dz = z - spec.clearCentre.y;
        return spec.clearRadius > 0.0 && dx * dx + dz * dz < r2;
    };
    if (spec.count > 0 && inClearance(spec.min.x, spec.min.y) && inClearance(spec.min.x, spec.max.y) &&
        inClearance(spec.max.x, spec.min.y) && inClearance(spec.max.x, spec.max.y))
        throw Error("scatter: the whole area lies within " + std::to_string(spec.clearRadius) + " m of the point kept clear");
    SplitMix64 rng{spec.seed};
    std::vector<InstanceDesc> out;
    out.reserve(size_t(spec.count));
    for (int k = 0; k < spec.count; ++k) {
        double u = rng.unit(), v = rng.unit();
        const double r = rng.unit(), s = rng.unit();
        auto x = [&] { return spec.min.x + u * (spec.max.x - spec.min.x); };
        auto z = [&] { return spec.min.y + v * (spec.max.y - spec.min.y); };
        int tries = 1;
        for (; inClearance(x(), z()) && tries < kScatterClearTries; ++tries) {
            u = rng.unit();
            v = rng.unit();
        }
        if (inClearance(x(), z())) continue;   // left out: the caller reports the shortfall
        InstanceDesc& in = out.emplace_back();
        in.species = spec.species;
        in.position = {x(), spec.height, z()};
        in.rotationDeg = {0.0f, spec.randomRotation ? float(360.0 * r) : 0.0f, 0.0f};
        if (in.rotationDeg.y >= 360.0f) in.rotationDeg.y = 0.0f;   // float rounding of 360 * (1 - 2^-53)
        in.scale = spec.scaleMin + float(s) * (spec.scaleMax - spec.scaleMin);
        in.scale = std::min(std::max(in.scale, spec.scaleMin), spec.scaleMax);
    }
    return out;
}

} // namespace sylva
