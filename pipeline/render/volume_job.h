// The volumes of a scene ready to trace: LB lighting solved through the grid cache (like a species'),
// blackbody tables for emission.
#pragma once

#include "core/base/progress.h"
#include "core/scene/scene.h"
#include "pipeline/lighting_job.h"

namespace sylva {

class Backend;
class GridCache;

// The LB parameters a volume's grid is solved with: its optics, the scene's sun (in the grid frame:
// placements share one solve, as a species' instances do), its steps and storage.
lb::LbParams volumeLightingParams(const Scene& scene, const VolumeDesc& v);

// A copy of `scene` whose volumes carry their LB lighting (when `needLighting` and the tracer uses it;
// solved or loaded from the cache, key: density content + parameters, stages "VOLUME: light" in log) and
// their blackbody table (when they have a temperature grid). The volumes' data must be loaded
// (loadSceneVolumes). Throws Error or Cancelled.
Scene lightSceneVolumes(const Scene& scene, GridCache* cache, bool needLighting, Progress* progress = nullptr, JobLog* log = nullptr,
                        Backend* backend = nullptr);

// kVolumeBlackbodySize linear-sRGB blackbody colours from kVolumeBlackbodyLo to kVolumeBlackbodyHi kelvin
// (CIE 1931 through core/color), divided by the luminance of a 6500 K blackbody; negative components 0.
std::vector<glm::vec3> volumeBlackbodyTable();

} // namespace sylva
