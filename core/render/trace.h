// Two-level ray queries over instanced species with alpha-tested leaves and a ground plane (host and device).
#pragma once

#include "core/accel/bvh.h"
#include "core/accel/kdtree.h"
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

// The cut-out coordinates of triangle k of a block at barycentrics (u, w): from the block's packed
// corners when it has them (equal to triangleUv up to whole units and 3e-5), else from the shading arrays.
SYLVA_HD SYLVA_INLINE glm::vec2 blockUv(const RenderView& v, const TriBlock& b, int k, float u, float w)
{
    if (!((b.uvPacked >> k) & 1u)) return triangleUv(v, b.tri[k], u, w);
    const uint16_t* q = b.uv[k];
    const float a = 1.0f - u - w;
    constexpr float s = 1.0f / kBlockUvScale;
    return glm::vec2((a * float(q[0]) + u * float(q[2]) + w * float(q[4])) * s, (a * float(q[1]) + u * float(q[3]) + w * float(q[5])) * s);
}

// tAlpha of a ray that tests every cut-out (adaptive transparency off).
inline constexpr float kAlphaEverywhere = 3.0e38f;

// Adaptive transparency (seed 000 section 2.1, Dietrich et al.): beyond v.alphaDistance from the camera
// leaf cards count as opaque. In the camera-relative frame a ray point's distance from the camera is at
// most |org| + t |dir|, so cut-outs are honoured for t < tAlpha = (D - |org|) / |dir| only: exactly the
// points within D on camera rays (org = 0); on shadow rays those surely within D (from a point beyond D,
// none). t is the same in every instance's frame, so one threshold per ray serves both levels.
SYLVA_HD SYLVA_INLINE float alphaTestLimit(const RenderView& v, const Ray& ray)
{
    if (!(v.alphaDistance > 0.0f)) return kAlphaEverywhere;
    return (v.alphaDistance - glm::length(ray.org)) / glm::length(ray.dir);
}

// Tests triangle `slot` of a species in its frame; alpha-tested triangles let the ray through where
// the cut-out is transparent, for t < tAlpha (beyond it they are opaque). Returns true on an accepted
// hit closer than tmax (then tmax = t).
SYLVA_HD SYLVA_INLINE bool hitTriangle(const RenderView& v, const TriAccel& tri, const glm::vec3& org,
                                       const glm::vec3& dir, float tmin, float& tmax, float& u, float& w,
                                       float tAlpha = kAlphaEverywhere)
{
    float t, uu, ww;
    if (!intersectTriangle(org, dir, tri.v0, tri.e1, tri.e2, tmin, tmax, t, uu, ww)) return false;
    if (tri.alpha != 0u && t < tAlpha && !alphaOpaque(v, tri.alpha - 1u, triangleUv(v, tri.tri, uu, ww))) return false;
    tmax = t;
    u = uu;
    w = ww;
    return true;
}

// Tests the first `count` triangles of a block (one SIMD pass on the host); the accepted hit
// (alpha cut-outs pass the ray through for t < tAlpha) closest and below tmax wins: tmax, u, w, tri
// are set. AnyHit returns at the first accepted hit. Returns true when a hit was accepted.
template <bool AnyHit>
SYLVA_HD inline bool hitBlock(const RenderView& v, const TriBlock& b, uint32_t count, const glm::vec3& org,
                              const glm::vec3& dir, float tmin, float& tmax, float& u, float& w, uint32_t& tri,
                              float tAlpha = kAlphaEverywhere)
{
    float tt[4], uu[4], vv[4];
    bool ok[4];
#if !defined(__CUDA_ARCH__)
    using F = detail::Float4;
    const F dx = {dir.x, dir.x, dir.x, dir.x}, dy = {dir.y, dir.y, dir.y, dir.y}, dz = {dir.z, dir.z, dir.z, dir.z};
    const F e1x = detail::load4(b.e1x), e1y = detail::load4(b.e1y), e1z = detail::load4(b.e1z);
    const F e2x = detail::load4(b.e2x), e2y = detail::load4(b.e2y), e2z = detail::load4(b.e2z);
    const F px = dy * e2z - dz * e2y, py = dz * e2x - dx * e2z, pz = dx * e2y - dy * e2x;
    const F det = e1x * px + e1y * py + e1z * pz;
    const F one = {1.0f, 1.0f, 1.0f, 1.0f}, zero = {0.0f, 0.0f, 0.0f, 0.0f};
    const F inv = one / det;
    const F sx = F{org.x, org.x, org.x, org.x} - detail::load4(b.v0x);
    const F sy = F{org.y, org.y, org.y, org.y} - detail::load4(b.v0y);
    const F sz = F{org.z, org.z, org.z, org.z} - detail::load4(b.v0z);
    const F U = (sx * px + sy * py + sz * pz) * inv;
    const F qx = sy * e1z - sz * e1y, qy = sz * e1x - sx * e1z, qz = sx * e1y - sy * e1x;
    const F V = (dx * qx + dy * qy + dz * qz) * inv;
    const F T = (e2x * qx + e2y * qy + e2z * qz) * inv;
    const auto mask = (det != zero) & (U >= zero) & (V >= zero) & (U + V <= one) & (T > F{tmin, tmin, tmin, tmin}) &
                      (T < F{tmax, tmax, tmax, tmax});
    for (int k = 0; k < 4; ++k) {
        ok[k] = mask[k] != 0 && uint32_t(k) < count;
        tt[k] = T[k];
        uu[k] = U[k];
        vv[k] = V[k];
    }
#else
    for (int k = 0; k < 4; ++k) {
        ok[k] = uint32_t(k) < count &&
                intersectTriangle(org, dir, glm::vec3(b.v0x[k], b.v0y[k], b.v0z[k]), glm::vec3(b.e1x[k], b.e1y[k], b.e1z[k]),
                                  glm::vec3(b.e2x[k], b.e2y[k], b.e2z[k]), tmin, tmax, tt[k], uu[k], vv[k]);
    }
#endif
    bool found = false;
    for (int k = 0; k < 4; ++k) {
        if (!ok[k] || !(tt[k] < tmax)) continue;
        if (b.alpha[k] != 0u && tt[k] < tAlpha && !alphaOpaque(v, b.alpha[k] - 1u, blockUv(v, b, k, uu[k], vv[k])))
            continue;
        tmax = tt[k];
        u = uu[k];
        w = vv[k];
        tri = b.tri[k];
        found = true;
        if (AnyHit) return true;
    }
    return found;
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

// Closest hit along the ray (camera-relative world frame) over instances and the ground, through
// the BVHs (Kd = false) or the kd-trees (Kd = true) at both levels. AnyHit stops at the first
// accepted hit (shadow rays). An instance is traced with its geometry record (the species or a pruned
// level of it); cut-outs are tested up to alphaTestLimit. Returns true on a hit.
template <bool AnyHit, bool Kd>
SYLVA_HD inline bool traceInstances(const RenderView& v, const Ray& ray, Hit& hit)
{
    hit.prim = kNoHit;
    hit.inst = kNoHit;
    float tmax = ray.tmax;
    const float tAlpha = alphaTestLimit(v, ray);
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
    auto instanceFn = [&](uint32_t inst, float& tlasMax) {
        const InstanceRecord& in = v.instances[inst];
        const glm::vec3 o = toLocalPoint(in, ray.org), d = toLocalDir(in, ray.dir);
        const SpeciesRecord& geo = v.species[in.geometry];
        const TriAccel* tris = v.tris + geo.triOffset;
        auto triFn = [&](uint32_t s, float& blasMax) {
            float u, w;
            if (!hitTriangle(v, tris[s], o, d, ray.tmin, blasMax, u, w, tAlpha)) return false;
            if (!AnyHit) {
                hit.t = blasMax;
                hit.u = u;
                hit.v = w;
                hit.prim = tris[s].tri;
                hit.inst = inst;
            }
            return AnyHit;
        };
        if constexpr (Kd) {
            const KdSpeciesRecord& k = v.kdSpecies[in.geometry];
            const KdView view{v.kdBlasNodes + k.nodeOffset, v.kdBlasRefs + k.refOffset, k.lo, k.hi};
            return traverseKd(view, o, d, ray.tmin, tlasMax, triFn);
        } else {
            const TriBlock* blocks = v.blocks + geo.blockOffset;
            auto blockFn = [&](uint32_t block, uint32_t count, float& blasMax) {
                float u, w;
                uint32_t tri;
                if (!hitBlock<AnyHit>(v, blocks[block], count, o, d, ray.tmin, blasMax, u, w, tri, tAlpha)) return false;
                if (!AnyHit) {
                    hit.t = blasMax;
                    hit.u = u;
                    hit.v = w;
                    hit.prim = tri;
                    hit.inst = inst;
                }
                return AnyHit;
            };
            const char* leafData = reinterpret_cast<const char*>(blocks);
#if !defined(__CUDACC__)
            // The host's 8-wide flattening of the same tree when the scene has it (same leaves; the same
            // closest hit up to which of two triangles at exactly the same t wins).
            if (v.blasWideNodes)
                return traverseBvh(BvhView8{v.blasWideNodes + geo.wideNodeOffset, leafData, sizeof(TriBlock)}, o, d, ray.tmin,
                                   tlasMax, blockFn);
#endif
            return traverseBvh(BvhView{v.blasNodes + geo.nodeOffset, leafData, sizeof(TriBlock)}, o, d, ray.tmin, tlasMax,
                               blockFn);
        }
    };
    bool stopped;
    if constexpr (Kd) {
        const KdView tlas{v.kdTlasNodes, v.kdTlasRefs, v.kdTlasLo, v.kdTlasHi};
        stopped = traverseKd(tlas, ray.org, ray.dir, ray.tmin, tmax, instanceFn);
    } else {
        auto slotFn = [&](uint32_t slot, float& tlasMax) { return instanceFn(v.tlasOrder[slot], tlasMax); };
#if !defined(__CUDACC__)
        if (v.tlasWideNodes) stopped = traverseBvh(BvhView8{v.tlasWideNodes}, ray.org, ray.dir, ray.tmin, tmax, slotFn);
        else
#endif
            stopped = traverseBvh(BvhView{v.tlasNodes}, ray.org, ray.dir, ray.tmin, tmax, slotFn);
    }
    if (AnyHit) return stopped;
    return hit.prim != kNoHit;
}

// The query the shading code calls: dispatches on the acceleration structure of the run.
template <bool AnyHit>
SYLVA_HD SYLVA_INLINE bool traceScene(const RenderView& v, const Ray& ray, Hit& hit)
{
    if (v.accel == AccelKind::KdTree) return traceInstances<AnyHit, true>(v, ray, hit);
    return traceInstances<AnyHit, false>(v, ray, hit);
}

} // namespace sylva
