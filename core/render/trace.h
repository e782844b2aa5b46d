// Ray queries through nested instance levels down to meshes with alpha-tested leaves and a ground plane (host and device).
#pragma once

#include "core/accel/bvh.h"
#include "core/accel/kdtree.h"
#include "core/accel/ray.h"
#include "core/render/render_view.h"

namespace sylva {

inline constexpr uint32_t kGroundPrim = 0xfffffffeu;   // Hit::prim of the ground plane
inline constexpr uint32_t kTerrainInst = 0xfffffffdu;  // Hit::inst of the terrain (Hit::prim: its triangle)
inline constexpr uint32_t kLandscapeInst = 0xfffffffcu; // Hit::inst of a landscape plant (nested[0]: cell, nested[1]: plant)

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

// Adaptive transparency (Geist & Steele, "A Lighting Model for Fast Rendering of Forest Ecosystems", section
// 2.1, Dietrich et al.): beyond v.alphaDistance from the camera leaf cards count as opaque. In the
// camera-relative frame a ray point's distance from the camera is at most |org| + t |dir|, so cut-outs are
// honoured for t < tAlpha = (D - |org|) / |dir| only: exactly the points within D on camera rays (org = 0); on
// shadow rays those surely within D (from a point beyond D, none). t is the same in every instance's frame, so
// one threshold per ray serves both levels.
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

// The composite of two instance maps: `inner` (in the frame `outer` maps to) after `outer`. The result
// maps outer's parent frame to inner's geometry frame; scales multiply.
SYLVA_HD SYLVA_INLINE InstanceRecord composeInstances(const InstanceRecord& inner, const InstanceRecord& outer)
{
    InstanceRecord r = inner;
    for (int i = 0; i < 3; ++i) {
        const glm::vec4& a = inner.row[i];
        for (int j = 0; j < 4; ++j)
            r.row[i][j] = a.x * outer.row[0][j] + a.y * outer.row[1][j] + a.z * outer.row[2][j] + (j == 3 ? a.w : 0.0f);
    }
    r.scale = inner.scale * outer.scale;
    return r;
}

// The hit instance as one map from the camera-relative world frame to the hit mesh's frame (the
// instances along the hit's path composed) with its mesh geometry and the total scale.
namespace trace_detail {
SYLVA_HD inline InstanceRecord landPlantInstance(const RenderView& v, uint32_t cell, uint32_t plant);
}

SYLVA_HD inline InstanceRecord hitInstance(const RenderView& v, const Hit& hit)
{
    if (hit.inst == kLandscapeInst) return trace_detail::landPlantInstance(v, hit.nested[0], hit.nested[1]);
    InstanceRecord m = v.instances[hit.inst];
    for (uint32_t k = 0; k < hit.depth && k < uint32_t(kMaxNested); ++k) m = composeInstances(v.groupInstances[hit.nested[k]], m);
    return m;
}

namespace trace_detail {

// What one query carries down the levels: the view, the ray's limits, the hit and the instance path.
struct Query {
    const RenderView& v;
    float tmin;
    float tAlpha;
    Hit& hit;
    uint32_t path[kMaxLevels];   // path[0]: top-level instance; path[k]: groupInstances index at depth k
};

// Records a closer hit of triangle `tri` found Depth levels below the top.
template <int Depth>
SYLVA_HD SYLVA_INLINE void recordHit(Query& q, float t, float u, float w, uint32_t tri)
{
    Hit& h = q.hit;
    h.t = t;
    h.u = u;
    h.v = w;
    h.prim = tri;
    h.inst = q.path[0];
    h.depth = uint32_t(Depth);
    for (int k = 1; k <= Depth; ++k) h.nested[k - 1] = q.path[k];
}

// A mesh in its own frame, Depth levels below the top: its BVH over triangle blocks (Kd = false; the host
// walks the 8-wide copy when the view has it) or its kd-tree (Kd = true). Returns true when an any-hit
// query found a hit. The query's limits are copied to locals so that hit writes cannot make the
// compiler reload them for every leaf.
template <bool AnyHit, bool Kd, int Depth>
SYLVA_HD inline bool traceMesh(Query& q, const GeometryRecord& geo, const glm::vec3& o, const glm::vec3& d, float& tmax)
{
    const RenderView& v = q.v;
    const float tmin = q.tmin, tAlpha = q.tAlpha;
    if constexpr (Kd) {
        const TriAccel* tris = v.tris + geo.triOffset;
        auto triFn = [&](uint32_t s, float& t) {
            float u, w;
            SYLVA_COUNT(g_triangleTests);
            if (!hitTriangle(v, tris[s], o, d, tmin, t, u, w, tAlpha)) return false;
            if (!AnyHit) recordHit<Depth>(q, t, u, w, tris[s].tri);
            return AnyHit;
        };
        const KdView view{v.kdNodes + geo.kdNodeOffset, v.kdRefs + geo.kdRefOffset, geo.lo, geo.hi};
        return traverseKd(view, o, d, tmin, tmax, triFn);
    } else {
        const TriBlock* blocks = v.blocks + geo.primOffset;
        auto blockFn = [&](uint32_t block, uint32_t count, float& t) {
            float u, w;
            uint32_t tri;
            SYLVA_COUNT_ADD(g_triangleTests, count);
            if (!hitBlock<AnyHit>(v, blocks[block], count, o, d, tmin, t, u, w, tri, tAlpha)) return false;
            if (!AnyHit) recordHit<Depth>(q, t, u, w, tri);
            return AnyHit;
        };
        const char* leafData = reinterpret_cast<const char*>(blocks);
#if !defined(__CUDACC__)
        // The host's 8-wide flattening of the same tree when the scene has it (same leaves; the same
        // closest hit up to which of two triangles at exactly the same t wins).
        if (v.blasWideNodes)
            return traverseBvh(BvhView8{v.blasWideNodes + geo.wideNodeOffset, leafData, sizeof(TriBlock)}, o, d, tmin, tmax,
                               blockFn);
#endif
        return traverseBvh(BvhView{v.blasNodes + geo.nodeOffset, leafData, sizeof(TriBlock)}, o, d, tmin, tmax, blockFn);
    }
}

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

} // namespace trace_detail

} // namespace sylva

#include "core/render/trace_landscape.h"

namespace sylva {

namespace trace_detail {

// The ground plane and the terrain, asked first (Dietrich, Marmitt & Slusallek, "Terrain Guided Multi-Level
// Instancing of Highly Complex Plant Populations", section 4.1): their hit shortens the ray (tmax) before the
// plants are traversed. Starts the hit record. Returns true when an any-hit query is answered.
template <bool AnyHit>
SYLVA_HD inline bool traceGround(const RenderView& v, const Ray& ray, Hit& hit, float& tmax)
{
    hit.prim = kNoHit;
    hit.inst = kNoHit;
    hit.depth = 0;
    tmax = ray.tmax;
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
    if (v.terrainEnabled) {
        const Ray local{ray.org - v.terrainBase, ray.tmin, ray.dir, tmax};
        uint32_t tri = kNoHit;
        float u = 0.0f, w = 0.0f;
        if (intersectHeightField<AnyHit>(HeightFieldView{v.terrain, v.terrainHeights, v.terrainRanges, v.terrainBaseI, v.terrainBaseJ}, local, tmax,
                                         tri, u, w)) {
            if (AnyHit) return true;
            hit.prim = tri;
            hit.inst = kTerrainInst;
            hit.t = tmax;
            hit.u = u;
            hit.v = w;
        }
    }
    return false;
}

// The top level's instances, asked last (below the closest hit so far, tmax): the query's answer.
template <bool AnyHit, bool Kd>
SYLVA_HD inline bool traceTopLevel(const RenderView& v, const Ray& ray, Hit& hit, float& tmax)
{
    if (v.instanceCount == 0) return AnyHit ? false : hit.prim != kNoHit;
    Query q{v, ray.tmin, alphaTestLimit(v, ray), hit, {}};
    const bool stopped = traceLevel<AnyHit, Kd, 0>(q, v.tlasNodes, v.tlasWideNodes, v.tlasOrder, v.instances, ray.org, ray.dir, tmax);
    if (AnyHit) return stopped;
    return hit.prim != kNoHit;
}

} // namespace trace_detail

// Closest hit along the ray (camera-relative world frame) over the ground plane, the terrain and the top level's instances,
// descending through instance groups to meshes traced through their BVHs (Kd = false) or kd-trees
// (Kd = true; groups and the top level always use BVHs). AnyHit stops at the first accepted hit (shadow
// rays). Cut-outs are tested up to alphaTestLimit. Returns true on a hit.
template <bool AnyHit, bool Kd>
SYLVA_HD inline bool traceInstances(const RenderView& v, const Ray& ray, Hit& hit)
{
    float tmax;
    if (trace_detail::traceGround<AnyHit>(v, ray, hit, tmax)) return true;
    // The landscape's cells and tiles (Dietrich et al. 2006, sections 4.1, 4.2), below the ground's hit.
    if (v.landscapeEnabled) {
        trace_detail::Query lq{v, ray.tmin, alphaTestLimit(v, ray), hit, {}};
        if (trace_detail::traceLandscape<AnyHit, Kd>(lq, ray.org, ray.dir, tmax) && AnyHit) return true;
    }
    return trace_detail::traceTopLevel<AnyHit, Kd>(v, ray, hit, tmax);
}

// The query the shading code calls: dispatches on the acceleration structure of the run.
template <bool AnyHit>
SYLVA_HD SYLVA_INLINE bool traceScene(const RenderView& v, const Ray& ray, Hit& hit)
{
    if (v.accel == AccelKind::KdTree) return traceInstances<AnyHit, true>(v, ray, hit);
    return traceInstances<AnyHit, false>(v, ray, hit);
}

} // namespace sylva
