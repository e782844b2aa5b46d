// The forest-level LB grid over a landscape (Geist & Steele, "A Lighting Model for Fast Rendering of Forest
// Ecosystems", section 3): a coarse lattice over the terrain's footprint whose nodes under the ground are
// opaque black and whose columns carry the foliage of the plants that grow there (each cell's tile plants,
// lifted and thinned exactly as the traversal does, x their species' biomass at their scale), solved with the
// scene's sun as a beam (lb::solveGroundedLattice: absorption only, see forest_grid.cpp). The light arriving at
// each column's canopy over the unobstructed light scales the LB lighting of every landscape plant there
// (core/terrain/landscape.h landLightFactor, read by the shader): plants in a valley or on a wall the terrain
// shades, or inside a stand that takes the sun's level share, get less than those on open ground. One lattice
// per frame, nothing per plant: billions of plants cost what their cells cost. docs/RENDERING.md says what it
// leaves out.
#pragma once

#include <vector>

#include "core/lb/forest_grid.h"
#include "core/terrain/height_field.h"
#include "core/terrain/landscape.h"

namespace sylva {

// Nodes along the terrain's longer side: automatic, and the most an explicit lighting.forest_grid_resolution
// gives the landscape (larger values are clamped: the scalar solve's time grows with the fourth power).
inline constexpr int kLandLightAutoResolution = 64;
inline constexpr int kLandLightMaxResolution = 128;
// Plants tested for growth per build at most: above it every stride-th plant of a cell's tile is tested and
// counts for stride plants (the stride shows in the stats).
inline constexpr size_t kLandLightPlantTests = size_t(1) << 22;

struct LandscapeLightSettings {
    int resolution = lb::kAutoResolution;   // 0: kLandLightAutoResolution; else 4 .. 512, clamped to kLandLightMaxResolution
    float uniformSpread = 0.02f;            // as lb::ForestGridSettings::uniformSpread
    size_t maxPlantTests = kLandLightPlantTests;
};

struct LandscapeLight {
    LandLightLayout layout{};          // dims.x == 0: no lattice (no plant with biomass grows)
    std::vector<glm::vec4> nodes;      // per node (z fastest), the factor per channel
    GridGeometry geometry;             // terrain frame
    int resolution = 0;
    int steps = 0;
    uint32_t stride = 1;               // every stride-th plant of a tile tested (kLandLightPlantTests)
    double plantsTested = 0.0;         // plants tested for growth
    double plantsGrowing = 0.0;        // of those, growing and of a species with a density grid, x stride
    size_t cellsWithPlants = 0;
    // Over the cells with plants, the factor at their canopy's centre (median: the channels' mean).
    float minFactor = 1.0f, medianFactor = 1.0f, maxFactor = 1.0f;
    float spread = 0.0f;               // (max - min) / max
    bool uniform = true;               // spread < uniformSpread
    double seconds = 0.0;              // build + solve
};

// The landscape's arrays as buildLandscape made them (the host's copies), the terrain's snow height and rock
// cosine as the traversal takes them (TerrainRecord::snowY, rockCos), `species` per scene species
// (biomass 0: it takes no part), `params` the optics and sun. Throws Error on a resolution out of range or a
// plant's species out of range of `species`.
LandscapeLight solveLandscapeLight(const HeightField& field, const LandscapeLayout& layout, const std::vector<LandCell>& cells,
                                   const std::vector<TileRecord>& tiles, const std::vector<TilePlant>& plants, float snowY, float rockCos,
                                   const std::vector<lb::ForestSpecies>& species, const lb::LbParams& params,
                                   const LandscapeLightSettings& settings = {});

} // namespace sylva
