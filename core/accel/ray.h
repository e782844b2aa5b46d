// Rays, hits and the ray/box and ray/triangle tests every traversal uses (host and device).
#pragma once

#include <cstdint>
#include <math.h>

#include <glm/glm.hpp>

#include "core/base/defines.h"

namespace sylva {

inline constexpr uint32_t kNoHit = 0xffffffffu;

// A ray in some frame; t is measured in units of |dir| (dir need not be normalized, so t survives
// affine instance transforms unchanged). 32 bytes.
struct Ray {
    glm::vec3 org;
    float tmin;
    glm::vec3 dir;
    float tmax;
};

// Closest hit so far: t along the ray, the surface kind that was hit (a SurfaceKind of core/render/
// surfaces/surface_list.h, 0 = nothing) and what that kind records of it: for a mesh reached through the
// instances, barycentrics (u,v) of the triangle, the triangle's index and the instance path down to it
// (`inst` indexes the top level's instances; a hit inside instance groups also records the `depth` group
// instances below it, nested[0] .. nested[depth-1], outermost first, indices into RenderView::groupInstances);
// other kinds say in their header what they keep in prim, inst and nested. 36 bytes.
inline constexpr int kMaxNested = 3;   // = kMaxLevels - 1 (core/render/render_view.h)
struct Hit {
    float t;
    float u, v;
    uint32_t prim;
    uint32_t inst;
    uint16_t depth;
    uint16_t kind;
    uint32_t nested[kMaxNested];
};

// min/max that compile to one instruction (fminf/fmaxf handle NaN and become libm calls on x86).
SYLVA_HD SYLVA_INLINE float minf(float a, float b) { return a < b ? a : b; }
SYLVA_HD SYLVA_INLINE float maxf(float a, float b) { return a > b ? a : b; }

// Reciprocal direction with zeros replaced by huge values of the right sign (no NaN in slab tests).
SYLVA_HD SYLVA_INLINE glm::vec3 safeReciprocal(const glm::vec3& d)
{
    const float big = 1e30f;
    return glm::vec3(d.x != 0.0f ? 1.0f / d.x : copysignf(big, d.x), d.y != 0.0f ? 1.0f / d.y : copysignf(big, d.y),
                     d.z != 0.0f ? 1.0f / d.z : copysignf(big, d.z));
}

// The entry distance of a missed box: NaN, so that `d <= tmax` is false even for tmax = inf.
SYLVA_HD SYLVA_INLINE float missDistance()
{
#if defined(__CUDA_ARCH__)
    return __int_as_float(0x7fc00000);
#else
    return __builtin_nanf("");
#endif
}

// Slab test. Returns the entry distance, or NaN (missDistance) when the box is missed. A zero
// direction component is inside the slab exactly when lo <= org <= hi on that axis (a ray lying in
// a box face enters the box).
SYLVA_HD SYLVA_INLINE float rayBoxEntry(const glm::vec3& lo, const glm::vec3& hi, const glm::vec3& org,
                                        const glm::vec3& invDir, float tmin, float tmax)
{
    float tx0 = (lo.x - org.x) * invDir.x, tx1 = (hi.x - org.x) * invDir.x;
    float ty0 = (lo.y - org.y) * invDir.y, ty1 = (hi.y - org.y) * invDir.y;
    float tz0 = (lo.z - org.z) * invDir.z, tz1 = (hi.z - org.z) * invDir.z;
    // safeReciprocal gives +-1e30 for a zero component; a zero offset would then give t = 0.
    if (invDir.x == 1e30f || invDir.x == -1e30f) {
        const bool in = lo.x <= org.x && org.x <= hi.x;
        tx0 = in ? -1e30f : 1e30f;
        tx1 = in ? 1e30f : -1e30f;
    }
    if (invDir.y == 1e30f || invDir.y == -1e30f) {
        const bool in = lo.y <= org.y && org.y <= hi.y;
        ty0 = in ? -1e30f : 1e30f;
        ty1 = in ? 1e30f : -1e30f;
    }
    if (invDir.z == 1e30f || invDir.z == -1e30f) {
        const bool in = lo.z <= org.z && org.z <= hi.z;
        tz0 = in ? -1e30f : 1e30f;
        tz1 = in ? 1e30f : -1e30f;
    }
    const float tnear = maxf(maxf(minf(tx0, tx1), minf(ty0, ty1)), maxf(minf(tz0, tz1), tmin));
    const float tfar = minf(minf(maxf(tx0, tx1), maxf(ty0, ty1)), minf(maxf(tz0, tz1), tmax));
    return tnear <= tfar ? tnear : missDistance();
}

// Moller-Trumbore with precomputed edges e1 = v1 - v0, e2 = v2 - v0. Two-sided. On a hit with
// tmin < t < tmax writes t, u, v and returns true.
SYLVA_HD SYLVA_INLINE bool intersectTriangle(const glm::vec3& org, const glm::vec3& dir, const glm::vec3& v0,
                                             const glm::vec3& e1, const glm::vec3& e2, float tmin, float tmax,
                                             float& t, float& u, float& v)
{
    const glm::vec3 p = glm::cross(dir, e2);
    const float det = glm::dot(e1, p);
    if (det == 0.0f) return false;
    const float inv = 1.0f / det;
    const glm::vec3 s = org - v0;
    const float uu = glm::dot(s, p) * inv;
    if (uu < 0.0f || uu > 1.0f) return false;
    const glm::vec3 q = glm::cross(s, e1);
    const float vv = glm::dot(dir, q) * inv;
    if (vv < 0.0f || uu + vv > 1.0f) return false;
    const float tt = glm::dot(e2, q) * inv;
    if (!(tt > tmin && tt < tmax)) return false;
    t = tt;
    u = uu;
    v = vv;
    return true;
}

} // namespace sylva
