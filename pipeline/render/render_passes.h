// Render passes: the film's parts as the layers a compositor reads (Cycles' names), into one multi-layer EXR.
#pragma once

#include <string>
#include <vector>

#include "core/render/cryptomatte.h"
#include "core/render/render_cpu.h"
#include "core/scene/scene.h"

namespace sylva {

// One Cryptomatte type of a frame (Jonah Friedman, Andrew C. Jones, Psyop, "Cryptomatte" specification): its
// layers <name>00, <name>01, ... hold the ranked (ID, coverage) pairs, its manifest the names the frame shows.
struct CryptomatteLayer {
    std::string name;                                   // CryptoObject, CryptoMaterial or CryptoAsset
    CryptomatteRanks ranks;
    std::vector<std::pair<std::string, float>> manifest;   // name and ID, sorted by name
};

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
    std::vector<CryptomatteLayer> cryptomatte;   // none, or CryptoObject, CryptoMaterial, CryptoAsset (cryptomatteLayers)
};

// The passes of a film in `mode` (ambient: the constant composeMode computes for the same film).
RenderPasses renderPasses(const Film& film, RenderMode mode, const glm::vec3& sky);

// What a camera sample's first hit is called in each Cryptomatte type (docs/RENDERING.md "Cryptomatte"):
// object: "<species>.<i>" for scene instance i (a group's: "<group>.<i>"), "<species>.landscape.<cell>.<plant>"
// for a landscape plant, "ground", "terrain", "sphere.<i>"; material: "<species>/leaf" or "<species>/bark",
// "ground", "terrain", "sphere"; asset: the species, else as the material.
struct MatteNames {
    std::string object, material, asset;
};
MatteNames matteNames(const MatteHit& hit, const Scene& scene);

// The three Cryptomatte types of a frame of `scene` (CryptoObject, CryptoMaterial, CryptoAsset) from its camera
// samples' first hits (renderMatteFilm of the frame's view).
std::vector<CryptomatteLayer> cryptomatteLayers(const MatteFilm& film, const Scene& scene);

// The EXR channel names, in the order writeRenderPasses writes them: Combined.R/G/B, DiffDir.R/G/B,
// DiffInd.R/G/B, DiffCol.R/G/B, Env.R/G/B, Normal.X/Y/Z, Depth.Z, Alpha.A; then per Cryptomatte type
// <name>00.R/G/B/A (ID rank 0, its coverage, ID rank 1, its coverage), <name>01.R/G/B/A, ...
const std::vector<std::string>& renderPassChannels();
std::vector<std::string> renderPassChannels(const RenderPasses& passes);

// One multi-layer EXR of 32-bit float channels named as renderPassChannels(passes), with each Cryptomatte
// type's metadata in the header (cryptomatte/<key>/name, hash, conversion, manifest). Error for another extension.
void writeRenderPasses(const std::string& path, const RenderPasses& passes);

} // namespace sylva
