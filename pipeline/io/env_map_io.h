// Equirectangular environment maps (.exr, .hdr, anything OpenImageIO reads as float) into sky::EnvMap,
// checked and cleaned (core/sky/env_map.h).
#pragma once

#include <functional>
#include <string>

#include "core/sky/env_map.h"

namespace sylva {

struct Scene;

struct EnvMapFile {
    sky::EnvMap map;                  // cleaned: no negative, NaN or infinite values
    sky::EnvMapCleanReport cleaned;   // what the cleaning changed
};

// Reads the first subimage's first three channels (a grey map: its one channel in all three) as linear
// radiance and cleans it (cleanEnvMap with spikeRatio). Throws sylva::Error naming the file when it is
// missing, not an image, empty, 1 x N or not 2:1, or cannot be decoded.
EnvMapFile readEnvMap(const std::string& path, float spikeRatio = 16.0f);

// One line for the log: "PATH: 512 x 256, cleaned: 1234 negative pixels -> 0, ..." (or "clean").
std::string envMapCleanSummary(const std::string& path, const EnvMapFile& file);

// Builds scene.skyModel.built for a Preetham sky (the scene's sun direction, turbidity, scale) or an HDR map
// (readEnvMap of skyModel.path, its sun taken out when sunFromMap, rotated and scaled); nothing for the
// constant sky or when already built. Returns the map's envMapCleanSummary line (empty for other skies).
// Throws sylva::Error for a bad map or Preetham parameters the model refuses (sun below -10 degrees).
// read: how the map file is read (default readEnvMap; the studio passes one that keeps maps in memory, so a
// rotation or intensity edit does not read the file again).
using EnvMapReader = std::function<EnvMapFile(const std::string& path)>;
std::string loadSceneSky(Scene& scene, const EnvMapReader& read = {});

} // namespace sylva
