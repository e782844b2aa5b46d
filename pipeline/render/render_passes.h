// Render passes: the film's parts as the layers a compositor reads (Cycles' names), into one multi-layer EXR.
#pragma once

#include <string>
#include <vector>

#include "core/render/render_cpu.h"

namespace sylva {

// The passes of a frame, row-major, top row first (docs/RENDERING.md, "Render passes"). In every mode
// combined = diffCol * (diffDir + diffInd) + env per channel, to float rounding, and combined is the
// picture a plain .exr of the same mode holds.
struct RenderPasses {
    int width = 0, height = 0;
    float ambient = 0.0f;              // the ambient mode's constant (0 in other modes)
    std::vector<glm::vec3> combined;   // Combined: the mode's linear picture, sky included
    std::vector<glm::vec3> diffDir;    // DiffDir: direct (sun) light, divided by diffCol
    std::vector<glm::vec3> diffInd;    // DiffInd: indirect (LB; ground: sky light; ambient mode: the constant), divided by diffCol
    std::vector<glm::vec3> diffCol;    // DiffCol: the surface colour (albedo), 0 for the sky
    std::vector<glm::vec3> env;        // Env: the sky, times the share of samples that saw it
    std::vector<glm::vec3> normal;     // Normal: unit normal facing the camera (world orientation), averaged; 0 for the sky
    std::vector<float> depth;          // Depth: distance along the camera's forward axis, nearest over the samples; kSkyDepth for the sky
    std::vector<float> alpha;          // Alpha: coverage, 1 - the share of samples that saw the sky
};

// The passes of a film in `mode` (ambient: the constant composeMode computes for the same film).
RenderPasses renderPasses(const Film& film, RenderMode mode, const glm::vec3& sky);

// The EXR channel names, in the order writeRenderPasses writes them: Combined.R/G/B, DiffDir.R/G/B,
// DiffInd.R/G/B, DiffCol.R/G/B, Env.R/G/B, Normal.X/Y/Z, Depth.Z, Alpha.A.
const std::vector<std::string>& renderPassChannels();

// One multi-layer EXR of 32-bit float channels named as renderPassChannels. Error for another extension.
void writeRenderPasses(const std::string& path, const RenderPasses& passes);

} // namespace sylva
