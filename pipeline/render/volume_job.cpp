// LB lighting and blackbody tables of a scene's volumes.
#include "pipeline/render/volume_job.h"

#include "core/base/error.h"
#include "core/color/color.h"
#include "core/lb/lb_solver.h"
#include "pipeline/render/render_job.h"

namespace sylva {

lb::LbParams volumeLightingParams(const Scene& scene, const VolumeDesc& v)
{
    lb::LbParams p = v.lighting;
    p.sun = lbSunDirection(scene);
    p.steps = 0;
    p.tolerance = 0.0;
    return p;
}

std::vector<glm::vec3> volumeBlackbodyTable()
{
    const CieTable& cie = bundledCieTable();
    const double y6500 = blackbodyXyz(6500.0, cie).y;
    std::vector<glm::vec3> out(static_cast<size_t>(kVolumeBlackbodySize));
    for (int i = 0; i < kVolumeBlackbodySize; ++i) {
        const double k = double(kVolumeBlackbodyLo) + (double(kVolumeBlackbodyHi) - double(kVolumeBlackbodyLo)) * i / (kVolumeBlackbodySize - 1);
        const glm::dvec3 rgb = glm::max(xyzToLinearSrgb(blackbodyXyz(k, cie)), glm::dvec3(0.0)) / y6500;
        out[size_t(i)] = glm::vec3(rgb);
    }
    return out;
}

Scene lightSceneVolumes(const Scene& scene, GridCache* cache, bool needLighting, Progress* progress, JobLog* log, Backend* backend)
{
    Scene s = scene;
    const size_t n = s.volumes.size();
    for (size_t i = 0; i < n; ++i) {
        VolumeDesc& v = s.volumes[i];
        if (!v.data) throw Error("volume '" + v.name + "': its grid was not loaded");
        auto data = std::make_shared<VolumeData>(*v.data);
        if (!data->temperature.empty()) data->blackbody = volumeBlackbodyTable();
        if (needLighting && v.lit) {
            SubProgress part(progress, double(i) / double(n), double(i + 1) / double(n));
            Progress sub([&](double f, const std::string& msg) { part.report(f, v.name + ": " + msg); });
            if (progress && progress->isCancelled()) sub.cancel();
            const lb::LbParams p = volumeLightingParams(s, v);
            JobLog own;
            try {
                // lighting.boundary sun_sky: the sky in the volume's boundary too, in the species' units.
                const std::optional<lb::BoundaryWeights> w = speciesBoundary(s, p);
                data->lighting = w ? lightingForWeights(data->density, p, *w, cache, &sub, &own, backend)
                                   : lightingFor(data->density, p, cache, &sub, &own, backend);
            } catch (const Error& e) {   // e.g. sigma_t over the LB's stability bound: name the volume
                throw Error("volume '" + v.name + "': " + e.what() + " (the LB solve of tracers lb and combined; single needs none)");
            }
            if (log) {
                for (const auto& st : own.stages) log->stages.push_back(v.name + ": " + st);
                for (const auto& w : own.warnings) log->warnings.push_back(v.name + ": " + w);
            }
            data->lightingNorm = sunFreeField(p);
        } else {
            data->lighting = LightingGrid{};
        }
        v.data = std::move(data);
    }
    return s;
}

} // namespace sylva
