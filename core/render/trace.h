// Ray queries over the kinds (core/render/surfaces/surface_list.h): each surface kind asked in the list's
// order below the closest hit so far, and what the media let through (host and device).
#pragma once

#include "core/render/surfaces/atmosphere_trace.h"
#include "core/render/surfaces/ground_trace.h"
#include "core/render/surfaces/instances_trace.h"
#include "core/render/surfaces/landscape_trace.h"
#include "core/render/surfaces/spheres_trace.h"
#include "core/render/surfaces/terrain_trace.h"
#include "core/render/surfaces/volumes_trace.h"

namespace sylva {

SYLVA_HD SYLVA_INLINE SurfaceKind hitKind(const Hit& hit) { return SurfaceKind(hit.kind); }

// The map from the camera-relative world frame to the frame of the mesh a hit is on (instances and landscape
// plants), with its mesh geometry and the total scale.
SYLVA_HD inline InstanceRecord hitInstance(const RenderView& v, const Hit& hit)
{
    if (hitKind(hit) == SurfaceKind::Landscape) return trace_detail::landPlantInstance(v, hit.nested[0], hit.nested[1]);
    return instancesHitMap(v, hit);
}

namespace trace_detail {

// Starts a query: no hit yet, the ray's whole extent.
SYLVA_HD SYLVA_INLINE void startHit(Hit& hit)
{
    hit.prim = kNoHit;
    hit.inst = kNoHit;
    hit.depth = 0;
    hit.kind = uint16_t(SurfaceKind::None);
}

} // namespace trace_detail

// Closest hit along the ray (camera-relative world frame) over every surface kind in the list's order, meshes
// traced through their BVHs (Kd = false) or kd-trees (Kd = true; groups and the top level always use BVHs).
// AnyHit stops at the first accepted hit (shadow rays). Cut-outs are tested up to alphaTestLimit. Returns true
// on a hit.
template <bool AnyHit, bool Kd>
SYLVA_HD inline bool traceSurfaces(const RenderView& v, const Ray& ray, Hit& hit)
{
    trace_detail::startHit(hit);
    float tmax = ray.tmax;
    trace_detail::Query q{v, ray.tmin, alphaTestLimit(v, ray), hit, SurfaceKind::None, {}};
#define SYLVA_X(Kind) \
    if (trace_detail::trace##Kind<AnyHit, Kd>(q, ray, tmax) && AnyHit) return true;
    SYLVA_SURFACE_KINDS(SYLVA_X, SYLVA_KIND_SKIP)
#undef SYLVA_X
    return AnyHit ? false : hit.kind != uint16_t(SurfaceKind::None);
}

// The query the shading code calls: dispatches on the acceleration structure of the run.
template <bool AnyHit>
SYLVA_HD SYLVA_INLINE bool traceScene(const RenderView& v, const Ray& ray, Hit& hit)
{
    if (v.accel == AccelKind::KdTree) return traceSurfaces<AnyHit, true>(v, ray, hit);
    return traceSurfaces<AnyHit, false>(v, ray, hit);
}

// A hit's surface point: the kind that recorded it shades it.
SYLVA_HD inline SurfacePoint surfaceAt(const RenderView& v, const Ray& ray, const Hit& hit)
{
    SurfacePoint s{};
    s.p = ray.org + hit.t * ray.dir;
    s.viewDir = glm::normalize(-ray.dir);
    switch (hitKind(hit)) {
#define SYLVA_X(Kind) \
    case SurfaceKind::Kind: shade##Kind(v, ray, hit, s); break;
        SYLVA_SURFACE_KINDS(SYLVA_X, SYLVA_KIND_SKIP)
#undef SYLVA_X
    case SurfaceKind::None: break;
    }
    return s;
}

// What gets through every medium kind along the shadow ray org + t dir, t in [0, tmax], per channel.
SYLVA_HD inline glm::vec3 mediaTransmittance(const RenderView& v, const glm::vec3& org, const glm::vec3& dir, float tmax = 1e30f)
{
    glm::vec3 t(1.0f);
#define SYLVA_X(Kind) t *= transmittance##Kind(v, org, dir, tmax);
    SYLVA_SURFACE_KINDS(SYLVA_KIND_SKIP, SYLVA_X)
#undef SYLVA_X
    return t;
}

} // namespace sylva
