// A sky on the host: a constant colour, a Preetham sky or an environment map, with its sun, as the
// renderer, the LB boundary and the studio take it: its per-ray view (core/sky/sky.h), its virtual
// directional lights (core/sky/virtual_lights.h) and its integrals over the LB's lattice directions.
#pragma once

#include <memory>
#include <vector>

#include <glm/glm.hpp>

#include "core/sky/env_map.h"
#include "core/sky/preetham.h"
#include "core/sky/sky.h"
#include "core/sky/virtual_lights.h"

namespace sylva::sky {

struct Sky {
    SkyKind kind = SkyKind::Constant;
    glm::vec3 constant{0.55f, 0.70f, 0.95f};   // Constant
    PreethamSky preetham;                      // Preetham (built by makePreetham)
    std::shared_ptr<const EnvMap> map;         // Map: cleaned, its sun taken out when it had one
    float rotationDeg = 0.0f, intensity = 1.0f;   // Map
    SkySun sun;                                // world direction (the map's rotation applied)

    // Plain data for per-ray code; points into *map, valid while this Sky (or a copy of it) lives.
    SkyView view() const;
};

// A constant sky with the given sun (e.g. today's scene: sky colour and the blackbody sun).
Sky constantSky(glm::vec3 radiance, const SkySun& sun);
// A Preetham sky and its sun (preethamSun).
Sky preethamSky(const PreethamParams& params, const CieTable& cie);
// A map sky: `map` cleaned already (cleanEnvMap); with findSun its sun is taken out (extractSun) and becomes
// the sky's sun (rotated, x intensity); *found (optional) says what was found. Throws sylva::Error for a bad
// map, a non-finite rotation or a negative or non-finite intensity.
Sky mapSky(EnvMap map, float rotationDeg, float intensity, bool findSun = true, FoundSun* found = nullptr);

// The sky (without its sun) as an unrotated-world equirectangular map: a map sky's own pixels x intensity
// resampled when rotated (or returned as is when not), an analytic sky sampled at pixel centres (width
// x width/2; for a map sky width is ignored unless the map must be resampled).
EnvMap skyToMap(const Sky& sky, int width = 512);

// The sky's virtual directional lights (the sun kept apart: it is sky.sun). A map sky is partitioned at
// its own resolution with its rotation and intensity; other skies through skyToMap(width). upperOnly: the
// upper hemisphere's alone (virtualLights), for a scene whose ground plane hides everything below it.
std::vector<VirtualLight> skyLights(const Sky& sky, int count, int width = 512, bool upperOnly = false);

// Integral of the sky's radiance (without its sun) over the whole sphere, RGB: what the LB boundary
// distributes; and the same over the share of the sphere nearest to each of `directions` (the LB
// lattice's, any length > 0; the shares sum to the total). Computed over the map of skyToMap(width) (a
// map sky: its own pixels, rotated), each pixel given whole to the direction with the largest cosine (the
// first of equals); upperOnly: only the pixels above the horizon (the sky; below it is the ground).
glm::dvec3 skyTotal(const Sky& sky, int width = 512);
std::vector<glm::dvec3> skyDirectionShares(const Sky& sky, const std::vector<glm::vec3>& directions, int width = 512,
                                           bool upperOnly = false);

} // namespace sylva::sky
