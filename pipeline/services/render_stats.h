// The acceleration structures' sizes in the units `sylva render --stats` prints.
#pragma once

#include "core/render/render_scene.h"

namespace sylva {

struct AccelSummary {
    double totalBytes = 0.0;                  // every structure the run traverses plus the host's 8-wide copies
    double bytesPerInstancedTriangle = 0.0;   // totalBytes / instanced triangles (at least 1)
    double bytesPerInstance = 0.0;            // (top level + instance records) / instances (at least 1)
};
AccelSummary summarizeAccel(const AccelStats& stats);

} // namespace sylva
