// The forest-level LB grid (Geist & Steele, "A Lighting Model for Fast Rendering of Forest Ecosystems", section
// 3): a coarse lattice over the whole scene whose node density comes from the plants in its cells, solved with
// the scene's boundary (sun, and sky when asked), giving each instance a per-channel factor that scales its
// species' (per-species, unchanged) lighting grid.
//
// Density: each instance spreads its species' biomass B (sum of the species grid's densities x its
// cell volume, x scale^3) evenly over its crown box (the species grid's occupied bounds, scaled and
// moved); a coarse node gets the overlap of that box with its cell, as mean density over the cell x
// (coarse spacing / the species grid's spacing): a coarse step crosses that many fine cells. That optical
// depth x (summed over plants) becomes the node's density rho = (1 - exp(-sigma_t x)) / sigma_t, so one
// coarse step lets through the Beer-Lambert transmittance of the depth (at most 1; sigma_t the largest
// channel's; ForestGridResult::density holds rho). Continuous in the instance's position and scale.
// Factor: the forest grid's light at the instance's crown centre divided by the light there on the same
// lattice with that instance alone (its own shading is already in its species grid): exactly 1 for an
// isolated plant, < 1 where other plants shade it (> 1 where they scatter more light in than they take).
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "core/grid/grid.h"
#include "core/lb/lb_params.h"

namespace sylva::lb {

// The six axis-aligned faces a plant's directional factors are given for: surfaces facing +x, -x, +y, -y,
// +z, -z (world axes). The renderer (core/render/shade.h forestFactor) blends them in this order.
inline constexpr int kFaces = 6;
inline constexpr int kFaceNormals[kFaces][3] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};

// A species as the forest grid sees it, in its own frame (scale 1, origin at the plant's position).
struct ForestSpecies {
    glm::dvec3 boxMin{0.0}, boxMax{0.0};   // occupied bounds of its density grid (node cells with density > 0)
    double biomass = 0.0;                  // sum of density x cell volume (m^3)
    double spacing = 1.0;                  // its density grid's spacing (m)
};
ForestSpecies forestSpecies(const DensityGrid& density);

// A plant's biomass over its fine spacing, both scaled: what splatDepth spreads (m^2 of density).
double plantExtinctionVolume(const ForestSpecies& s, float scale);

// Adds the optical depth of foliage spread evenly over the box [lo, hi] to the coarse lattice g (z fastest): a
// node gets its cell's overlap with the box as the mean fine density over the cell x (coarse spacing / fine
// spacing), the fine steps a coarse step crosses. extinctionVolume: plantExtinctionVolume, summed over the
// plants the box stands for. Continuous in the box; nothing for an empty box.
void splatDepth(const glm::dvec3& lo, const glm::dvec3& hi, double extinctionVolume, const GridGeometry& g, std::vector<float>& depth);

struct ForestPlant {
    glm::dvec3 position{0.0};   // of the species' origin, world metres
    float scale = 1.0f;
    int species = 0;
};

// ForestGridSettings::resolution 0: kAutoCellsPerCrown nodes across the median crown, at most
// kAutoMaxResolution along the extent. `sylva study scene` (docs/ACCURACY.md "Scene scale"): on its stand the
// grid improves the picture over none from about 4 cells a crown (face factors need 3, see forest_grid.cpp);
// the cap keeps the default forest (8 m crowns over 220 m: 1.0 cells a crown) under 1 s on 2 cores
// (bench_forest_grid: 0.85 s at 32, 1.5-1.6 s at 48 on a slow day).
inline constexpr int kAutoResolution = 0;
inline constexpr double kAutoCellsPerCrown = 4.0;
inline constexpr int kAutoMaxResolution = 32;

struct ForestGridSettings {
    int resolution = kAutoResolution;   // nodes along the longest horizontal extent (4 .. 512), or kAutoResolution
    float uniformSpread = 0.02f;    // auto: factors within this (max - min) / max count as uniform exposure
};

struct ForestGridResult {
    int resolution = 0;             // nodes along the longest horizontal extent as used (automatic: as chosen)
    GridGeometry geometry;
    std::vector<float> density;     // coarse node density as solved (rho above), z fastest
    LightingGrid lighting;          // the forest grid's solve (unit intensity boundary)
    std::vector<glm::vec3> factors; // per plant, per channel
    // Per plant and face (kFaceNormals), per channel: the irradiance on a surface facing that way in the
    // forest grid over the same with the plant alone, at its crown centre (the light from the open side of a
    // stand's edge tree keeps ~1, the light from the stand less). Equal to `factors` where the solve kept no
    // directions (a window or forest grid over kSmallNodes nodes).
    std::vector<std::array<glm::vec3, kFaces>> faceFactors;
    float minFactor = 1.0f, maxFactor = 1.0f;   // over plants and channels of `factors`
    float medianFactor = 1.0f;      // median over plants of the channels' mean of `factors`
    float minFaceFactor = 1.0f, maxFaceFactor = 1.0f;   // over plants, faces and channels of faceFactors
    bool uniform = true;            // (max - min) / max < settings.uniformSpread over factors and faceFactors
    int steps = 0;
    double seconds = 0.0;           // build + solve (forest grid and the per-plant solves)
};

// Lattices up to this many nodes run through a scalar loop that keeps the directions (faceFactors); larger
// ones through the full solver (no directions).
inline constexpr size_t kSmallNodes = size_t(1) << 17;

// Throws Error for bad settings, a species index out of range or a non-positive scale. `params` gives the
// optics, boundary (sun or params.boundary) and storage; steps are 2 x the forest grid's longest edge for
// the forest grid and 4 x its window's for each plant's own solve (both converge: an isolated plant gets 1).
ForestGridResult solveForestGrid(const std::vector<ForestPlant>& plants, const std::vector<ForestSpecies>& species,
                                 const LbParams& params, const ForestGridSettings& settings = {});

// The landscape's lattice (core/terrain/landscape_light.h fills its inputs), 2.5D: per node the optical depth
// of the plants that grow there (splatDepth) and whether it lies under the ground (solid: opaque black,
// absorbing what arrives). A column's foliage is a layer on its ground, far thinner than a node: all of its
// depth goes into the column's first open node. Solved with params' optics and boundary through the forest
// grid's scalar loop for 2 x the longest edge (any size: it keeps the solid nodes), the boundary's
// upward-travelling directions dropped (the ground beyond the lattice absorbs them) and the foliage's
// extinction all absorbed, no scattering (see forest_grid.cpp). Returns per column and channel the light
// arriving at its first open node (before that node's own foliage acts: a plant's own canopy, which its
// species grid holds, is not in it) over the empty lattice's (the boundary's unobstructed value), in every
// node of the column: 1 on open level ground, < 1 in a valley or on a slope the terrain shades and inside
// a stand whose neighbours take the light from the side. *steps (when given): the steps run. Throws Error
// when the arrays' sizes differ from the lattice's.
LightingGrid solveGroundedLattice(const GridGeometry& g, std::vector<float> depth, const std::vector<uint8_t>& solid,
                                  const LbParams& params, int* steps = nullptr);

// One line for stats: resolution, dims, time, factor range, and whether exposure is uniform.
std::string forestGridSummary(const ForestGridResult& r);

} // namespace sylva::lb
