// Exact triangle / axis-aligned box overlap by the separating-axis theorem (13 axes), closed boxes.
#pragma once

#include <glm/glm.hpp>

#include "core/base/defines.h"

namespace sylva {

// One triangle prepared for overlap tests against many axis-aligned boxes of one half-size.
// Units and frame are the caller's (the voxelizer uses sub-cell units around a local anchor).
// Candidate separating axes: the 3 box normals (handled by the triangle bounds lo/hi), the
// triangle normal (axis[0]) and the 9 cross products edge_e x unit_a (axis[1 + 3e + a]).
// On axis k the box (centre c) and the triangle overlap iff dot(axis[k], c) lies in
// [cmin[k], cmax[k]] = [min_v dot(axis, v) - r, max_v dot(axis, v) + r], r = dot(half, abs(axis)).
// The triangle is projected with all three vertices on every axis, so an axis computed with
// rounding error (slivers) or a zero axis (degenerate triangles) can never separate wrongly;
// for a segment or point the 13 axes still contain the complete SAT set of that shape.
// Boxes are closed: touching (a projection gap of exactly zero) counts as overlap. 236 bytes.
struct TriBoxSat {
    glm::vec3 lo, hi;        // triangle bounds
    glm::vec3 half;          // box half-size, per axis
    glm::vec3 axis[10];      // normal, then edge x axis
    float cmin[10];          // overlap interval of the box centre's projection on each axis
    float cmax[10];
};

SYLVA_HD SYLVA_INLINE TriBoxSat triBoxPrepare(const glm::vec3& v0, const glm::vec3& v1, const glm::vec3& v2,
                                              const glm::vec3& halfSize)
{
    TriBoxSat s;
    s.lo = glm::min(v0, glm::min(v1, v2));
    s.hi = glm::max(v0, glm::max(v1, v2));
    s.half = halfSize;
    const glm::vec3 e[3] = {v1 - v0, v2 - v1, v0 - v2};
    s.axis[0] = glm::cross(e[0], v2 - v0);
    for (int k = 0; k < 3; ++k) {
        // edge x unit x, edge x unit y, edge x unit z
        s.axis[1 + 3 * k + 0] = glm::vec3(0.0f, e[k].z, -e[k].y);
        s.axis[1 + 3 * k + 1] = glm::vec3(-e[k].z, 0.0f, e[k].x);
        s.axis[1 + 3 * k + 2] = glm::vec3(e[k].y, -e[k].x, 0.0f);
    }
    for (int k = 0; k < 10; ++k) {
        const glm::vec3& a = s.axis[k];
        const float p0 = glm::dot(a, v0), p1 = glm::dot(a, v1), p2 = glm::dot(a, v2);
        const float r = glm::dot(halfSize, glm::abs(a));
        s.cmin[k] = glm::min(p0, glm::min(p1, p2)) - r;
        s.cmax[k] = glm::max(p0, glm::max(p1, p2)) + r;
    }
    return s;
}

// Does the box's projection on triangle axis k (box centre projected to d) meet the triangle's?
SYLVA_HD SYLVA_INLINE bool triBoxSatAxis(const TriBoxSat& s, int k, float d)
{
    return (d >= s.cmin[k]) & (d <= s.cmax[k]);
}

// The triangle axes grouped by the box coordinates they depend on, so that a caller testing a block
// of boxes can evaluate each group once per row or column: the plane needs the whole centre; the
// edge x unit-x axes only (y, z) (the projections on the yz plane overlap), edge x unit-y only
// (z, x), edge x unit-z only (x, y).
SYLVA_HD SYLVA_INLINE bool triBoxSatPlane(const TriBoxSat& s, const glm::vec3& center)
{
    return triBoxSatAxis(s, 0, glm::dot(s.axis[0], center));
}
SYLVA_HD SYLVA_INLINE bool triBoxSatProjectedX(const TriBoxSat& s, float cy, float cz)
{
    bool overlap = true;
    for (int e = 0; e < 3; ++e) {
        const glm::vec3& a = s.axis[1 + 3 * e];
        overlap &= triBoxSatAxis(s, 1 + 3 * e, a.y * cy + a.z * cz);
    }
    return overlap;
}
SYLVA_HD SYLVA_INLINE bool triBoxSatProjectedY(const TriBoxSat& s, float cz, float cx)
{
    bool overlap = true;
    for (int e = 0; e < 3; ++e) {
        const glm::vec3& a = s.axis[2 + 3 * e];
        overlap &= triBoxSatAxis(s, 2 + 3 * e, a.z * cz + a.x * cx);
    }
    return overlap;
}
SYLVA_HD SYLVA_INLINE bool triBoxSatProjectedZ(const TriBoxSat& s, float cx, float cy)
{
    bool overlap = true;
    for (int e = 0; e < 3; ++e) {
        const glm::vec3& a = s.axis[3 + 3 * e];
        overlap &= triBoxSatAxis(s, 3 + 3 * e, a.x * cx + a.y * cy);
    }
    return overlap;
}

// The 10 triangle axes only, for a caller that already knows the box overlaps the triangle bounds.
SYLVA_HD SYLVA_INLINE bool triBoxSatOverlapsAxes(const TriBoxSat& s, const glm::vec3& center)
{
    return triBoxSatProjectedZ(s, center.x, center.y) && triBoxSatProjectedX(s, center.y, center.z) &&
           triBoxSatProjectedY(s, center.z, center.x) && triBoxSatPlane(s, center);
}

// All 13 axes: does the closed box centred at center (half-size s.half) meet the triangle?
SYLVA_HD SYLVA_INLINE bool triBoxSatOverlaps(const TriBoxSat& s, const glm::vec3& center)
{
    const glm::vec3 bmin = center - s.half, bmax = center + s.half;
    if (s.lo.x > bmax.x || s.lo.y > bmax.y || s.lo.z > bmax.z) return false;
    if (s.hi.x < bmin.x || s.hi.y < bmin.y || s.hi.z < bmin.z) return false;
    return triBoxSatOverlapsAxes(s, center);
}

// One-shot test: does the triangle (v0, v1, v2) meet the closed box center +- halfSize?
// Works in the box's frame (vertices minus center) for accuracy far from the origin.
SYLVA_HD SYLVA_INLINE bool triBoxOverlap(const glm::vec3& center, const glm::vec3& halfSize, const glm::vec3& v0,
                                         const glm::vec3& v1, const glm::vec3& v2)
{
    const TriBoxSat s = triBoxPrepare(v0 - center, v1 - center, v2 - center, halfSize);
    return triBoxSatOverlaps(s, glm::vec3(0.0f));
}

} // namespace sylva
