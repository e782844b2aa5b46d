// Deterministic random numbers and the sampling the shading code draws with (host and device).
#pragma once

#include <math.h>
#include <stdint.h>

#include <glm/glm.hpp>

#include "core/base/defines.h"
#include "core/base/hash.h"

namespace sylva {

// A hash-based random number in [0,1) (deterministic per pixel, sample and dimension).
SYLVA_HD SYLVA_INLINE float hashToUnit(uint32_t a, uint32_t b, uint32_t c)
{
    const uint32_t h = hashFinalize(a * 0x9E3779B1u ^ (b + 0x7F4A7C15u) * 0x85EBCA77u ^ (c + 0x165667B1u) * 0xC2B2AE3Du);
    return float(h >> 8) * (1.0f / 16777216.0f);
}

// Low-discrepancy samples: the first two dimensions of Sobol's sequence (a (0,2)-sequence in base 2: any 2^k
// consecutive points from 0 put one point in each of the 2^k elementary intervals of every shape), Owen-scrambled
// by hashing as Burley, "Practical Hash-based Owen Scrambling" (JCGT 2020) describes: the index shuffled and each
// dimension scrambled, with seeds from the pixel and the dimension, so every pixel and every pair of dimensions
// gets its own randomization and the points of a pixel's samples 0 .. 2^k - 1 stay stratified.
namespace lds {

SYLVA_HD SYLVA_INLINE uint32_t reverseBits(uint32_t x)
{
    x = ((x >> 1) & 0x55555555u) | ((x & 0x55555555u) << 1);
    x = ((x >> 2) & 0x33333333u) | ((x & 0x33333333u) << 2);
    x = ((x >> 4) & 0x0F0F0F0Fu) | ((x & 0x0F0F0F0Fu) << 4);
    x = ((x >> 8) & 0x00FF00FFu) | ((x & 0x00FF00FFu) << 8);
    return (x >> 16) | (x << 16);
}

// Owen scrambling of x (a fraction in its 32 bits): each bit flipped by a hash of the bits above it. On the
// reversed bits, Laine and Karras' permutation (each bit of the result depends only on the bits below it).
SYLVA_HD SYLVA_INLINE uint32_t owenScramble(uint32_t x, uint32_t seed)
{
    x = reverseBits(x);
    x += seed;
    x ^= x * 0x6C50B47Cu;
    x ^= x * 0xB82F1E52u;
    x ^= x * 0xC7AFE638u;
    x ^= x * 0x8D22F6E6u;
    return reverseBits(x);
}

// Sobol's second dimension for index i (its generator matrix: Pascal's triangle mod 2); the first is reverseBits(i).
SYLVA_HD SYLVA_INLINE uint32_t sobolSecond(uint32_t i)
{
    uint32_t v = 1u << 31, r = 0u;
    for (; i; i >>= 1, v ^= v >> 1)
        if (i & 1u) r ^= v;
    return r;
}

SYLVA_HD SYLVA_INLINE uint32_t mix(uint32_t a, uint32_t b)
{
    return hashFinalize(a * 0x9E3779B1u ^ (b + 0x7F4A7C15u) * 0x85EBCA77u);
}

SYLVA_HD SYLVA_INLINE float toUnit(uint32_t x) { return float(x >> 8) * (1.0f / 16777216.0f); }

// Point `index` of the scrambled 2D sequence with seed `seed` (a pixel and a pair of dimensions), in [0,1)^2.
SYLVA_HD SYLVA_INLINE glm::vec2 sample2(uint32_t index, uint32_t seed)
{
    const uint32_t i = owenScramble(index, mix(seed, 0x5851F42Du));   // shuffled order: an aligned block stays one
    return glm::vec2(toUnit(owenScramble(reverseBits(i), mix(seed, 0x68E31DA4u))), toUnit(owenScramble(sobolSecond(i), mix(seed, 0xB5297A4Du))));
}

// The same in one dimension (the scrambled van der Corput sequence).
SYLVA_HD SYLVA_INLINE float sample1(uint32_t index, uint32_t seed)
{
    const uint32_t i = owenScramble(index, mix(seed, 0x5851F42Du));
    return toUnit(owenScramble(reverseBits(i), mix(seed, 0x68E31DA4u)));
}

} // namespace lds

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
