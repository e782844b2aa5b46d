// Analytic spheres (lookdev probes: grey balls placed beside the plants): the smallest surface kind, and
// the example docs/ARCHITECTURE.md walks through for adding one. Placed by code (RenderScene::sphereRecords,
// camera-relative); spheres_trace.h intersects and shades them.
#pragma once

#include <cstdint>

#include <glm/glm.hpp>

namespace sylva {

// One sphere, camera-relative. 32 bytes.
struct SphereRecord {
    glm::vec3 centre;
    float radius;
    glm::vec3 albedo;        // Lambertian
    uint32_t pad;
};
static_assert(sizeof(SphereRecord) == 32);

struct SpheresRecord {
    uint32_t count;          // of RenderView::sphereRecords
};

} // namespace sylva
