// The quality presets and how they set a scene.
#include "core/scene/quality.h"

#include "core/base/error.h"

namespace sylva {

const std::vector<QualityPreset>& qualityPresets()
{
    // From the fronts in docs/ACCURACY.md: LB on the real tree and the dense tree (fixed steps of
    // 1 x the longest edge in fp16 are the cheapest solve at their error at every grid), render on the
    // default forest (preview: 1 spp with leaf cut-outs skipped beyond 25 m, the fastest point of the
    // front; pruning is on no front there: it costs trace time on this forest); the lighting from the ground
    // truth against Cycles ("Ground truth"): the LB grid as a radiance cache after 2 bounces with the sky in its
    // boundary is within the references' noise of converged Cycles on all four scenes, at 64 spp 1.5-3.8% from
    // it; after 1 bounce the same at 1 spp (the noise dominates there); reference: the path tracer. No preset shares
    // the bounces (render.bounce_samples): a quarter of 100 samples tracing them errs as little as 64 whole samples on
    // the stand and the forest crop in 0.8-0.86x their time, but 1.8x as much on the study's close single tree, where
    // the bounced light's own noise, not the pixels' geometry, is the error (docs/RENDERING.md "Bounce samples").
    static const std::vector<QualityPreset> presets{
        {"preview", 32, "half", true, 1, 25.0f, 0.0f, Integrator::Lb, 1, DirectLight::Once, LbBoundary::SunSky, true, 0},
        {"final", 64, "half", true, 64, 0.0f, 0.0f, Integrator::Lb, 2, DirectLight::Once, LbBoundary::SunSky, true, 0},
        {"reference", 128, "half", true, 256, 0.0f, 0.0f, Integrator::Path, 0, DirectLight::Once, LbBoundary::SunSky, true, 0},
    };
    return presets;
}

const QualityPreset* findQualityPreset(const std::string& name)
{
    for (const QualityPreset& q : qualityPresets())
        if (name == q.name) return &q;
    return nullptr;
}

std::string qualityPresetSettings(const QualityPreset& q)
{
    auto dist = [](float m) { return m > 0.0f ? std::to_string(int(m)) + " m" : std::string("off"); };
    return "grid " + std::to_string(q.grid) + ", " + q.steps + ", " + (q.fp16 ? "fp16" : "fp32") + ", " + std::to_string(q.spp) +
           " spp, alpha " + dist(q.alphaDistance) + ", prune " + dist(q.pruneDistance) + ", " + integratorName(q.integrator) + ", " +
           std::to_string(q.bounces) + " bounces, direct " + directLightName(q.direct) + ", boundary " + lbBoundaryName(q.boundary) +
           (q.aerialPerspective ? ", aerial perspective on terrains" : "") +
           (q.bounceSamples > 0 ? ", " + std::to_string(q.bounceSamples) + " bounce samples" : std::string());
}

void applyQualityLighting(const QualityPreset& preset, lb::LbParams& params)
{
    const std::string steps = preset.steps;
    params.steps = 0;
    params.tolerance = 0.0;
    if (steps == "half") params.stepsPerEdge = 1;
    else if (steps == "default") params.stepsPerEdge = 2;
    else if (steps == "tol 1e-3") params.tolerance = 1e-3;
    else if (steps == "tol 1e-4") params.tolerance = 1e-4;
    else throw Error(std::string("quality preset ") + preset.name + ": unknown steps '" + steps + "'");
    params.storage = preset.fp16 ? lb::Storage::Fp16 : lb::Storage::Fp32;
}

void applyQuality(Scene& scene, const QualityPreset& preset)
{
    for (SpeciesDesc& sp : scene.species) {
        sp.grid = preset.grid;
        applyQualityLighting(preset, sp.lighting);
    }
    scene.render.spp = preset.spp;
    scene.render.bounceSamples = preset.bounceSamples;
    scene.render.alphaDistance = preset.alphaDistance;
    scene.render.pruneDistance = preset.pruneDistance;
    scene.render.integrator = preset.integrator;
    scene.lighting.bounces = preset.bounces;
    scene.lighting.direct = preset.direct;
    scene.lighting.boundary = preset.boundary;
    if (scene.terrain.enabled()) scene.skyModel.aerialPerspective = preset.aerialPerspective;
}

} // namespace sylva
