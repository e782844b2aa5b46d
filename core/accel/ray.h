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

// Closest hit so far: t along the ray, barycentrics (u,v) of the triangle, the triangle's index in
// its mesh and the instance. prim == kNoHit when nothing was hit. 20 bytes.
struct Hit {
    float t;
    float u, v;
    uint32_t prim;
    uint32_t inst;
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

// Slab test. Returns the entry distance, or a value > tmax when the box is missed.
SYLVA_HD SYLVA_INLINE float rayBoxEntry(const glm::vec3& lo, const glm::vec3& hi, const glm::vec3& org,
                                        const glm::vec3& invDir, float tmin, float tmax)
{
    const float tx0 = (lo.x - org.x) * invDir.x, tx1 = (hi.x - org.x) * invDir.x;
    const float ty0 = (lo.y - org.y) * invDir.y, ty1 = (hi.y - org.y) * invDir.y;
    const float tz0 = (lo.z - org.z) * invDir.z, tz1 = (hi.z - org.z) * invDir.z;
    const float tnear = maxf(maxf(minf(tx0, tx1), minf(ty0, ty1)), maxf(minf(tz0, tz1), tmin));
    const float tfar = minf(minf(maxf(tx0, tx1), maxf(ty0, ty1)), minf(maxf(tz0, tz1), tmax));
    return tnear <= tfar ? tnear : 1e38f;
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
