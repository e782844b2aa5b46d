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
    SplitMix64 rng{spec.seed};
    std::vector<InstanceDesc> out(size_t(spec.count));
    for (InstanceDesc& in : out) {
        const double u = rng.unit(), v = rng.unit(), r = rng.unit(), s = rng.unit();
        in.species = spec.species;
        in.position = {spec.min.x + u * (spec.max.x - spec.min.x), spec.height, spec.min.y + v * (spec.max.y - spec.min.y)};
        in.rotationDeg = {0.0f, spec.randomRotation ? float(360.0 * r) : 0.0f, 0.0f};
        if (in.rotationDeg.y >= 360.0f) in.rotationDeg.y = 0.0f;   // float rounding of 360 * (1 - 2^-53)
        in.scale = spec.scaleMin + float(s) * (spec.scaleMax - spec.scaleMin);
        in.scale = std::min(std::max(in.scale, spec.scaleMin), spec.scaleMax);
    }
    return out;
}

} // namespace sylva
