// The CPU render loop over 8x8 pixel tiles, the film of shading parts, and how render modes combine them.
#pragma once

#include <vector>

#include "core/base/progress.h"
#include "core/render/render_view.h"
#include "core/render/shade.h"

namespace sylva {

// Per-pixel shading parts of a frame, row-major, top row first.
struct Film {
    int width = 0, height = 0;
    std::vector<SampleParts> pixels;
};

// Traces every pixel of v.width x v.height with v.spp samples, in parallel over 8x8 tiles.
// Reports progress per tile row; throws Cancelled when cancelled.
Film renderFilm(const RenderView& v, Progress* progress = nullptr);

// Linear RGB of a render mode: full = local + indirect, local = sun light only, ambient = local + a
// constant ambient x albedo with the constant chosen so the mean luminance equals that of full,
// lb = indirect only; the sky is added where samples saw it. ambientOut receives the constant.
std::vector<glm::vec3> composeMode(const Film& film, RenderMode mode, const glm::vec3& sky, float* ambientOut = nullptr);

} // namespace sylva
