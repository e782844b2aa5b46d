// The landscape's record: cells of the terrain carrying Wang tiles of plants (landscape_trace.h walks them;
// their arrays are landNodes ... tilePlants and landLight of render_view.h).
#pragma once

#include <glm/glm.hpp>

#include "core/terrain/landscape.h"

namespace sylva {

struct LandscapeRecord {
    bool enabled;
    LandscapeLayout layout;
    glm::ivec2 baseCell;         // the cell under the camera (clamped to the grid)
    glm::vec3 base;              // camera-relative corner of baseCell at the terrain frame's y = 0, placed in double
    LandLightLayout lightLayout; // of landLight, terrain frame: the forest grid's factor on landscape plants (dims.x 0: none)
};

} // namespace sylva
