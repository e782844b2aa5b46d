// The landscape's build: Wang tile set and tiling, Poisson-disk tile populations with edge plants replicated
// across matching edges, each tile's 2D tree, the cells' ground ranges and the top-level 2D kd-tree.
#include "core/terrain/landscape.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <numeric>
#include <string>

#include <tbb/parallel_for.h>

#include "core/base/error.h"
#include "core/base/splitmix.h"

namespace sylva {
namespace {

uint64_t mix(uint64_t a, uint64_t b)
{
    SplitMix64 r{a * 0x2545F4914F6CDD1Dull ^ b};
    return r.next();
}

std::string colourText(const WangTile& t)
{
    return "[" + std::to_string(t.s) + ", " + std::to_string(t.e) + ", " + std::to_string(t.n) + ", " + std::to_string(t.w) + "]";
}

// A root drawn by dart throwing: tile-frame position, kind (index into the population's plants), scale, rotation.
struct Root {
    double x, z;
    uint32_t kind;
    double scale, rotation;
};

struct Rect {
    double x0, z0, x1, z1;
};

// Dart throwing (Poisson disk): for each kind k in order, 30 x area / spacing^2 candidates uniform in rect(k);
// a candidate is kept when it lies (spacing_k + spacing_j) / 2 from every root of kind j already there
// (`fixed` and those drawn before it). Returns the new roots.
template <class RectOf>
std::vector<Root> throwDarts(const TileSetDesc& d, RectOf rectOf, SplitMix64& rng, const std::vector<Root>& fixed)
{
    std::vector<Root> all = fixed;
    const size_t firstNew = all.size();
    double maxSpacing = 1e-3;
    for (const TilePlantDesc& p : d.plants) maxSpacing = std::max(maxSpacing, p.spacing);
    double gx0 = -d.size, gz0 = -d.size;
    const double cell = maxSpacing;
    const int gw = int(std::ceil(3.0 * d.size / cell)) + 2, gd = gw;
    std::vector<std::vector<uint32_t>> grid(size_t(gw) * size_t(gd));
    auto at = [&](double x, double z, int& i, int& j) {
        i = std::clamp(int(std::floor((x - gx0) / cell)), 0, gw - 1);
        j = std::clamp(int(std::floor((z - gz0) / cell)), 0, gd - 1);
    };
    for (uint32_t k = 0; k < all.size(); ++k) {
        int i, j;
        at(all[k].x, all[k].z, i, j);
        grid[size_t(j) * size_t(gw) + size_t(i)].push_back(k);
    }
    for (uint32_t kind = 0; kind < d.plants.size(); ++kind) {
        const TilePlantDesc& p = d.plants[kind];
        const Rect r = rectOf(kind);
        if (!(r.x1 > r.x0 && r.z1 > r.z0)) continue;
        const double area = (r.x1 - r.x0) * (r.z1 - r.z0);
        const long long attempts = std::min<long long>(50000000, (long long)(30.0 * area / (p.spacing * p.spacing)) + 1);
        for (long long a = 0; a < attempts; ++a) {
            const double x = r.x0 + rng.unit() * (r.x1 - r.x0), z = r.z0 + rng.unit() * (r.z1 - r.z0);
            const double sc = double(p.scaleMin) + rng.unit() * double(p.scaleMax - p.scaleMin);
            const double rot = 360.0 * rng.unit();
            int ci, cj;
            at(x, z, ci, cj);
            bool ok = true;
            for (int j = std::max(cj - 1, 0); j <= std::min(cj + 1, gd - 1) && ok; ++j)
                for (int i = std::max(ci - 1, 0); i <= std::min(ci + 1, gw - 1) && ok; ++i)
                    for (uint32_t o : grid[size_t(j) * size_t(gw) + size_t(i)]) {
                        const double need = 0.5 * (p.spacing + d.plants[all[o].kind].spacing);
                        const double dx = all[o].x - x, dz = all[o].z - z;
                        if (dx * dx + dz * dz < need * need) {
                            ok = false;
                            break;
                        }
                    }
            if (!ok) continue;
            grid[size_t(cj) * size_t(gw) + size_t(ci)].push_back(uint32_t(all.size()));
            all.push_back(Root{x, z, kind, sc, rot});
        }
    }
    return std::vector<Root>(all.begin() + long(firstNew), all.end());
}

TilePlant makePlant(const Root& r, const TilePlantDesc& p, const LandscapeSpecies& sp, uint32_t densityId)
{
    const double a = r.rotation * M_PI / 180.0, c = std::cos(a), s = std::sin(a);
    // world = R (scale x_local) + root, R about +Y: x' = c x + s z, z' = -s x + c z. local = R^T (q) / scale.
    const double inv = 1.0 / r.scale;
    TilePlant t{};
    t.row[0] = glm::vec4(float(c * inv), 0.0f, float(-s * inv), 0.0f);
    t.row[1] = glm::vec4(0.0f, float(inv), 0.0f, 0.0f);
    t.row[2] = glm::vec4(float(s * inv), 0.0f, float(c * inv), 0.0f);
    t.geometry = sp.geometry;
    t.scale = float(r.scale);
    t.x = float(r.x);
    t.z = float(r.z);
    t.densityId = densityId;
    t.species = p.species;
    glm::vec3 lo(3e38f), hi(-3e38f);
    for (int k = 0; k < 8; ++k) {
        const glm::dvec3 q((k & 1) ? sp.hi.x : sp.lo.x, (k & 2) ? sp.hi.y : sp.lo.y, (k & 4) ? sp.hi.z : sp.lo.z);
        const glm::dvec3 w(r.scale * (c * q.x + s * q.z), r.scale * q.y, r.scale * (-s * q.x + c * q.z));
        lo = glm::min(lo, glm::vec3(w));
        hi = glm::max(hi, glm::vec3(w));
    }
    const glm::vec3 pad = 1e-5f * (glm::abs(lo) + glm::abs(hi)) + 1e-6f;
    t.lo = lo - pad;
    t.hi = hi + pad;
    return t;
}

// The tile's 2D tree (Dietrich, Marmitt & Slusallek, "Terrain Guided Multi-Level Instancing of Highly Complex
// Plant Populations", section 4.2: a two-dimensional SAH tree): plants split into two runs of their roots'
// order along x or z where the surface-area heuristic is lowest. A node's box is its plants' rectangle and
// vertical extent, which the traversal raises by the ground's band under it: the cost model takes that band as
// kSahBand of the tile's side, and a node's cost as its box's half surface (top and sides: rays over a
// landscape are shallow). Leaves of 1 .. kMaxLeaf plants; below depth kSahDepth splits are medians, so the
// traversal's 64-entry stack always suffices. `plants` is reordered into leaf order. Deterministic: sorts break
// ties by index.
void buildTileTree(std::vector<TilePlant>& plants, uint32_t plantBase, double tileSize, std::vector<TileNode>& nodes)
{
    // The cost constants, measured (bench_landscape, 82 km St Helens, 64^2 and 512^2 cells): a plant's box test
    // costed as a node's (kPlantTest 1) gives the fastest frames (kPlantTest 2 or 3: fewer plant tests, more nodes,
    // 4-7% slower); the band's share changes the counts by under 5%.
    constexpr float kTraversal = 1.0f, kPlantTest = 1.0f, kSahBand = 0.05f;
    constexpr uint32_t kMaxLeaf = 8, kSahDepth = 40;
    const float band = kSahBand * float(tileSize);
    struct Box {
        float lox = 3e38f, loz = 3e38f, hix = -3e38f, hiz = -3e38f, ylo = 3e38f, yhi = -3e38f;
        void grow(const TilePlant& p)
        {
            lox = std::min(lox, p.x + p.lo.x), loz = std::min(loz, p.z + p.lo.z);
            hix = std::max(hix, p.x + p.hi.x), hiz = std::max(hiz, p.z + p.hi.z);
            ylo = std::min(ylo, p.lo.y), yhi = std::max(yhi, p.hi.y);
        }
        float area(float b) const
        {
            const float wx = hix - lox, wz = hiz - loz, h = yhi - ylo + b;
            return wx * wz + (wx + wz) * h;
        }
    };
    // Original indices break ties, so equal roots sort the same way on every platform.
    std::vector<uint32_t> order(plants.size());
    for (uint32_t k = 0; k < order.size(); ++k) order[k] = k;
    auto sortAlong = [&](uint32_t first, uint32_t count, bool alongX) {
        std::sort(order.begin() + first, order.begin() + first + count, [&](uint32_t a, uint32_t b) {
            const float ka = alongX ? plants[a].x : plants[a].z, kb = alongX ? plants[b].x : plants[b].z;
            return ka < kb || (ka == kb && a < b);
        });
    };
    const uint32_t base = uint32_t(nodes.size());
    struct Item {
        uint32_t node, first, count, depth;
    };
    nodes.push_back(TileNode{});
    std::vector<Item> todo{{base, 0, uint32_t(plants.size()), 0}};
    std::vector<float> suffix;
    while (!todo.empty()) {
        const Item it = todo.back();
        todo.pop_back();
        Box box;
        for (uint32_t k = it.first; k < it.first + it.count; ++k) box.grow(plants[order[k]]);
        TileNode& n = nodes[it.node];
        n.lox = box.lox, n.loz = box.loz, n.hix = box.hix, n.hiz = box.hiz, n.ylo = box.ylo, n.yhi = box.yhi;
        // The best split: (cost, axis, plants in the first child); a leaf costs every plant's test.
        float bestCost = kPlantTest * float(it.count);
        bool bestX = true;
        uint32_t bestLeft = 0;
        if (it.count > 1 && it.depth < kSahDepth) {
            const float parent = std::max(box.area(band), 1e-20f);
            for (const bool alongX : {true, false}) {
                sortAlong(it.first, it.count, alongX);
                suffix.assign(it.count, 0.0f);
                Box right;
                for (uint32_t m = it.count; m-- > 1;) {
                    right.grow(plants[order[it.first + m]]);
                    suffix[m] = right.area(band);
                }
                Box left;
                for (uint32_t m = 1; m < it.count; ++m) {
                    left.grow(plants[order[it.first + m - 1]]);
                    const float cost = kTraversal + kPlantTest * (left.area(band) * float(m) + suffix[m] * float(it.count - m)) / parent;
                    if (cost < bestCost) bestCost = cost, bestX = alongX, bestLeft = m;
                }
            }
        }
        if (bestLeft == 0 && it.count > kMaxLeaf) {   // too many for a leaf and no split pays (or too deep): the median
            bestX = box.hix - box.lox >= box.hiz - box.loz;
            bestLeft = it.count / 2;
        }
        if (bestLeft == 0) {
            n.first = plantBase + it.first;
            n.count = it.count;
            continue;
        }
        sortAlong(it.first, it.count, bestX);
        const uint32_t child = uint32_t(nodes.size());
        nodes[it.node].first = child;
        nodes[it.node].count = 0;
        nodes.push_back(TileNode{});
        nodes.push_back(TileNode{});
        todo.push_back({child, it.first, bestLeft, it.depth + 1});
        todo.push_back({child + 1, it.first + bestLeft, it.count - bestLeft, it.depth + 1});
    }
    std::vector<TilePlant> sorted(plants.size());
    for (size_t k = 0; k < order.size(); ++k) sorted[k] = plants[order[k]];
    plants.swap(sorted);
}

} // namespace

std::vector<WangTile> wangTileSet(const TilingDesc& d)
{
    if (d.horizontal < 1 || d.vertical < 1)
        throw Error("terrain.tiling: colours must be >= 1 each, got " + std::to_string(d.horizontal) + " x " + std::to_string(d.vertical));
    std::vector<WangTile> set = d.set;
    if (!d.setGiven) {
        for (int s = 0; s < d.horizontal; ++s)
            for (int w = 0; w < d.vertical; ++w)
                for (int n = 0; n < d.horizontal; ++n)
                    for (int e = 0; e < d.vertical; ++e) set.push_back(WangTile{s, e, n, w});
    }
    if (set.empty()) throw Error("terrain.tiling.set: the tile set is empty");
    for (size_t k = 0; k < set.size(); ++k) {
        const WangTile& t = set[k];
        if (t.s < 0 || t.n < 0 || t.s >= d.horizontal || t.n >= d.horizontal || t.e < 0 || t.w < 0 || t.e >= d.vertical || t.w >= d.vertical)
            throw Error("terrain.tiling.set[" + std::to_string(k) + "]: colours " + colourText(t) + " (south, east, north, west) out of range (" +
                        std::to_string(d.horizontal) + " horizontal, " + std::to_string(d.vertical) + " vertical)");
    }
    // Every north colour a tile has can lie below a cell, every east colour beside it: each such pair needs a tile.
    for (const WangTile& below : set)
        for (const WangTile& left : set) {
            bool found = false;
            for (const WangTile& t : set) found = found || (t.s == below.n && t.w == left.e);
            if (!found)
                throw Error("terrain.tiling.set: the set cannot tile: no tile has south colour " + std::to_string(below.n) + " and west colour " +
                            std::to_string(left.e) + " (an edge-matched tiling needs one for every north/east pair its tiles show)");
        }
    return set;
}

std::vector<uint32_t> wangTiling(const std::vector<WangTile>& set, uint32_t cellsX, uint32_t cellsZ, uint64_t seed)
{
    // Candidates by (south, west) colour, and by south or west only for the first row and column.
    int maxH = 0, maxV = 0;
    for (const WangTile& t : set) maxH = std::max({maxH, t.s + 1, t.n + 1}), maxV = std::max({maxV, t.e + 1, t.w + 1});
    std::vector<std::vector<uint32_t>> bySW(size_t(maxH) * size_t(maxV));
    for (uint32_t k = 0; k < set.size(); ++k) bySW[size_t(set[k].s) * size_t(maxV) + size_t(set[k].w)].push_back(k);
    std::vector<uint32_t> out(size_t(cellsX) * cellsZ);
    std::vector<uint32_t> cand;
    for (uint32_t z = 0; z < cellsZ; ++z)
        for (uint32_t x = 0; x < cellsX; ++x) {
            cand.clear();
            const int needS = z > 0 ? set[out[size_t(z - 1) * cellsX + x]].n : -1;
            const int needW = x > 0 ? set[out[size_t(z) * cellsX + x - 1]].e : -1;
            if (needS >= 0 && needW >= 0) {
                cand = bySW[size_t(needS) * size_t(maxV) + size_t(needW)];
            } else {
                for (uint32_t k = 0; k < set.size(); ++k)
                    if ((needS < 0 || set[k].s == needS) && (needW < 0 || set[k].w == needW)) cand.push_back(k);
            }
            if (cand.empty()) throw Error("terrain.tiling: the tile set cannot tile cell (" + std::to_string(x) + ", " + std::to_string(z) + ")");
            out[size_t(z) * cellsX + x] = cand[mix(mix(seed, x), z) % cand.size()];
        }
    return out;
}

TilePopulation populateTiles(const TileSetDesc& d, const std::vector<WangTile>& set, const std::vector<LandscapeSpecies>& species)
{
    if (!(d.size > 0.0) || !std::isfinite(d.size)) throw Error("terrain.tiles.size must be finite and > 0");
    if (d.plants.empty()) throw Error("terrain.tiles.plants: a tile set needs at least one species");
    std::vector<double> margin(d.plants.size());   // footprint radius of each kind at its largest scale
    for (size_t k = 0; k < d.plants.size(); ++k) {
        const TilePlantDesc& p = d.plants[k];
        if (p.species >= species.size()) throw Error("terrain.tiles.plants[" + std::to_string(k) + "]: unknown species '" + p.speciesName + "'");
        if (!(p.spacing > 0.0) || !std::isfinite(p.spacing)) throw Error("terrain.tiles.plants[" + std::to_string(k) + "].spacing must be > 0");
        if (!(p.scaleMin > 0.0f) || !(p.scaleMax >= p.scaleMin))
            throw Error("terrain.tiles.plants[" + std::to_string(k) + "]: the scale range must satisfy 0 < min <= max");
        const LandscapeSpecies& sp = species[p.species];
        double r = 0.0;
        for (int c = 0; c < 4; ++c) {
            const double x = (c & 1) ? sp.hi.x : sp.lo.x, z = (c & 2) ? sp.hi.z : sp.lo.z;
            r = std::max(r, std::sqrt(x * x + z * z));
        }
        margin[k] = r * double(p.scaleMax) * 1.0001 + 1e-4;
        if (2.0 * margin[k] >= 0.5 * d.size)
            throw Error("terrain.tiles: species '" + p.speciesName + "' is too wide (" + std::to_string(2.0 * margin[k]) + " m) for tiles of " +
                        std::to_string(d.size) + " m");
    }
    int H = 0, V = 0;
    for (const WangTile& t : set) H = std::max({H, t.s + 1, t.n + 1}), V = std::max({V, t.e + 1, t.w + 1});
    const double S = d.size;
    // Edge plants: roots of kind k within margin_k of the edge line (on both sides), at least margin_k from the
    // tile's corners, drawn once per colour: horizontal edges as (x, dz) about z = 0, vertical ones as
    // (dx, z) about x = 0.
    std::vector<std::vector<Root>> hEdge(static_cast<size_t>(H)), vEdge(static_cast<size_t>(V));
    for (int c = 0; c < H; ++c) {
        SplitMix64 rng{mix(d.seed, 1000 + uint64_t(c))};
        hEdge[size_t(c)] = throwDarts(d, [&](uint32_t k) { return Rect{margin[k], -margin[k], S - margin[k], margin[k]}; }, rng, {});
    }
    for (int c = 0; c < V; ++c) {
        SplitMix64 rng{mix(d.seed, 2000 + uint64_t(c))};
        vEdge[size_t(c)] = throwDarts(d, [&](uint32_t k) { return Rect{-margin[k], margin[k], margin[k], S - margin[k]}; }, rng, {});
    }
    // eq. 2's id_tile: the tile's index for its own plants; an edge set's plants share one id_tile (the number
    // of tiles + the edge set's index), so both copies of a replicated plant are kept or dropped together.
    const uint32_t nt = uint32_t(set.size());
    TilePopulation pop;
    pop.tiles.resize(nt);
    tbb::parallel_for(uint32_t(0), nt, [&](uint32_t t) {
        const WangTile& w = set[t];
        std::vector<Root> edges;
        std::vector<uint32_t> ids;
        auto addEdge = [&](const std::vector<Root>& e, double ox, double oz, uint32_t idTile) {
            for (size_t k = 0; k < e.size(); ++k) {
                Root r = e[k];
                r.x += ox, r.z += oz;
                edges.push_back(r);
                ids.push_back(uint32_t(k) + idTile);
            }
        };
        addEdge(hEdge[size_t(w.s)], 0.0, 0.0, nt + uint32_t(w.s));
        addEdge(hEdge[size_t(w.n)], 0.0, S, nt + uint32_t(w.n));
        addEdge(vEdge[size_t(w.w)], 0.0, 0.0, nt + uint32_t(H) + uint32_t(w.w));
        addEdge(vEdge[size_t(w.e)], S, 0.0, nt + uint32_t(H) + uint32_t(w.e));
        SplitMix64 rng{mix(d.seed, 5000 + uint64_t(t))};
        const std::vector<Root> inner =
            throwDarts(d, [&](uint32_t k) { return Rect{margin[k], margin[k], S - margin[k], S - margin[k]}; }, rng, edges);
        std::vector<TilePlant>& out = pop.tiles[t];
        out.reserve(edges.size() + inner.size());
        for (size_t k = 0; k < edges.size(); ++k)
            out.push_back(makePlant(edges[k], d.plants[edges[k].kind], species[d.plants[edges[k].kind].species], ids[k]));
        for (size_t k = 0; k < inner.size(); ++k)
            out.push_back(makePlant(inner[k], d.plants[inner[k].kind], species[d.plants[inner[k].kind].species], uint32_t(k) + t));
    });
    return pop;
}

void setLandscapeDensity(LandscapeLayout& L, const DensityDesc& density, double terrainY)
{
    if (density.enabled && (density.m < 2 || density.a < 1))
        throw Error("terrain.density: a must be >= 1 and m >= 2");
    L.densityOn = density.enabled ? 1u : 0u;
    L.dLower = density.atLower;
    L.dUpper = density.atUpper;
    L.hLower = float(density.lower - terrainY);
    L.hUpper = float(density.upper - terrainY);
    L.a = uint32_t(density.a);
    L.m = uint32_t(density.m);
    L.noSnow = density.enabled && density.noSnow ? 1u : 0u;
    L.noRock = density.enabled && density.noRock ? 1u : 0u;
}

namespace {

// Cell record of tile t over samples [i0, i1] x [j0, j1] (the footprint of its plants), the cell's corner at DEM
// frame (x0, z0): the samples' range and the least-squares plane h = a + b tx + c tz in the tile frame (tx = (X -
// x0) / tileScale) with the samples' largest deviation from it, plus rounding (the traversal evaluates the plane in
// float, the roots' heights are float).
LandCell groundUnder(const HeightField& field, long i0, long i1, long j0, long j1, double x0, double z0, double tileScale, uint32_t t)
{
    const HeightFieldLayout& H = field.layout;
    float lo = 3e38f, hi = -3e38f;
    double n = 0.0, sx = 0.0, sz = 0.0, sh = 0.0, sxx = 0.0, szz = 0.0, sxz = 0.0, sxh = 0.0, szh = 0.0;
    // Centred coordinates (tile metres about the footprint's middle) keep the normal equations well conditioned.
    const double mx = 0.5 * double(i0 + i1) * H.dx, mz = 0.5 * double(j0 + j1) * H.dz;
    for (long j = j0; j <= j1; ++j)
        for (long i = i0; i <= i1; ++i) {
            const float h = field.heights[size_t(j) * H.nx + size_t(i)];
            lo = std::min(lo, h), hi = std::max(hi, h);
            const double x = (double(i) * H.dx - mx) / tileScale, z = (double(j) * H.dz - mz) / tileScale;
            n += 1.0, sx += x, sz += z, sh += h, sxx += x * x, szz += z * z, sxz += x * z, sxh += x * h, szh += z * h;
        }
    // Solve [n sx sz; sx sxx sxz; sz sxz szz] (a, b, c) = (sh, sxh, szh) by Cramer's rule; a flat plane through
    // the range's middle when the samples are one row or column (the matrix is singular).
    const double det = n * (sxx * szz - sxz * sxz) - sx * (sx * szz - sxz * sz) + sz * (sx * sxz - sxx * sz);
    double a = 0.5 * (double(lo) + double(hi)), b = 0.0, c = 0.0;
    if (i1 > i0 && j1 > j0 && std::abs(det) > 1e-12 * std::max(1.0, n * sxx * szz)) {
        a = (sh * (sxx * szz - sxz * sxz) - sx * (sxh * szz - sxz * szh) + sz * (sxh * sxz - sxx * szh)) / det;
        b = (n * (sxh * szz - sxz * szh) - sh * (sx * szz - sxz * sz) + sz * (sx * szh - sxh * sz)) / det;
        c = (n * (sxx * szh - sxh * sxz) - sx * (sx * szh - sxh * sz) + sh * (sx * sxz - sxx * sz)) / det;
    }
    double e = 0.0;
    for (long j = j0; j <= j1; ++j)
        for (long i = i0; i <= i1; ++i) {
            const double x = (double(i) * H.dx - mx) / tileScale, z = (double(j) * H.dz - mz) / tileScale;
            e = std::max(e, std::abs(double(field.heights[size_t(j) * H.nx + size_t(i)]) - (a + b * x + c * z)));
        }
    // From the footprint's middle to the cell corner: tx' = tx + (mx - x0) / tileScale.
    a -= b * (mx - x0) / tileScale + c * (mz - z0) / tileScale;
    const double mag = std::max(std::abs(double(lo)), std::abs(double(hi)));
    e += 1e-4 * (mag + double(hi - lo)) + 1e-4;
    return LandCell{glm::vec2(lo, hi), t, 0, glm::vec4(float(a), float(b), float(c), float(e))};
}

} // namespace

LandscapeBuild buildLandscape(const HeightField& field, uint32_t cells, const TileSetDesc& tiles, const TilingDesc& tiling,
                              const DensityDesc& density, double terrainY, float snowY, float rockCos,
                              const std::vector<LandscapeSpecies>& species)
{
    const auto start = std::chrono::steady_clock::now();
    if (cells < 1 || cells > 65536) throw Error("terrain.cells must lie in [1, 65536], got " + std::to_string(cells));
    if (density.enabled && (density.m < 2 || density.a < 1))
        throw Error("terrain.density: a must be >= 1 and m >= 2");
    LandscapeBuild b;
    b.set = wangTileSet(tiling);
    TilePopulation pop = populateTiles(tiles, b.set, species);
    const HeightFieldLayout& H = field.layout;
    const double wx = double(H.nx - 1) * double(H.dx), wz = double(H.nz - 1) * double(H.dz);
    const double C = std::max(wx, wz) / double(cells);
    LandscapeLayout& L = b.layout;
    L.cellSize = float(C);
    L.cellsX = uint32_t(std::max(1.0, std::ceil(wx / C - 1e-9)));
    L.cellsZ = uint32_t(std::max(1.0, std::ceil(wz / C - 1e-9)));
    L.tileScale = float(C / tiles.size);
    L.invTileScale = float(tiles.size / C);
    setLandscapeDensity(L, density, terrainY);
    (void)snowY;
    (void)rockCos;

    // Tiles: records, 2D trees, plants in leaf order, the vertical extent and horizontal overhang.
    const uint32_t nt = uint32_t(b.set.size());
    b.tiles.resize(nt);
    std::vector<glm::vec4> extent(nt);   // tile-frame footprint of its plants' boxes: lox, loz, hix, hiz
    b.stats.plantsPerTileMin = ~size_t(0);
    for (uint32_t t = 0; t < nt; ++t) {
        std::vector<TilePlant>& ps = pop.tiles[t];
        TileRecord& r = b.tiles[t];
        r.nodeOffset = uint32_t(b.tileNodes.size());
        r.plantOffset = uint32_t(b.plants.size());
        r.plantCount = uint32_t(ps.size());
        r.yLo = 3e38f, r.yHi = -3e38f;
        glm::vec4 e(3e38f, 3e38f, -3e38f, -3e38f);
        for (const TilePlant& p : ps) {
            r.yLo = std::min(r.yLo, p.lo.y), r.yHi = std::max(r.yHi, p.hi.y);
            e = glm::vec4(std::min(e.x, p.x + p.lo.x), std::min(e.y, p.z + p.lo.z), std::max(e.z, p.x + p.hi.x), std::max(e.w, p.z + p.hi.z));
        }
        if (ps.empty()) e = glm::vec4(0.0f, 0.0f, float(tiles.size), float(tiles.size));
        extent[t] = e;
        if (!ps.empty()) buildTileTree(ps, r.plantOffset, tiles.size, b.tileNodes);
        else b.tileNodes.push_back(TileNode{1.0f, 1.0f, 0.0f, 0.0f, 1.0f, 0.0f, r.plantOffset, 0});   // an empty box
        b.plants.insert(b.plants.end(), ps.begin(), ps.end());
        b.stats.plantsPerTileMin = std::min(b.stats.plantsPerTileMin, ps.size());
        b.stats.plantsPerTileMax = std::max(b.stats.plantsPerTileMax, ps.size());
    }
    b.stats.tiles = nt;
    b.stats.tilePlants = b.plants.size();

    // Cells: tiles, and the ground's range under the cell's tile (its plants' footprint mapped onto the cell).
    const std::vector<uint32_t> tileOf = wangTiling(b.set, L.cellsX, L.cellsZ, tiling.seed);
    const size_t nc = size_t(L.cellsX) * L.cellsZ;
    b.cells.resize(nc);
    std::vector<double> tileTriangles(nt, 0.0);
    for (uint32_t t = 0; t < nt; ++t)
        for (uint32_t k = 0; k < b.tiles[t].plantCount; ++k) tileTriangles[t] += species[b.plants[b.tiles[t].plantOffset + k].species].triangles;
    tbb::parallel_for(size_t(0), size_t(L.cellsZ), [&](size_t cz) {
        for (size_t cx = 0; cx < L.cellsX; ++cx) {
            const uint32_t t = tileOf[cz * L.cellsX + cx];
            const glm::vec4 e = extent[t];
            const double x0 = double(cx) * C + double(L.tileScale) * e.x, x1 = double(cx) * C + double(L.tileScale) * e.z;
            const double z0 = double(cz) * C + double(L.tileScale) * e.y, z1 = double(cz) * C + double(L.tileScale) * e.w;
            const long i0 = std::clamp(long(std::floor(x0 / H.dx)), 0L, long(H.nx - 1)), i1 = std::clamp(long(std::ceil(x1 / H.dx)), 0L, long(H.nx - 1));
            const long j0 = std::clamp(long(std::floor(z0 / H.dz)), 0L, long(H.nz - 1)), j1 = std::clamp(long(std::ceil(z1 / H.dz)), 0L, long(H.nz - 1));
            b.cells[cz * L.cellsX + cx] = groundUnder(field, i0, i1, j0, j1, double(cx) * C, double(cz) * C, double(L.tileScale), t);
        }
    });
    for (size_t c = 0; c < nc; ++c) {
        b.stats.instances += double(b.tiles[b.cells[c].tile].plantCount);
        b.stats.triangles += tileTriangles[b.cells[c].tile];
    }
    b.stats.cells = nc;

    // The top-level 2D kd-tree: rectangles split at the middle of the longer side; ranges merged bottom-up.
    struct Item {
        uint32_t node, x0, z0, x1, z1;
    };
    b.nodes.push_back(LandNode{});
    std::vector<Item> order{{0, 0, 0, L.cellsX, L.cellsZ}};
    for (size_t k = 0; k < order.size(); ++k) {
        const Item it = order[k];
        if (it.x1 - it.x0 == 1 && it.z1 - it.z0 == 1) continue;
        const uint32_t child = uint32_t(b.nodes.size());
        b.nodes[it.node].child = child;
        b.nodes.push_back(LandNode{});
        b.nodes.push_back(LandNode{});
        if (it.x1 - it.x0 >= it.z1 - it.z0) {
            const uint32_t mid = (it.x0 + it.x1) / 2;
            order.push_back({child, it.x0, it.z0, mid, it.z1});
            order.push_back({child + 1, mid, it.z0, it.x1, it.z1});
        } else {
            const uint32_t mid = (it.z0 + it.z1) / 2;
            order.push_back({child, it.x0, it.z0, it.x1, mid});
            order.push_back({child + 1, it.x0, mid, it.x1, it.z1});
        }
    }
    for (size_t k = order.size(); k-- > 0;) {
        const Item it = order[k];
        LandNode& n = b.nodes[it.node];
        if (n.child == 0) {
            const LandCell& c = b.cells[size_t(it.z0) * L.cellsX + it.x0];
            const TileRecord& t = b.tiles[c.tile];
            n.range = t.plantCount ? glm::vec2(c.ground.x + L.tileScale * t.yLo, c.ground.y + L.tileScale * t.yHi) : glm::vec2(3e38f, -3e38f);
        } else {
            const glm::vec2 a = b.nodes[n.child].range, c = b.nodes[n.child + 1].range;
            n.range = glm::vec2(std::min(a.x, c.x), std::max(a.y, c.y));
        }
    }
    b.stats.buildSeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return b;
}

} // namespace sylva
