// Plant-covered landscapes (Dietrich, Marmitt & Slusallek, "Terrain Guided Multi-Level Instancing of Highly
// Complex Plant Populations", sections 4.1-4.3, 5.2): the terrain cut into N x N cells, each mapped to a Wang
// tile (a square population of plant instances), a 2D kd-tree over the cells and a 2D tree per tile whose boxes
// reach the tile's top; plants are lifted onto the height field and thinned by the density rule while tracing,
// nothing is stored per cell beyond its tile and a bound of its ground (range and plane). Plain records here
// (host and device); the traversal is core/render/surfaces/landscape_trace.h, the build is landscape.cpp.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "core/accel/ray.h"
#include "core/base/defines.h"
#include "core/terrain/height_field.h"

namespace sylva {

// The shape of a landscape (RenderView::land). Cells are squares of cellSize metres in the DEM's frame,
// cell (cx, cz) = landCells[cz * cellsX + cx] spanning [cx, cx + 1) x [cz, cz + 1) cellSize; a tile of
// tileSize metres is mapped onto a cell scaled by tileScale = cellSize / tileSize (uniform: plants grow
// with the cell when tiles and cells do not conform, as in the seed's coarse rows of Table 1).
struct LandscapeLayout {
    uint32_t cellsX, cellsZ;
    float cellSize;                  // metres
    float tileScale;                 // cellSize / tileSize
    float invTileScale;
    uint32_t densityOn;              // the altitude rule (eq. 2, 3) is applied
    float dLower, dUpper;            // d at the lower and upper tree line
    float hLower, hUpper;            // the tree lines, terrain-frame heights (metres above the DEM's zero)
    uint32_t a, m;                   // eq. 2's multiplier and modulus
    uint32_t noSnow, noRock;         // no plants on snow (above the snow line) / on rock (steeper than the rock slope)
};

// A node of the top-level 2D kd-tree over cells: the min/max height of everything in its cells (ground
// plus the tile's extent, eq. 1). Its rectangle of cells is implicit: the root spans every cell, a node
// splits at the middle of its longer side (x on ties) into children child (low half) and child + 1.
// child == 0: a leaf (one cell). 16 bytes.
struct LandNode {
    glm::vec2 range;
    uint32_t child;
    uint32_t pad;
};

// One cell: the ground under its tile's plants' footprint, its tile. ground: the min/max height there; plane:
// a plane through it, the ground height at tile-frame (tx, tz) (tile metres, the cell corner at 0) within
// plane.x + plane.y tx + plane.z tz +- plane.w metres (DEM frame), a least-squares fit to the samples under the
// footprint with its largest deviation from them (the ground is linear between samples, so the bound holds
// everywhere on it) plus float rounding. The traversal raises a tile node or plant over the plane's range under
// it instead of the whole cell's (a cell on a slope spans tens of metres). 32 bytes.
struct LandCell {
    glm::vec2 ground;
    uint32_t tile;
    uint32_t pad;
    glm::vec4 plane;
};

// A tile: its 2D tree (tileNodes from nodeOffset, node 0 its root) and plants. yLo/yHi: the plants' boxes'
// vertical extent in the plant-centred tile frame (root at 0), the tile's bottom and top. 32 bytes.
struct TileRecord {
    uint32_t nodeOffset, plantOffset, plantCount, pad;
    float yLo, yHi;
    float pad2[2];
};

// A node of a tile's 2D tree: a horizontal rectangle (tile frame) and the vertical extent [ylo, yhi] of its
// plants' boxes in the plant-centred frame (root at 0), raised by the cell's ground range at traversal (splits
// stay horizontal-only; the per-node extent only lowers the top over short plants). count > 0: a leaf of plants
// [first, first + count) (tilePlants, absolute); else children first and first + 1 (tileNodes, absolute).
// 32 bytes.
struct TileNode {
    float lox, loz, hix, hiz;
    float ylo, yhi;
    uint32_t first, count;
};

// A plant of a tile: the map from its plant-centred tile frame (root at the origin, tile metres) to its
// geometry (rotation about +Y and 1 / scale, as an InstanceRecord's rows), its root (x, z) in the tile
// frame and its box in the plant-centred frame. densityId = id_inst + id_tile of eq. 2. 96 bytes; what a box
// test reads (x, z, lo, hi: the first 32 bytes, the array 32-byte aligned) lies in one cache line.
struct alignas(32) TilePlant {
    float x, z;
    glm::vec3 lo;
    glm::vec3 hi;
    uint32_t densityId;
    uint32_t species;
    uint32_t geometry;
    float scale;
    glm::vec4 row[3];
};
static_assert(sizeof(TilePlant) == 96);

// ---- the description (core/scene/scene.h's TerrainDesc carries these) ----

// A species in the tiles' population: Poisson-disk (dart throwing) with this spacing between roots (metres,
// tile frame), uniform scale in [scaleMin, scaleMax], uniform rotation about +Y.
struct TilePlantDesc {
    uint32_t species = 0;            // index into Scene::species (resolved from `speciesName` when read)
    std::string speciesName;
    double spacing = 12.0;
    float scaleMin = 0.8f, scaleMax = 1.2f;
};

struct TileSetDesc {
    double size = 160.0;             // metres, the tile's side
    uint64_t seed = 1;
    std::vector<TilePlantDesc> plants;
};

// A Wang tile's edge colours: south (z = 0), east (x = size), north (z = size), west (x = 0). South and
// north take one of `horizontal` colours, east and west one of `vertical`.
struct WangTile {
    int s = 0, e = 0, n = 0, w = 0;
};

struct TilingDesc {
    int horizontal = 2, vertical = 2;
    bool setGiven = false;           // `set` was written in the file (else every combination of colours)
    std::vector<WangTile> set;
    uint64_t seed = 1;
};

struct DensityDesc {
    bool enabled = false;
    double lower = 1000.0, upper = 2000.0;   // tree lines, world y metres
    float atLower = 1.0f, atUpper = 0.0f;    // d there (eq. 3; clamped beyond the lines)
    int a = 47, m = 256;
    bool noSnow = true, noRock = true;
};

// ---- host build ----

// What the build needs of one species: its geometry record (the full mesh), its bounds in its frame and its
// triangle count.
struct LandscapeSpecies {
    uint32_t geometry;
    glm::vec3 lo, hi;
    double triangles;
};

struct LandscapeStats {
    size_t tiles = 0, plantsPerTileMin = 0, plantsPerTileMax = 0, tilePlants = 0;
    size_t cells = 0;
    double instances = 0.0;          // potentially visible plant instances (every cell's tile, before thinning)
    double triangles = 0.0;          // their triangles
    double buildSeconds = 0.0;
};

struct LandscapeBuild {
    LandscapeLayout layout{};
    std::vector<LandNode> nodes;
    std::vector<LandCell> cells;
    std::vector<TileRecord> tiles;
    std::vector<TileNode> tileNodes;
    std::vector<TilePlant> plants;
    std::vector<WangTile> set;       // the tile set used (tiles[i] has set[i]'s edges)
    LandscapeStats stats;
};

// The Wang tile set of `d`: the given set, or every combination of colours. Throws Error when it is empty,
// a colour is out of range, or it cannot tile: some pair (south, west) of colours that an edge-matched
// tiling meets has no tile.
std::vector<WangTile> wangTileSet(const TilingDesc& d);

// An edge-matched tiling of cellsX x cellsZ cells (tile index per cell, row z, column x): cell (x, z)'s west
// edge matches (x - 1, z)'s east, its south edge (x, z - 1)'s north; among the tiles that match, one is
// picked by a hash of (seed, x, z): deterministic and aperiodic. Throws as wangTileSet.
std::vector<uint32_t> wangTiling(const std::vector<WangTile>& set, uint32_t cellsX, uint32_t cellsZ, uint64_t seed);

// The tiles' populations: for each species (in order) Poisson-disk roots; plants whose footprint crosses an
// edge are drawn once per edge colour and replicated into every tile with that colour on that edge (the same
// world position in both cells), interior plants per tile. Plants of each tile in its own frame [0, size]^2.
struct TilePopulation {
    std::vector<std::vector<TilePlant>> tiles;
};
TilePopulation populateTiles(const TileSetDesc& d, const std::vector<WangTile>& set, const std::vector<LandscapeSpecies>& species);

// The density rule's part of the layout (eq. 2, 3 and the snow/rock masks) from `density`, `terrainY` the
// terrain origin's world y. Only thins plants during traversal: the cells' bounds and trees do not depend on
// it, so a density edit changes these fields alone (the studio's viewport re-renders without a build).
// Throws Error when a < 1 or m < 2 with the rule on.
void setLandscapeDensity(LandscapeLayout& layout, const DensityDesc& density, double terrainY);

// Everything: tiling, populations, tile trees, cells' ground ranges and the cell kd-tree. `cells` per side of
// the terrain's longer extent (cellsX x cellsZ cover the footprint); snowY / rockCos as the terrain's colour
// rule (TerrainRecord::snowY, rockCos), `terrainY` the terrain origin's world y. Throws Error on
// bad input (cells < 1, no plants, an unknown species index, a set that cannot tile).
LandscapeBuild buildLandscape(const HeightField& field, uint32_t cells, const TileSetDesc& tiles, const TilingDesc& tiling,
                              const DensityDesc& density, double terrainY, float snowY, float rockCos,
                              const std::vector<LandscapeSpecies>& species);

// ---- shared by host and device ----

// The ground height of the height field's triangles at DEM-frame (x, z) and the triangle there; NaN outside
// the footprint.
SYLVA_HD inline float groundHeightAt(const HeightFieldView& h, float x, float z, uint32_t& tri)
{
    const float u = x / h.layout.dx, w = z / h.layout.dz;
    if (!(u >= 0.0f && u <= float(h.layout.nx - 1) && w >= 0.0f && w <= float(h.layout.nz - 1))) return NAN;
    uint32_t i = uint32_t(u), j = uint32_t(w);
    i = i > h.layout.nx - 2 ? h.layout.nx - 2 : i;
    j = j > h.layout.nz - 2 ? h.layout.nz - 2 : j;
    const float s = u - float(i), r = w - float(j);
    const float h00 = height_detail::sampleAt(h, i, j), h10 = height_detail::sampleAt(h, i + 1, j);
    const float h01 = height_detail::sampleAt(h, i, j + 1), h11 = height_detail::sampleAt(h, i + 1, j + 1);
    const uint32_t c = j * (h.layout.nx - 1) + i;
    if (s >= r) {
        tri = 2 * c;
        return h00 + s * (h10 - h00) + r * (h11 - h10);
    }
    tri = 2 * c + 1;
    return h00 + r * (h01 - h00) + s * (h11 - h01);
}

// Eq. 2: p = (a (id_inst + id_tile) mod m) / (m - 1) (a mask for the usual power-of-two m: no 64-bit division).
SYLVA_HD SYLVA_INLINE float densityValue(uint32_t id, uint32_t a, uint32_t m)
{
    const uint64_t x = uint64_t(a) * uint64_t(id);
    return float((m & (m - 1u)) == 0u ? (x & uint64_t(m - 1u)) : x % uint64_t(m)) / float(m - 1);
}

// Eq. 3: the threshold at terrain-frame height y, linear between the tree lines and clamped beyond them.
SYLVA_HD SYLVA_INLINE float densityThreshold(const LandscapeLayout& L, float y)
{
    if (!(L.hUpper > L.hLower)) return y < L.hLower ? L.dLower : L.dUpper;
    const float f = (y - L.hLower) / (L.hUpper - L.hLower);
    const float c = f < 0.0f ? 0.0f : (f > 1.0f ? 1.0f : f);
    return L.dLower + c * (L.dUpper - L.dLower);
}

// Where plant `p` of cell (cx, cz) stands: its DEM-frame root height `y` and the ground triangle `tri` there;
// false off the terrain.
SYLVA_HD SYLVA_INLINE bool landPlantHeight(const LandscapeLayout& L, const HeightFieldView& h, uint32_t cx, uint32_t cz, const TilePlant& p, float& y,
                                           uint32_t& tri)
{
    const float x = float(cx) * L.cellSize + L.tileScale * p.x, z = float(cz) * L.cellSize + L.tileScale * p.z;
    y = groundHeightAt(h, x, z, tri);
    return y == y;
}

// Whether a plant standing at height y on triangle tri is kept: by the density rule (p <= d), not on snow or
// rock when those masks are on. (The traversal asks only for plants whose lifted box the ray enters.)
SYLVA_HD SYLVA_INLINE bool landPlantKept(const LandscapeLayout& L, const HeightFieldView& h, float snowY, float rockCos, const TilePlant& p, float y,
                                         uint32_t tri)
{
    if (L.densityOn && densityValue(p.densityId, L.a, L.m) > densityThreshold(L, y)) return false;
    if (L.noSnow && y > snowY) return false;
    if (L.noRock && heightFieldNormal(h, tri).y < rockCos) return false;
    return true;
}

// Where plant `p` of cell (cx, cz) stands (DEM-frame root height `y`) and whether it grows there: on the
// terrain, kept by the density rule (p <= d), not on snow or rock when those masks are on.
SYLVA_HD inline bool landPlantGrows(const LandscapeLayout& L, const HeightFieldView& h, float snowY, float rockCos, uint32_t cx, uint32_t cz,
                                    const TilePlant& p, float& y)
{
    uint32_t tri = 0;
    return landPlantHeight(L, h, cx, cz, p, y, tri) && landPlantKept(L, h, snowY, rockCos, p, y, tri);
}

// The landscape's share of the forest-level LB grid (core/terrain/landscape_light.h): a lattice over the
// terrain frame whose node value (per channel, w unused) scales the LB lighting of the plants there.
// dims.x == 0: none (factor 1). 32 bytes.
struct LandLightLayout {
    glm::vec3 origin;                // terrain frame, node (0, 0, 0)
    float invSpacing;
    glm::ivec3 dims;
    uint32_t pad;
};

// The factor at terrain-frame point p: trilinear over the nodes (z fastest, as GridGeometry::index),
// clamped to the lattice; the ground's nodes hold the light of the first open node above them.
SYLVA_HD inline glm::vec3 landLightFactor(const LandLightLayout& L, const glm::vec4* nodes, const glm::vec3& p)
{
    if (L.dims.x == 0) return glm::vec3(1.0f);
    const glm::vec3 g = (p - L.origin) * L.invSpacing;
    const glm::vec3 c = glm::clamp(g, glm::vec3(0.0f), glm::vec3(L.dims - 1) - 1e-4f);
    const glm::ivec3 i = glm::ivec3(c);
    const glm::vec3 f = c - glm::vec3(i);
    glm::vec3 out(0.0f);
    for (int corner = 0; corner < 8; ++corner) {
        const int dx = corner >> 2, dy = (corner >> 1) & 1, dz = corner & 1;
        const float w = (dx ? f.x : 1.0f - f.x) * (dy ? f.y : 1.0f - f.y) * (dz ? f.z : 1.0f - f.z);
        out += w * glm::vec3(nodes[(size_t(i.x + dx) * size_t(L.dims.y) + size_t(i.y + dy)) * size_t(L.dims.z) + size_t(i.z + dz)]);
    }
    return out;
}

} // namespace sylva
