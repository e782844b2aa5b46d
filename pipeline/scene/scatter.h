// Scatter: many instances of one species placed at random over a rectangle of the ground, for
// approximate instancing (the studio's scatter tool). Deterministic per seed on every platform.
#pragma once

#include <cstdint>
#include <vector>

#include "core/scene/scene.h"

namespace sylva {

struct ScatterSpec {
    uint32_t species = 0;                  // index into Scene::species
    int count = 100;                       // instances to add, >= 0
    glm::dvec2 min{-10.0, -10.0};          // world x, z of the rectangle's corners, metres (min <= max)
    glm::dvec2 max{10.0, 10.0};
    double height = 0.0;                   // world y of every instance (the ground's height)
    bool randomRotation = true;            // rotation about +Y uniform in [0, 360) degrees; off: 0
    float scaleMin = 1.0f, scaleMax = 1.0f;   // uniform scale in [scaleMin, scaleMax], 0 < min <= max
    uint64_t seed = 1;
    glm::dvec2 clearCentre{0.0, 0.0};      // world x, z of a point kept clear (the studio: the camera's eye)
    double clearRadius = 0.0;              // metres: no instance within it of clearCentre (horizontally); 0: none
};

// The instances a spec describes: x uniform in [min.x, max.x], z in [min.y, max.y], y = height,
// rotation (0, r, 0), scale as given. The same spec gives the same instances (splitmix64, no
// standard-library distributions). A position within clearRadius of clearCentre is drawn again (up to
// kScatterClearTries times; an instance that still falls there is left out, so fewer than count may
// come back: the caller reports it). Throws Error naming the bad field (negative count, min > max,
// a scale <= 0 or min > max, a negative clearance, non-finite values) or when the whole area lies
// within the clearance.
inline constexpr int kScatterClearTries = 1000;
std::vector<InstanceDesc> scatterInstances(const ScatterSpec& spec);

} // namespace sylva
