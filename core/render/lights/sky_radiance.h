// The view's sky as radiance toward a direction: the light (piecewise constant over a map's pixels, the function
// the sky's integrals, virtual lights and sampling table are built from) and the background camera rays see
// (a map filtered to the camera's sample footprint). Host and device.
#pragma once

#include <math.h>

#include <glm/glm.hpp>

#include "core/base/defines.h"
#include "core/render/render_view.h"
#include "core/sky/sky.h"

namespace sylva {

// The view's map: its pixels (and their coarser levels) are the skyMap array (on the device too).
SYLVA_HD SYLVA_INLINE sky::EnvMapView viewSkyMap(const RenderView& v)
{
    sky::EnvMapView m = v.sky.model.map;
    m.rgb = v.skyMap;
    return m;
}

// Radiance of the view's Preetham or map sky (without its sun) toward unit direction d.
SYLVA_HD inline glm::vec3 viewSkyRadiance(const RenderView& v, const glm::vec3& d)
{
    if (v.sky.model.kind == sky::SkyKind::Map) return sky::envMapRadiance(viewSkyMap(v), d);
    return sky::skyRadiance(v.sky.model, d);
}

// The angle (radians) one camera sample covers toward unit direction d: a pixel's angle at the image centre,
// 2 tan(fov_y / 2) / height, times cos^2 of d's angle to the view axis (a pinhole's pixels shrink off-axis),
// over sqrt(spp) (the samples of a pixel share it).
SYLVA_HD SYLVA_INLINE float cameraSampleFootprint(const RenderView& v, const glm::vec3& d)
{
    const float c = glm::dot(d, v.camera.forward);
    return 2.0f * v.camera.tanHalfY / float(v.height > 0 ? v.height : 1) * c * c / sqrtf(float(v.spp > 0 ? v.spp : 1));
}

// What a camera ray that leaves the scene toward unit direction d sees of a Preetham or map sky: a map filtered
// to the sample's footprint (no blocky texels up close, no aliasing from afar), the Preetham sky as it is.
SYLVA_HD inline glm::vec3 viewSkyBackground(const RenderView& v, const glm::vec3& d)
{
    if (v.sky.model.kind == sky::SkyKind::Map) return sky::envMapFiltered(viewSkyMap(v), d, cameraSampleFootprint(v, d));
    return sky::skyRadiance(v.sky.model, d);
}

} // namespace sylva
