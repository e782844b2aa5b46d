// Digital elevation models in, as height fields: 16-bit PNG (as resources/terrain/sthelens_10m.png), 8-bit images,
// float TIFF or EXR, read with OpenImageIO.
#pragma once

#include <memory>
#include <string>

#include "core/scene/scene.h"
#include "core/terrain/height_field.h"

namespace sylva {

// Reads the DEM at `path`: its first channel, row 0 at z = 0, column 0 at x = 0; height = DEM unit x
// heightScale, where a DEM unit is the stored integer of integer images (PNG's 0..65535; any colour
// space the file names is ignored: the values are heights, not colours) and the stored value of float
// images. Throws Error naming the file: missing or unreadable, not an image, smaller than 2 x 2, a
// sample NaN or infinite, a spacing or scale not finite and > 0, or too large for the memory left
// (checked before the heights are allocated).
HeightField loadDem(const std::string& path, double spacing, double heightScale);

// Loads scene.terrain's DEM into scene.terrain.field when it has a DEM and no field yet (shared by the
// scene's copies). Throws Error as loadDem.
void loadSceneTerrain(Scene& scene);

} // namespace sylva
