// Improved Perlin noise (Perlin 2002) and its fBm sum, written here, seeded and deterministic.
// The permutation comes from the seed through splitmix64 and a Fisher-Yates shuffle of our own, so
// the same seed gives the same values on every platform and standard library.
#pragma once

#include <array>
#include <cstdint>

#include <glm/glm.hpp>

namespace sylva::volume {

class PerlinNoise {
public:
    explicit PerlinNoise(uint64_t seed = 0);
    // Gradient noise in about [-1, 1]; 0 at every integer lattice point; smooth (C2, quintic fade).
    float noise(const glm::vec3& p) const;
    // fBm: sum over octaves o of gain^o * noise(p * lacunarity^o), divided by the sum of gain^o, so
    // |fbm| stays within the range of one octave (about [-1, 1]). octaves >= 1.
    float fbm(const glm::vec3& p, int octaves, float lacunarity = 2.0f, float gain = 0.5f) const;

private:
    std::array<uint8_t, 512> m_perm{};
};

// splitmix64: the project's seed mixer for volume sources (deterministic, platform independent).
inline uint64_t splitmix64(uint64_t& state)
{
    uint64_t z = (state += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
}

} // namespace sylva::volume
