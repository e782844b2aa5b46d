// The ground plane surface kind: its ray query and its surface (host and device). Hit: t only.
#pragma once

#include "core/render/surfaces/mesh_trace.h"

namespace sylva {

namespace trace_detail {

template <bool AnyHit, bool Kd>
SYLVA_HD SYLVA_INLINE bool traceGround(Query& q, const Ray& ray, float& tmax)
{
    const GroundRecord& g = q.v.ground;
    if (!g.enabled || ray.dir.y == 0.0f) return false;
    const float tg = (g.y - ray.org.y) / ray.dir.y;
    if (!(tg > ray.tmin && tg < tmax)) return false;
    if (AnyHit) return true;
    tmax = tg;
    q.hit.kind = uint16_t(SurfaceKind::Ground);
    q.hit.t = tg;
    q.hit.u = q.hit.v = 0.0f;
    return false;
}

} // namespace trace_detail

// Lambertian, facing the viewer.
SYLVA_HD SYLVA_INLINE void shadeGround(const RenderView& v, const Ray& ray, const Hit&, SurfacePoint& s)
{
    s.ground = true;
    s.ng = glm::vec3(0.0f, ray.dir.y < 0.0f ? 1.0f : -1.0f, 0.0f);
    s.albedo = v.ground.color;
}

} // namespace sylva
