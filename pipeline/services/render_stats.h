// The acceleration structures' sizes in the units `sylva render --stats` prints.
#pragma once

#include <string>

#include "core/render/render_scene.h"

namespace sylva {

struct AccelSummary {
    double totalBytes = 0.0;                  // every structure the run traverses plus the host's 8-wide copies
    double bytesPerInstancedTriangle = 0.0;   // totalBytes / instanced triangles (at least 1)
    double bytesPerInstance = 0.0;            // (top level + instance records) / instances (at least 1)
};
AccelSummary summarizeAccel(const AccelStats& stats);

// `sylva render --stats`'s line on the forest-level LB grid (lighting.forest_grid): mode, resolution and
// dims, build + solve time, the factors' min / median / max over instances, and whether it was applied or
// skipped (auto, exposure uniform); and a second line on its share over the landscape's plants
// (LandscapeLightStats) where the scene has a landscape; empty when the scene has it off.
std::string forestGridLine(const ForestGridStats& stats, const LandscapeLightStats& landscape);

} // namespace sylva
