// The monotonic tricubic interpolation of the smoke simulation's advection (Fedkiw, Stam & Jensen 2001,
// section 5): Hermite pieces whose slopes are zeroed where they disagree with the secant.
#pragma once

#include <cstddef>

#include <glm/glm.hpp>

namespace sylva::volume::smoke_detail {

// A staggered field: samples at (index + offset) in cell units.
struct FieldView {
    const float* data;
    glm::ivec3 n;
    glm::vec3 offset;
    float at(int i, int j, int k) const { return data[(size_t(i) * size_t(n.y) + size_t(j)) * size_t(n.z) + size_t(k)]; }
};

// Monotonic cubic Hermite through f1 (t = 0) and f2 (t = 1), Fedkiw et al. 2001 eq. (8)-(9): the
// slopes are central differences, set to 0 where their sign differs from the secant's (or it is 0)
// and capped at 3 times the secant (Fritsch and Carlson 1980), so the curve never leaves [min(f1, f2), max(f1, f2)] between the samples.
float monotonicCubic(float f0, float f1, float f2, float f3, float t);

// The field at pos (cell units), monotonic cubic along z, then y, then x over the 4x4x4 samples around it
// (clamped at the field's edges).
float sampleCubic(const FieldView& f, const glm::vec3& pos);

} // namespace sylva::volume::smoke_detail
