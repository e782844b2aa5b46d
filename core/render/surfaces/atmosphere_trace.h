// The atmosphere kind's crossing (aerial perspective, atmosphere.h): the camera ray's segment to the surface it
// hit dims that surface's light by the air's transmittance and adds the air's own light, the sky toward the
// horizon under the ray x (1 - T). Shadow rays pass unchanged: the sun's light on every slope already comes
// through the air above it (the Preetham sun's transmittance, core/sky/preetham.h).
#pragma once

#include <glm/glm.hpp>

#include "core/accel/ray.h"
#include "core/base/defines.h"
#include "core/render/lights/sky_radiance.h"
#include "core/render/render_view.h"
#include "core/render/surface_point.h"
#include "core/render/surfaces/atmosphere.h"

namespace sylva {

// The sky's radiance toward the horizon under unit direction dir: what a ray that never ends sees there (a map
// filtered over kHorizonFootprint: the air's light is gathered from many directions, not one texel's).
SYLVA_HD SYLVA_INLINE glm::vec3 atmosphereHorizon(const RenderView& v, const glm::vec3& dir)
{
    switch (v.sky.model.kind) {
    case sky::SkyKind::Constant: return v.sky.constant;
    case sky::SkyKind::Map: return sky::envMapFiltered(viewSkyMap(v), horizonDirection(dir, kHorizonMinY), kHorizonFootprint);
    default: return sky::skyRadiance(v.sky.model, horizonDirection(dir, 0.0f));
    }
}

SYLVA_HD inline void crossAtmosphere(const RenderView& v, const Ray& ray, float tEnd, SampleParts& parts)
{
    if (!v.atmosphere.enabled || !(tEnd < kAtmosphereSkyDistance)) return;
    const float y0 = v.atmosphere.cameraY + ray.org.y + ray.tmin * ray.dir.y;
    const glm::vec3 T = atmosphereTransmittance(v.atmosphere, y0, ray.dir, tEnd - ray.tmin);
    parts.local *= T;
    parts.indirect = parts.indirect * T + (glm::vec3(1.0f) - T) * atmosphereHorizon(v, ray.dir);
    parts.albedo *= T;
}

SYLVA_HD SYLVA_INLINE glm::vec3 transmittanceAtmosphere(const RenderView&, const glm::vec3&, const glm::vec3&, float) { return glm::vec3(1.0f); }

} // namespace sylva
