// The ground plane's record: a horizontal Lambertian plane (ground_trace.h intersects and shades it).
#pragma once

#include <glm/glm.hpp>

namespace sylva {

struct GroundRecord {
    bool enabled;            // the scene's ground plane, where no terrain replaces it
    float y;                 // camera-relative height of the plane
    glm::vec3 color;         // its albedo, and the terrain's below the rock slope and snow line
};

} // namespace sylva
