// Names of render modes and acceleration structures; sun direction from angles.
#include "core/scene/scene.h"

#include "core/scene/quality.h"

#include <cmath>

namespace sylva {

lb::LbParams defaultSpeciesLighting(const lb::Preset& preset)
{
    lb::LbParams p = lb::paramsFromPreset(preset);
    p.steps = 0;
    p.tolerance = 0.0;
    p.stepsPerEdge = kDefaultStepsPerEdge;
    p.storage = lb::Storage::Fp16;
    return p;
}

const char* renderModeName(RenderMode mode)
{
    switch (mode) {
    case RenderMode::Full: return "full";
    case RenderMode::Local: return "local";
    case RenderMode::Ambient: return "ambient";
    case RenderMode::Lb: return "lb";
    }
    return "full";
}

bool parseRenderMode(const std::string& name, RenderMode* out)
{
    for (RenderMode m : {RenderMode::Full, RenderMode::Local, RenderMode::Ambient, RenderMode::Lb})
        if (name == renderModeName(m)) {
            *out = m;
            return true;
        }
    return false;
}

const char* directLightName(DirectLight d) { return d == DirectLight::Once ? "once" : "seed"; }

bool parseDirectLight(const std::string& name, DirectLight* out)
{
    if (name == "seed") *out = DirectLight::Seed;
    else if (name == "once") *out = DirectLight::Once;
    else return false;
    return true;
}

const char* lbBoundaryName(LbBoundary b) { return b == LbBoundary::SunSky ? "sun_sky" : "sun"; }

bool parseLbBoundary(const std::string& name, LbBoundary* out)
{
    if (name == "sun") *out = LbBoundary::Sun;
    else if (name == "sun_sky") *out = LbBoundary::SunSky;
    else return false;
    return true;
}

const char* forestGridModeName(ForestGridMode m) { return m == ForestGridMode::On ? "on" : m == ForestGridMode::Auto ? "auto" : "off"; }

bool parseForestGridMode(const std::string& name, ForestGridMode* out)
{
    if (name == "off") *out = ForestGridMode::Off;
    else if (name == "auto") *out = ForestGridMode::Auto;
    else if (name == "on") *out = ForestGridMode::On;
    else return false;
    return true;
}

const char* accelName(AccelKind kind) { return kind == AccelKind::KdTree ? "kdtree" : "bvh"; }

bool parseAccel(const std::string& name, AccelKind* out)
{
    if (name == "bvh") *out = AccelKind::Bvh;
    else if (name == "kdtree") *out = AccelKind::KdTree;
    else return false;
    return true;
}

const char* integratorName(Integrator i) { return i == Integrator::Path ? "path" : "lb"; }

bool parseIntegrator(const std::string& name, Integrator* out)
{
    if (name == "lb") *out = Integrator::Lb;
    else if (name == "path") *out = Integrator::Path;
    else return false;
    return true;
}

glm::vec3 sunDirection(double elevationDeg, double azimuthDeg)
{
    const double el = elevationDeg * M_PI / 180.0, az = azimuthDeg * M_PI / 180.0;
    return glm::vec3(float(std::cos(el) * std::sin(az)), float(std::sin(el)), float(std::cos(el) * std::cos(az)));
}

Scene newSceneDefaults()
{
    Scene s;
    s.skyModel.kind = sky::SkyKind::Uniform;
    // The lighting of the `final` preset (docs/ACCURACY.md "Ground truth"): direct light once, the sky in the LB
    // boundary, the grid as a radiance cache after its bounces.
    const QualityPreset* final = findQualityPreset("final");
    s.lighting.direct = final->direct;
    s.lighting.boundary = final->boundary;
    s.lighting.bounces = final->bounces;
    return s;
}

} // namespace sylva
