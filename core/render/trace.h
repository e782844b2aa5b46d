// Two-level ray queries over instanced species with alpha-tested leaves and a ground plane (host and device).
#pragma once

#include "core/accel/bvh.h"
#include "core/accel/ray.h"
#include "core/render/render_view.h"

namespace sylva {

inline constexpr uint32_t kGroundPrim = 0xfffffffeu;   // Hit::prim of the ground plane

// Texel lookup in a 1-bit cut-out, uv wrapped (OBJ convention: v = 0 is the image's bottom row).
SYLVA_HD SYLVA_INLINE bool alphaOpaque(const RenderView& v, uint32_t maskIndex, glm::vec2 uv)
{
    const AlphaMaskRecord m = v.alphaMasks[maskIndex];
    const float fu = uv.x - floorf(uv.x), fv = uv.y - floorf(uv.y);
    int x = int(fu * float(m.width)), y = int((1.0f - fv) * float(m.height));
    x = x < 0 ? 0 : (x >= m.width ? m.width - 1 : x);
    y = y < 0 ? 0 : (y >= m.height ? m.height - 1 : y);
    const uint32_t bit = uint32_t(y) * uint32_t(m.width) + uint32_t(x);
    return (v.alphaBits[m.offset + (bit >> 5)] >> (bit & 31u)) & 1u;
}

SYLVA_HD SYLVA_INLINE glm::vec2 triangleUv(const RenderView& v, uint32_t tri, float u, float w)
{
    const glm::uvec3 t = v.triVerts[tri];
    return (1.0f - u - w) * v.uvs[t.x] + u * v.uvs[t.y] + w * v.uvs[t.z];
}

// Tests triangle `slot` of a species in its frame; alpha-tested triangles let the ray through where
// the cut-out is transparent. Returns true on an accepted hit closer than tmax (then tmax = t).
SYLVA_HD SYLVA_INLINE bool hitTriangle(const RenderView& v, const TriAccel& tri, const glm::vec3& org,
                                       const glm::vec3& dir, float tmin, float& tmax, float& u, float& w)
{
    float t, uu, ww;
    if (!intersectTriangle(org, dir, tri.v0, tri.e1, tri.e2, tmin, tmax, t, uu, ww)) return false;
    if (tri.alpha != 0u && !alphaOpaque(v, tri.alpha - 1u, triangleUv(v, tri.tri, uu, ww))) return false;
    tmax = t;
    u = uu;
    w = ww;
    return true;
}

SYLVA_HD SYLVA_INLINE glm::vec3 toLocalPoint(const InstanceRecord& in, const glm::vec3& p)
{
    return glm::vec3(glm::dot(glm::vec3(in.row[0]), p) + in.row[0].w, glm::dot(glm::vec3(in.row[1]), p) + in.row[1].w,
                     glm::dot(glm::vec3(in.row[2]), p) + in.row[2].w);
}

SYLVA_HD SYLVA_INLINE glm::vec3 toLocalDir(const InstanceRecord& in, const glm::vec3& d)
{
    return glm::vec3(glm::dot(glm::vec3(in.row[0]), d), glm::dot(glm::vec3(in.row[1]), d), glm::dot(glm::vec3(in.row[2]), d));
}

// A species-frame normal back to the world: transpose of the linear part (rotation / scale).
SYLVA_HD SYLVA_INLINE glm::vec3 toWorldNormal(const InstanceRecord& in, const glm::vec3& n)
{
    return glm::vec3(in.row[0]) * n.x + glm::vec3(in.row[1]) * n.y + glm::vec3(in.row[2]) * n.z;
}

// Closest hit along the ray (camera-relative world frame) over instances and the ground.
// anyHit = true stops at the first accepted hit (shadow rays). Returns true on a hit.
template <bool AnyHit>
SYLVA_HD inline bool traceBvh(const RenderView& v, const Ray& ray, Hit& hit)
{
    hit.prim = kNoHit;
    hit.inst = kNoHit;
    float tmax = ray.tmax;
    if (v.groundEnabled && ray.dir.y != 0.0f) {
        const float tg = (v.groundY - ray.org.y) / ray.dir.y;
        if (tg > ray.tmin && tg < tmax) {
            if (AnyHit) return true;
            tmax = tg;
            hit.prim = kGroundPrim;
            hit.t = tg;
            hit.u = hit.v = 0.0f;
        }
    }
    const BvhView tlas{v.tlasNodes};
    const bool stopped = traverseBvh(tlas, ray.org, ray.dir, ray.tmin, tmax, [&](uint32_t slot, float& tlasMax) {
        const uint32_t inst = v.tlasOrder[slot];
        const InstanceRecord& in = v.instances[inst];
        const SpeciesRecord& sp = v.species[in.species];
        const glm::vec3 o = toLocalPoint(in, ray.org), d = toLocalDir(in, ray.dir);
        const TriAccel* tris = v.tris + sp.triOffset;
        bool found = false;
        const bool stop = traverseBvh(BvhView{v.blasNodes + sp.nodeOffset}, o, d, ray.tmin, tlasMax,
                                      [&](uint32_t s, float& blasMax) {
                                          float u, w;
                                          if (!hitTriangle(v, tris[s], o, d, ray.tmin, blasMax, u, w)) return false;
                                          found = true;
                                          if (!AnyHit) {
                                              hit.t = blasMax;
                                              hit.u = u;
                                              hit.v = w;
                                              hit.prim = tris[s].tri;
                                              hit.inst = inst;
                                          }
                                          return AnyHit;
                                      });
        (void)found;
        return stop;
    });
    if (AnyHit) return stopped;
    return hit.prim != kNoHit;
}

// The query the shading code calls: dispatches on the acceleration structure of the run.
template <bool AnyHit>
SYLVA_HD SYLVA_INLINE bool traceScene(const RenderView& v, const Ray& ray, Hit& hit)
{
    return traceBvh<AnyHit>(v, ray, hit);
}

} // namespace sylva
