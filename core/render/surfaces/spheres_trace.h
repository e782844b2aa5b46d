// The spheres surface kind: analytic ray/sphere tests, one sphere after another (a handful of probes), and
// the Lambertian surface they show (host and device). Hit: prim = the sphere (RenderView::sphereRecords).
#pragma once

#include "core/render/surfaces/mesh_trace.h"

namespace sylva {

namespace trace_detail {

template <bool AnyHit, bool Kd>
SYLVA_HD inline bool traceSpheres(Query& q, const Ray& ray, float& tmax)
{
    const RenderView& v = q.v;
    if (v.spheres.count == 0) return false;
    const float a = glm::dot(ray.dir, ray.dir);
    if (!(a > 0.0f)) return false;
    for (uint32_t i = 0; i < v.spheres.count; ++i) {
        const SphereRecord& sp = v.sphereRecords[i];
        // |o + t d - c|^2 = r^2 with b = (o - c).d, c' = |o - c|^2 - r^2: t = (-b -+ sqrt(b^2 - a c')) / a.
        const glm::vec3 oc = ray.org - sp.centre;
        const float b = glm::dot(oc, ray.dir), c = glm::dot(oc, oc) - sp.radius * sp.radius;
        const float disc = b * b - a * c;
        if (!(disc >= 0.0f)) continue;
        const float root = sqrtf(disc);
        float t = (-b - root) / a;
        if (!(t > ray.tmin)) t = (-b + root) / a;   // the origin inside: the far side
        if (!(t > ray.tmin && t < tmax)) continue;
        if (AnyHit) return true;
        tmax = t;
        q.hit.kind = uint16_t(SurfaceKind::Spheres);
        q.hit.prim = i;
        q.hit.t = t;
        q.hit.u = q.hit.v = 0.0f;
    }
    return false;
}

} // namespace trace_detail

// Lambertian, the normal facing the viewer, lit like the ground (the lights and the uniform sky's ambient).
SYLVA_HD inline void shadeSpheres(const RenderView& v, const Ray&, const Hit& hit, SurfacePoint& s)
{
    const SphereRecord& sp = v.sphereRecords[hit.prim];
    s.ground = true;
    glm::vec3 n = (s.p - sp.centre) / sp.radius;
    n = glm::normalize(n);
    s.ng = glm::dot(n, s.viewDir) < 0.0f ? -n : n;
    s.albedo = sp.albedo;
    s.extent = fmaxf(fmaxf(fabsf(sp.centre.x), fabsf(sp.centre.y)), fabsf(sp.centre.z)) + sp.radius;
}

} // namespace sylva
