// The instances surface kind: the scene's top-level instances under their BVH, each a mesh or a group of
// further instances (GeometryKind; groups nest up to kMaxLevels - 1 deep), and what a hit on a mesh through
// them shows (host and device). Hit: prim = the triangle, inst = the top-level instance, depth and nested =
// the group instances below it.
#pragma once

#include "core/render/surfaces/mesh_trace.h"

namespace sylva {

namespace trace_detail {

// The instances of one level (the top level, or a group at `Depth` > 0) under their BVH: each entered
// instance maps the ray into its geometry's frame and descends into it. The chain of levels is bounded at
// compile time (kMaxLevels); the builder refuses deeper nesting. Returns true when an any-hit query found a hit.
template <bool AnyHit, bool Kd, int Depth>
SYLVA_HD inline bool traceLevel(Query& q, const BvhNode* nodes, const BvhNode8* wideNodes, const uint32_t* order,
                                const InstanceRecord* instances, const glm::vec3& o,
                                const glm::vec3& d, float& tmax)
{
    const RenderView& v = q.v;
    auto instanceFn = [&](uint32_t slot, float& t) {
        const uint32_t index = order[slot];
        const InstanceRecord& in = instances[index];
        q.path[Depth] = index;
        const glm::vec3 lo = toLocalPoint(in, o), ld = toLocalDir(in, d);
        const GeometryRecord& geo = v.geometries[in.geometry];
        if (geo.kind == GeometryKind::Mesh) return traceMesh<AnyHit, Kd, Depth>(q, geo, lo, ld, t);
        if constexpr (Depth + 1 < kMaxLevels) {
            if (geo.kind == GeometryKind::Group)
                return traceLevel<AnyHit, Kd, Depth + 1>(q, v.groupNodes + geo.nodeOffset,
                                                         v.groupWideNodes ? v.groupWideNodes + geo.wideNodeOffset : nullptr,
                                                         v.groupOrder + geo.primOffset, v.groupInstances, lo, ld, t);
        }
        return false;
    };
#if !defined(__CUDACC__)
    if (wideNodes) return traverseBvh(BvhView8{wideNodes}, o, d, q.tmin, tmax, instanceFn);
#else
    (void)wideNodes;
#endif
    return traverseBvh(BvhView{nodes}, o, d, q.tmin, tmax, instanceFn);
}


// The kind's query: the top level's instances below the closest hit so far (tmax).
template <bool AnyHit, bool Kd>
SYLVA_HD inline bool traceInstances(Query& q, const Ray& ray, float& tmax)
{
    const RenderView& v = q.v;
    if (v.instanceCount == 0) return false;
    q.kind = SurfaceKind::Instances;
    return traceLevel<AnyHit, Kd, 0>(q, v.tlasNodes, v.tlasWideNodes, v.tlasOrder, v.instances, ray.org, ray.dir, tmax);
}

} // namespace trace_detail

// The hit's instances along its path composed into one map from the camera-relative world frame to the hit
// mesh's frame, with its mesh geometry and the total scale.
SYLVA_HD inline InstanceRecord instancesHitMap(const RenderView& v, const Hit& hit)
{
    InstanceRecord m = v.instances[hit.inst];
    for (uint32_t k = 0; k < hit.depth && k < uint32_t(kMaxNested); ++k) m = composeInstances(v.groupInstances[hit.nested[k]], m);
    return m;
}

// The forest-level grid's factor on instance `in`'s species lighting at species-frame point lp (1 where the
// instance has none): its per-channel factor at the crown centre, blended towards the mix of its face
// factors along the world direction d from the centre (weights d.x^2, d.y^2, d.z^2, the face of each sign)
// as lp moves out to the crown box's half extent, so the side of a crown facing open ground keeps its light.
// Continuous in lp; per instance, read by every backend (the species grid stays one per species).
SYLVA_HD inline glm::vec3 forestFactor(const RenderView& v, const InstanceRecord& in, const glm::vec3& lp)
{
    if (in.light == 0u) return glm::vec3(1.0f);
    const InstanceLightRecord& r = v.instanceLights[in.light - 1u];
    const glm::vec3 centre(r.factor);
    const glm::vec3 o = lp - r.centre;
    const glm::vec3 w = toWorldNormal(in, o);   // R o / scale: the world direction
    const float wl = glm::length(w);
    if (!(wl > 0.0f)) return centre;
    const glm::vec3 d = w / wl;
    const glm::vec3 d2 = d * d;
    const glm::vec3 cube = d2.x * glm::vec3(r.face[d.x >= 0.0f ? 0 : 1]) + d2.y * glm::vec3(r.face[d.y >= 0.0f ? 2 : 3]) +
                           d2.z * glm::vec3(r.face[d.z >= 0.0f ? 4 : 5]);
    const float t = fminf(glm::length(o) * r.invRadius, 1.0f);
    return centre + t * (cube - centre);
}

// The kind's surface: the mesh's, its LB light scaled by the forest grid's factor of its top-level instance.
SYLVA_HD inline void shadeInstances(const RenderView& v, const Ray& ray, const Hit& hit, SurfacePoint& s)
{
    const InstanceRecord in = instancesHitMap(v, hit);
    const glm::vec3 lp = toLocalPoint(in, ray.org) + hit.t * toLocalDir(in, ray.dir);
    shadeMesh(v, hit, in, lp, s);
    meshIndirect(v, in, lp, forestFactor(v, in, lp), s);
}

} // namespace sylva
