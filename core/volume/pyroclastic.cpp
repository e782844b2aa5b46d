// Pyroclastic cloud grid: one noise-displaced sphere, evaluated per node in parallel (no reductions).
#include "core/volume/pyroclastic.h"

#include <algorithm>
#include <cmath>
#include <string>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "core/base/error.h"
#include "core/volume/noise.h"

namespace sylva::volume {
namespace {

void require(bool ok, const std::string& what)
{
    if (!ok) throw Error("volume cloud: " + what);
}

} // namespace

void validatePyroclastic(const PyroclasticParams& p)
{
    const std::string context = "volume cloud";
    checkParam(kCloudRadius, p.radius, context);
    checkParam(kCloudAmplitude, p.amplitude, context);
    checkParam(kCloudFrequency, p.frequency, context);
    checkParam(kCloudOctaves, p.octaves, context);
    checkParam(kCloudResolution, p.resolution, context);
    checkParam(kCloudDensity, p.density, context);
    checkParam(kCloudSeed, p.seed, context);
    require(std::isfinite(p.centre.x) && std::isfinite(p.centre.y) && std::isfinite(p.centre.z), "centre must be finite");
}

float pyroclasticSurfaceRadius(const PyroclasticParams& params, const glm::vec3& d)
{
    const PerlinNoise noise(params.seed);   // a 256-entry shuffle: cheap beside a caller's loop
    return params.radius + params.amplitude * std::fabs(noise.fbm(d * params.frequency, params.octaves));
}

GridGeometry pyroclasticGeometry(const PyroclasticParams& p)
{
    GridGeometry g;
    g.dims = glm::ivec3(p.resolution);
    const double half = double(p.radius) + double(p.amplitude);
    g.spacing = 2.0 * half / double(p.resolution - 2);
    g.origin = glm::dvec3(p.centre) - 0.5 * g.spacing * glm::dvec3(g.dims - 1);
    return g;
}

DensityGrid makePyroclasticCloud(const PyroclasticParams& p)
{
    validatePyroclastic(p);
    DensityGrid grid;
    grid.geometry = pyroclasticGeometry(p);
    const GridGeometry& g = grid.geometry;
    grid.density.assign(g.nodeCount(), 0.0f);
    grid.woodFraction.assign(g.nodeCount(), 0.0f);
    const PerlinNoise noise(p.seed);
    const int n = p.resolution;
    const float spacing = float(g.spacing);
    const double c = 0.5 * double(n - 1);
    tbb::parallel_for(tbb::blocked_range<int>(1, n - 1), [&](const tbb::blocked_range<int>& r) {
        for (int i = r.begin(); i != r.end(); ++i)
            for (int j = 1; j < n - 1; ++j)
                for (int k = 1; k < n - 1; ++k) {
                    const glm::vec3 d(float((double(i) - c) * g.spacing), float((double(j) - c) * g.spacing),
                                      float((double(k) - c) * g.spacing));
                    const float rs = p.radius + p.amplitude * std::fabs(noise.fbm(d * p.frequency, p.octaves));
                    const float t = std::clamp(0.5f + (rs - glm::length(d)) / spacing, 0.0f, 1.0f);
                    grid.density[g.index(i, j, k)] = p.density * t;
                }
    });
    return grid;
}

} // namespace sylva::volume
