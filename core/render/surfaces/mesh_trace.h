// The mesh surface kind's ray queries, below an instance: triangles with alpha-tested cut-outs under a BVH
// of 4-triangle blocks or a kd-tree, and the instance maps every kind that places meshes uses (host and device).
#pragma once

#include "core/accel/bvh.h"
#include "core/accel/kdtree.h"
#include "core/accel/ray.h"
#include "core/render/render_view.h"
#include "core/lb/leaf_optics.h"
#include "core/render/surface_point.h"

namespace sylva {

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

namespace trace_detail {

// What one query carries down the levels: the view, the ray's limits, the hit, the surface kind that records
// it and the instance path (Hit's fields as that kind uses them).
struct Query {
    const RenderView& v;
    float tmin;
    float tAlpha;
    Hit& hit;
    SurfaceKind kind;
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
    h.depth = uint16_t(Depth);
    h.kind = uint16_t(q.kind);
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

} // namespace trace_detail

// Bilinear, wrapped texture lookup (v = 0 is the bottom row, as in OBJ).
SYLVA_HD inline glm::vec4 sampleTexture(const RenderView& v, int32_t index, glm::vec2 uv)
{
    const TextureRecord t = v.textures[index];
    const float x = (uv.x - floorf(uv.x)) * float(t.width) - 0.5f;
    const float y = (1.0f - (uv.y - floorf(uv.y))) * float(t.height) - 0.5f;
    const float fx = floorf(x), fy = floorf(y);
    const float ax = x - fx, ay = y - fy;
    int x0 = int(fx), y0 = int(fy);
    x0 = ((x0 % t.width) + t.width) % t.width;
    y0 = ((y0 % t.height) + t.height) % t.height;
    const int x1 = (x0 + 1) % t.width, y1 = (y0 + 1) % t.height;
    const glm::vec4* p = v.texels + t.offset;
    return (1.0f - ay) * ((1.0f - ax) * p[y0 * t.width + x0] + ax * p[y0 * t.width + x1]) +
           ay * ((1.0f - ax) * p[y1 * t.width + x0] + ax * p[y1 * t.width + x1]);
}

// Trilinear lookup of a species' normalized lighting grid at a species-frame point (clamped to the grid).
SYLVA_HD inline glm::vec3 sampleLighting(const RenderView& v, const SpeciesRecord& sp, const glm::vec3& p)
{
    if (sp.gridInvSpacing == 0.0f) return glm::vec3(1.0f);
    const glm::vec3 g = (p - sp.gridOrigin) * sp.gridInvSpacing;
    const glm::vec3 hi = glm::vec3(sp.gridDims - 1) - 1e-4f;
    const glm::vec3 c = glm::clamp(g, glm::vec3(0.0f), hi);
    const glm::ivec3 i = glm::ivec3(c);
    const glm::vec3 f = c - glm::vec3(i);
    const float* L = v.lighting + sp.gridOffset;
    const int sy = sp.gridDims.z, sx = sp.gridDims.y * sp.gridDims.z;
    glm::vec3 out(0.0f);
    for (int corner = 0; corner < 8; ++corner) {
        const int dx = corner >> 2, dy = (corner >> 1) & 1, dz = corner & 1;
        const float w = (dx ? f.x : 1.0f - f.x) * (dy ? f.y : 1.0f - f.y) * (dz ? f.z : 1.0f - f.z);
        const int node = (i.x + dx) * sx + (i.y + dy) * sy + (i.z + dz);
        out += w * glm::vec3(L[node * 3], L[node * 3 + 1], L[node * 3 + 2]);
    }
    return out;
}

// A mesh hit's surface reached through instance map `in` (camera-relative world -> the mesh's frame), at
// species-frame point lp (s.p and s.viewDir set): the two-sided shading normal and the material (texture,
// leaf or bark).
SYLVA_HD inline void shadeMesh(const RenderView& v, const Hit& hit, const InstanceRecord& in, const glm::vec3& lp, SurfacePoint& s)
{
    const SpeciesRecord& sp = v.species[v.geometries[in.geometry].species];
    const glm::uvec3 tv = v.triVerts[hit.prim];
    const MaterialRecord m = v.materials[v.triMaterial[hit.prim]];
    // Geometric normal from the triangle's vertices (species frame) and the interpolated shading normal.
    const float b0 = 1.0f - hit.u - hit.v;
    glm::vec3 ns = b0 * v.normals[tv.x] + hit.u * v.normals[tv.y] + hit.v * v.normals[tv.z];
    glm::vec3 ng = glm::normalize(toWorldNormal(in, ns));
    if (!(glm::dot(ng, ng) > 0.5f)) ng = glm::vec3(0.0f, 1.0f, 0.0f);
    if (glm::dot(ng, s.viewDir) < 0.0f) ng = -ng;   // two-sided: face the viewer
    s.ng = ng;
    glm::vec3 kd = m.diffuse;
    if (m.texture >= 0) {
        const glm::vec2 uv = b0 * v.uvs[tv.x] + hit.u * v.uvs[tv.y] + hit.v * v.uvs[tv.z];
        kd *= glm::vec3(sampleTexture(v, m.texture, uv));
    }
    s.albedo = kd;
    s.indirectWeight = m.isLeaf ? sp.leafIndirect : glm::vec3(sp.barkIndirect);
    if (m.isLeaf)   // a leaf scatters at most kMaxLeafScattering of what it receives (leaf_optics.h)
        for (int c = 0; c < 3; ++c)
            if (kd[c] * s.indirectWeight[c] > sp.leafIndirectCap) s.indirectWeight[c] = sp.leafIndirectCap / kd[c];
    // Diffuse transmission as the Blender export's translucent BSDF: kd x ratio, kd + it at most kMaxLeafScattering.
    if (m.isLeaf && tracesPaths(v))   // only paths read it
        for (int c = 0; c < 3; ++c) s.transmission[c] = fmaxf(0.0f, fminf(kd[c] * sp.leafRatio[c], lb::kMaxLeafScattering - kd[c]));
    s.specular = m.specular;
    s.shininess = m.shininess;
    s.extent = in.scale * fmaxf(fmaxf(fabsf(lp.x), fabsf(lp.y)), fabsf(lp.z));
}

// The mesh point's LB light (species-frame point lp) times the forest grid's factor, and what the surface shows of it.
SYLVA_HD inline void meshIndirect(const RenderView& v, const InstanceRecord& in, const glm::vec3& lp, const glm::vec3& factor, SurfacePoint& s)
{
    const SpeciesRecord& sp = v.species[v.geometries[in.geometry].species];
    s.lighting = sampleLighting(v, sp, lp) * factor;
    s.indirect = s.albedo * s.lighting * s.indirectWeight * v.lbRadiance * v.indirectScale;
}

} // namespace sylva
