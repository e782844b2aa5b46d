// The height-field terrain's record (terrain_trace.h intersects and shades it; its samples are the arrays
// terrainHeights and terrainRanges of render_view.h).
#pragma once

#include <cstdint>

#include <glm/glm.hpp>

#include "core/terrain/height_field.h"

namespace sylva {

struct TerrainRecord {
    bool enabled;
    HeightFieldLayout layout;    // of terrainHeights / terrainRanges
    glm::vec3 origin;            // camera-relative position of the terrain frame's origin (its first sample)
    glm::vec3 rock, snow;        // albedo above the rock slope and the snow line (ground.color below)
    float rockCos;               // normals with a y below this are rock
    float snowY;                 // terrain-frame height above which the ground is snow (> max height: none)
    glm::vec3 base;              // camera-relative position of sample (baseI, baseJ), placed in double: the height
    int32_t baseI, baseJ;        // field is traced relative to it (precise near the camera anywhere)
};

// The terrain's colour rule: at terrain-frame height y on a surface whose unit normal has y component ny, snow above
// snowY, rock where ny < rockCos (steeper than the rock slope), else the ground's colour. The shader's (shadeTerrain)
// and the glTF export's vertex colours.
SYLVA_HD SYLVA_INLINE glm::vec3 terrainAlbedo(float y, float ny, float snowY, float rockCos, const glm::vec3& snow, const glm::vec3& rock,
                                              const glm::vec3& ground)
{
    return y > snowY ? snow : (ny < rockCos ? rock : ground);
}

} // namespace sylva
