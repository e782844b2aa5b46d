// Deterministic random numbers and the sampling the shading code draws with (host and device).
#pragma once

#include <math.h>
#include <stdint.h>

#include <glm/glm.hpp>

#include "core/base/defines.h"

namespace sylva {

// A hash-based random number in [0,1) (deterministic per pixel, sample and dimension).
SYLVA_HD SYLVA_INLINE float hashToUnit(uint32_t a, uint32_t b, uint32_t c)
{
    uint32_t h = a * 0x9E3779B1u ^ (b + 0x7F4A7C15u) * 0x85EBCA77u ^ (c + 0x165667B1u) * 0xC2B2AE3Du;
    h ^= h >> 16;
    h *= 0x7FEB352Du;
    h ^= h >> 15;
    h *= 0x846CA68Bu;
    h ^= h >> 16;
    return float(h >> 8) * (1.0f / 16777216.0f);
}

// A unit direction about unit n with density cos(theta) / pi (Malley's method: a uniform disc point lifted).
SYLVA_HD inline glm::vec3 cosineHemisphere(const glm::vec3& n, float u1, float u2)
{
    const float r = sqrtf(u1), phi = 6.28318530717958648f * u2;
    const float x = r * cosf(phi), y = r * sinf(phi), z = sqrtf(fmaxf(0.0f, 1.0f - u1));
    // An orthonormal frame about n (Duff et al., "Building an Orthonormal Basis, Revisited").
    const float sign = copysignf(1.0f, n.z);
    const float a = -1.0f / (sign + n.z), b = n.x * n.y * a;
    const glm::vec3 t(1.0f + sign * n.x * n.x * a, sign * b, -sign * n.x);
    const glm::vec3 bt(b, sign + n.y * n.y * a, -n.y);
    return glm::normalize(x * t + y * bt + z * n);
}

} // namespace sylva
