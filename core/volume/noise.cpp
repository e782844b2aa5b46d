// Improved Perlin noise: 12 edge gradients, quintic fade, seeded permutation.
#include "core/volume/noise.h"

#include <cmath>

namespace sylva::volume {
namespace {

float fade(float t) { return t * t * t * (t * (t * 6.0f - 15.0f) + 10.0f); }
float lerp(float a, float b, float t) { return a + t * (b - a); }

// Dot of the offset with one of the 12 cube-edge gradients (Perlin 2002's grad()).
float grad(int hash, float x, float y, float z)
{
    const int h = hash & 15;
    const float u = h < 8 ? x : y;
    const float v = h < 4 ? y : (h == 12 || h == 14 ? x : z);
    return ((h & 1) ? -u : u) + ((h & 2) ? -v : v);
}

} // namespace

PerlinNoise::PerlinNoise(uint64_t seed)
{
    std::array<uint8_t, 256> p{};
    for (int i = 0; i < 256; ++i) p[size_t(i)] = uint8_t(i);
    uint64_t state = seed;
    for (int i = 255; i > 0; --i) {
        const int j = int(splitmix64(state) % uint64_t(i + 1));
        const uint8_t t = p[size_t(i)];
        p[size_t(i)] = p[size_t(j)];
        p[size_t(j)] = t;
    }
    for (int i = 0; i < 512; ++i) m_perm[size_t(i)] = p[size_t(i & 255)];
}

float PerlinNoise::noise(const glm::vec3& q) const
{
    const float fx = std::floor(q.x), fy = std::floor(q.y), fz = std::floor(q.z);
    const int X = int(fx) & 255, Y = int(fy) & 255, Z = int(fz) & 255;
    const float x = q.x - fx, y = q.y - fy, z = q.z - fz;
    const float u = fade(x), v = fade(y), w = fade(z);
    const auto& P = m_perm;
    const int A = P[size_t(X)] + Y, AA = P[size_t(A)] + Z, AB = P[size_t(A + 1)] + Z;
    const int B = P[size_t(X + 1)] + Y, BA = P[size_t(B)] + Z, BB = P[size_t(B + 1)] + Z;
    return lerp(lerp(lerp(grad(P[size_t(AA)], x, y, z), grad(P[size_t(BA)], x - 1, y, z), u),
                     lerp(grad(P[size_t(AB)], x, y - 1, z), grad(P[size_t(BB)], x - 1, y - 1, z), u), v),
                lerp(lerp(grad(P[size_t(AA + 1)], x, y, z - 1), grad(P[size_t(BA + 1)], x - 1, y, z - 1), u),
                     lerp(grad(P[size_t(AB + 1)], x, y - 1, z - 1), grad(P[size_t(BB + 1)], x - 1, y - 1, z - 1), u), v),
                w);
}

float PerlinNoise::fbm(const glm::vec3& p, int octaves, float lacunarity, float gain) const
{
    float sum = 0.0f, amp = 1.0f, norm = 0.0f;
    glm::vec3 q = p;
    for (int o = 0; o < octaves; ++o) {
        sum += amp * noise(q);
        norm += amp;
        amp *= gain;
        q *= lacunarity;
    }
    return norm > 0.0f ? sum / norm : 0.0f;
}

} // namespace sylva::volume
