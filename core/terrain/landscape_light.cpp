// The forest-level LB grid over a landscape (landscape_light.h).
#include "core/terrain/landscape_light.h"

#include <algorithm>
#include <chrono>
#include <cmath>

#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include "core/base/error.h"

namespace sylva {

namespace {

// A cell's growing plants: counts, their extinction volume and mean crown bottom and top (weighted by it), for
// the stats' sample at the cell's canopy.
struct CellCanopy {
    double extinction = 0.0;   // sum of plantExtinctionVolume x stride
    double yLo = 0.0, yHi = 0.0;   // weighted sums, then means (terrain frame)
    double tested = 0.0, growing = 0.0;
};

// The mean ground height over node column (x, z)'s square of side h: 4 x 4 samples, each clamped into the
// footprint (the lattice's margin continues the terrain's edge).
double columnGround(const HeightField& f, double x, double z, double h)
{
    const double xMax = double(f.layout.nx - 1) * double(f.layout.dx), zMax = double(f.layout.nz - 1) * double(f.layout.dz);
    double sum = 0.0;
    for (int a = 0; a < 4; ++a)
        for (int b = 0; b < 4; ++b) {
            const double sx = std::clamp(x + h * ((a + 0.5) / 4.0 - 0.5), 0.0, xMax);
            const double sz = std::clamp(z + h * ((b + 0.5) / 4.0 - 0.5), 0.0, zMax);
            sum += surfaceHeight(f, sx, sz);
        }
    return sum / 16.0;
}

} // namespace

LandscapeLight solveLandscapeLight(const HeightField& field, const LandscapeLayout& layout, const std::vector<LandCell>& cells,
                                   const std::vector<TileRecord>& tiles, const std::vector<TilePlant>& plants, float snowY, float rockCos,
                                   const std::vector<lb::ForestSpecies>& species, const lb::LbParams& params,
                                   const LandscapeLightSettings& settings)
{
    const int resolution = settings.resolution;
    const auto t0 = std::chrono::steady_clock::now();
    if (resolution != lb::kAutoResolution && (resolution < 4 || resolution > 512))
        throw Error("landscape light: resolution " + std::to_string(resolution) + " is outside [4, 512] (0: automatic)");
    LandscapeLight r;
    r.resolution = resolution == lb::kAutoResolution ? kLandLightAutoResolution : std::min(resolution, kLandLightMaxResolution);
    for (const TilePlant& p : plants)
        if (p.species >= species.size()) throw Error("landscape light: a tile plant's species index is out of range");

    // The lattice: the footprint with one node of margin, from below the lowest ground to above the highest crown.
    const double X = double(field.layout.nx - 1) * double(field.layout.dx), Z = double(field.layout.nz - 1) * double(field.layout.dz);
    float gLo = field.heights.empty() ? 0.0f : field.heights[0], gHi = gLo;
    for (float v : field.heights) gLo = std::min(gLo, v), gHi = std::max(gHi, v);
    double crownTop = 0.0;
    for (const TilePlant& p : plants) {
        const lb::ForestSpecies& s = species[p.species];
        if (s.biomass > 0.0) crownTop = std::max(crownTop, double(layout.tileScale * p.scale) * s.boxMax.y);
    }
    const double h = std::max(std::max(X, Z), 1e-6) / double(r.resolution - 2);
    GridGeometry& g = r.geometry;
    g.spacing = h;
    g.origin = glm::dvec3(-h, double(gLo) - h, -h);
    g.dims = glm::ivec3(int(std::ceil(X / h)) + 3, int(std::ceil((double(gHi) + crownTop - double(gLo)) / h)) + 3, int(std::ceil(Z / h)) + 3);

    // Which plants grow (the traversal's own test), in strides when there are too many to test; each one that
    // does adds its extinction volume to the four lattice columns around its root (bilinear: continuous as it
    // moves). A column's foliage all lies in its first open node (solveGroundedLattice), so only the column counts.
    double total = 0.0;
    for (const LandCell& c : cells) total += double(tiles[c.tile].plantCount);
    r.stride = uint32_t(std::max(1.0, std::ceil(total / double(std::max<size_t>(settings.maxPlantTests, 1)))));
    const HeightFieldView hv = field.view();
    const size_t columns = size_t(g.dims.x) * size_t(g.dims.z);
    tbb::enumerable_thread_specific<std::vector<double>> maps([&] { return std::vector<double>(columns, 0.0); });
    std::vector<CellCanopy> canopy(cells.size());
    tbb::parallel_for(size_t(0), cells.size(), [&](size_t cell) {
        const uint32_t cx = uint32_t(cell % layout.cellsX), cz = uint32_t(cell / layout.cellsX);
        const TileRecord& t = tiles[cells[cell].tile];
        CellCanopy& cc = canopy[cell];
        std::vector<double>& map = maps.local();
        for (uint32_t q = uint32_t(cell % r.stride); q < t.plantCount; q += r.stride) {
            const TilePlant& p = plants[t.plantOffset + q];
            cc.tested += 1.0;
            float y = 0.0f;
            if (!landPlantGrows(layout, hv, snowY, rockCos, cx, cz, p, y)) continue;
            const lb::ForestSpecies& s = species[p.species];
            if (!(s.biomass > 0.0)) continue;
            const float k = layout.tileScale * p.scale;
            const double e = lb::plantExtinctionVolume(s, k) * double(r.stride);
            cc.extinction += e;
            cc.yLo += e * (double(y) + double(k) * s.boxMin.y);
            cc.yHi += e * (double(y) + double(k) * s.boxMax.y);
            cc.growing += double(r.stride);
            const double u = (double(cx) * double(layout.cellSize) + double(layout.tileScale) * double(p.x) - g.origin.x) / h;
            const double w = (double(cz) * double(layout.cellSize) + double(layout.tileScale) * double(p.z) - g.origin.z) / h;
            const int i0 = std::clamp(int(std::floor(u)), 0, g.dims.x - 2), k0 = std::clamp(int(std::floor(w)), 0, g.dims.z - 2);
            const double fu = std::clamp(u - double(i0), 0.0, 1.0), fw = std::clamp(w - double(k0), 0.0, 1.0);
            map[size_t(i0) * size_t(g.dims.z) + size_t(k0)] += e * (1.0 - fu) * (1.0 - fw);
            map[size_t(i0 + 1) * size_t(g.dims.z) + size_t(k0)] += e * fu * (1.0 - fw);
            map[size_t(i0) * size_t(g.dims.z) + size_t(k0 + 1)] += e * (1.0 - fu) * fw;
            map[size_t(i0 + 1) * size_t(g.dims.z) + size_t(k0 + 1)] += e * fu * fw;
        }
        if (cc.extinction > 0.0) cc.yLo /= cc.extinction, cc.yHi /= cc.extinction;
    });
    for (const CellCanopy& cc : canopy) {
        r.plantsTested += cc.tested;
        r.plantsGrowing += cc.growing;
        if (cc.extinction > 0.0) ++r.cellsWithPlants;
    }
    if (r.cellsWithPlants == 0) {
        r.geometry = GridGeometry{};
        r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        return r;
    }
    // The optical depth a coarse step crosses: mean fine density over the node's cell x (h / fine spacing) =
    // extinction volume / h^2 (lb::splatDepth's rule, for foliage inside one column).
    std::vector<float> depth(g.nodeCount(), 0.0f);
    for (const std::vector<double>& map : maps)
        for (int a = 0; a < g.dims.x; ++a)
            for (int c = 0; c < g.dims.z; ++c) depth[g.index(a, 0, c)] += float(map[size_t(a) * size_t(g.dims.z) + size_t(c)] / (h * h));
    const double C = double(layout.cellSize);
    std::vector<uint8_t> solid(g.nodeCount(), 0);
    tbb::parallel_for(0, g.dims.x, [&](int i) {
        for (int k = 0; k < g.dims.z; ++k) {
            const double ground = columnGround(field, g.origin.x + h * i, g.origin.z + h * k, h);
            for (int j = 0; j < g.dims.y; ++j) solid[g.index(i, j, k)] = g.origin.y + h * j < ground ? 1 : 0;
        }
    });
    const LightingGrid light = lb::solveGroundedLattice(g, std::move(depth), solid, params, &r.steps);
    r.nodes.resize(g.nodeCount());
    for (size_t n = 0; n < r.nodes.size(); ++n) r.nodes[n] = glm::vec4(light.rgb[n * 3], light.rgb[n * 3 + 1], light.rgb[n * 3 + 2], 1.0f);
    r.layout.origin = glm::vec3(g.origin);
    r.layout.invSpacing = float(1.0 / h);
    r.layout.dims = g.dims;

    // The factor each cell's canopy reads at its centre, as the shader samples it.
    std::vector<float> means;
    r.minFactor = 1e30f;
    r.maxFactor = 0.0f;
    for (size_t cell = 0; cell < cells.size(); ++cell) {
        const CellCanopy& cc = canopy[cell];
        if (!(cc.extinction > 0.0)) continue;
        const glm::vec3 p(float((double(cell % layout.cellsX) + 0.5) * C), float(0.5 * (cc.yLo + cc.yHi)), float((double(cell / layout.cellsX) + 0.5) * C));
        const glm::vec3 f = landLightFactor(r.layout, r.nodes.data(), p);
        means.push_back((f.x + f.y + f.z) / 3.0f);
        for (int c = 0; c < 3; ++c) r.minFactor = std::min(r.minFactor, f[c]), r.maxFactor = std::max(r.maxFactor, f[c]);
    }
    std::nth_element(means.begin(), means.begin() + std::ptrdiff_t(means.size() / 2), means.end());
    r.medianFactor = means[means.size() / 2];
    r.spread = r.maxFactor > 0.0f ? (r.maxFactor - r.minFactor) / r.maxFactor : 0.0f;
    r.uniform = r.spread < settings.uniformSpread;
    r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    return r;
}

} // namespace sylva
