// Voxelizer: triangles binned by x node layer, tiles of sub-cell flags filled in parallel, counted per node.
#include "core/voxel/voxelize.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <limits>
#include <mutex>
#include <string>
#include <vector>

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>
#include <tbb/partitioner.h>

#include "core/base/error.h"
#include "core/base/progress.h"
#include "core/voxel/solid_voxelize.h"
#include "core/voxel/tri_box.h"

namespace sylva {
namespace {

constexpr uint8_t kMarked = 1;              // sub-cell flag: met by any triangle
constexpr uint8_t kWood = 2;                // sub-cell flag: met by a wood triangle
constexpr size_t kBinChunk = 16384;         // triangles per binning task
constexpr size_t kTileBytes = size_t(16) << 20; // sub-cell flags of one tile (per thread)
constexpr size_t kCancelEvery = 4096;       // triangles between cancel checks inside a tile
constexpr int kBlockSide = 16;              // triangles whose range is at most this per axis use 2D tables
constexpr int kProgressSteps = 50;          // report every 2%
constexpr double kSetupShare = 0.1;         // progress share of validation, transform and binning

const char* axisName(int a) { return a == 0 ? "x" : (a == 1 ? "y" : "z"); }

void checkNodeCount(int n, const std::string& what)
{
    if (n < kVoxelMinNodes || n > kVoxelMaxNodes)
        throw Error("voxelize: " + what + " is " + std::to_string(n) + ", must be in " +
                    std::to_string(kVoxelMinNodes) + ".." + std::to_string(kVoxelMaxNodes));
}

bool finite3(const glm::vec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

// Closed sub-cells [u, u+1] met by the closed interval [bmin, bmax]: u in [ceil(bmin) - 1, floor(bmax)].
void closedCellRange(const glm::vec3& bmin, const glm::vec3& bmax, glm::ivec3& lo, glm::ivec3& hi)
{
    lo = glm::ivec3(glm::ceil(bmin)) - 1;
    hi = glm::ivec3(glm::floor(bmax));
}

void validateMesh(const TriangleMesh& mesh)
{
    const size_t triCount = mesh.triangles.size();
    if (triCount == 0) throw Error("voxelize: the mesh has no triangles");
    if (triCount > size_t(std::numeric_limits<uint32_t>::max()))
        throw Error("voxelize: the mesh has more than 2^32 - 1 triangles");
    if (!mesh.triangleMaterial.empty() && mesh.triangleMaterial.size() != triCount)
        throw Error("voxelize: the mesh has " + std::to_string(mesh.triangleMaterial.size()) +
                    " triangle materials for " + std::to_string(triCount) + " triangles");
    const size_t vertexCount = mesh.positions.size();
    for (size_t t = 0; t < triCount; ++t) {
        for (int c = 0; c < 3; ++c)
            if (mesh.triangles[t][c] >= vertexCount)
                throw Error("voxelize: triangle " + std::to_string(t) + " uses vertex " +
                            std::to_string(mesh.triangles[t][c]) + " but the mesh has " +
                            std::to_string(vertexCount) + " vertices");
        if (!mesh.triangleMaterial.empty() && mesh.triangleMaterial[t] >= mesh.materials.size())
            throw Error("voxelize: triangle " + std::to_string(t) + " uses material " +
                        std::to_string(mesh.triangleMaterial[t]) + " but the mesh has " +
                        std::to_string(mesh.materials.size()) + " materials");
    }
    for (size_t v = 0; v < vertexCount; ++v)
        if (!finite3(mesh.positions[v]))
            throw Error("voxelize: vertex " + std::to_string(v) + " has a NaN or infinite coordinate");
}

// A triangle as the tiles see it: vertices in sub-cell units and the flags it sets. 40 bytes.
struct BinnedTriangle {
    glm::vec3 p[3];
    uint32_t bits;
};

// Per-thread scratch of one tile: sub-cell flags and per-node counts.
// Everything is zero between tiles; a tile clears what it set, so its cost follows the marked
// sub-cells, not the volume.
struct TileScratch {
    std::vector<uint8_t> flags;          // per sub-cell of the tile: kMarked | kWood
    std::vector<uint16_t> marked, wood;  // per node of the tile: marked / wood sub-cells
    std::vector<uint32_t> setCells;      // sub-cells whose flags became non-zero
    std::vector<uint32_t> setNodes;      // nodes whose marked count became non-zero
    std::vector<uint32_t> nodeOfV, nodeOfW;  // tile-local sub-cell row / column -> tile-local node offset
};

} // namespace

GridGeometry gridForMesh(const Bounds3& bounds, const VoxelizeSettings& settings)
{
    if (!finite3(bounds.lo) || !finite3(bounds.hi))
        throw Error("voxelize: the mesh bounds are not finite (NaN or infinite coordinates)");
    if (!bounds.valid()) throw Error("voxelize: the mesh bounds are empty (no vertices)");
    const glm::dvec3 extent = glm::dvec3(bounds.hi) - glm::dvec3(bounds.lo);  // exact in double
    if (extent.x <= 0.0 && extent.y <= 0.0 && extent.z <= 0.0)
        throw Error("voxelize: the mesh has zero extent along all axes (all vertices coincide)");

    GridGeometry g;
    const bool explicitDims = settings.dims.x > 0 && settings.dims.y > 0 && settings.dims.z > 0;
    if (explicitDims) {
        for (int a = 0; a < 3; ++a) checkNodeCount(settings.dims[a], std::string("grid size along ") + axisName(a));
        g.dims = settings.dims;
        g.spacing = 0.0;
        for (int a = 0; a < 3; ++a) g.spacing = std::max(g.spacing, extent[a] / double(g.dims[a] - 2));
    } else {
        checkNodeCount(settings.longestAxisNodes, "the node count of the longest axis");
        const int n = settings.longestAxisNodes;
        int longest = 0;
        for (int a = 1; a < 3; ++a)
            if (extent[a] > extent[longest]) longest = a;
        const double length = extent[longest];
        g.spacing = length / double(n - 2);
        for (int a = 0; a < 3; ++a) {
            if (a == longest) {
                g.dims[a] = n;
            } else {
                // Interior cells needed: extent / spacing, written so that equal extents give n - 2 exactly.
                const int cells = int(std::ceil(extent[a] * double(n - 2) / length));
                g.dims[a] = std::max(kVoxelMinNodes, cells + 2);
            }
        }
    }
    // Centre the mesh: the grid's middle (origin + spacing * (dims - 1) / 2) is the middle of the bounds.
    const glm::dvec3 centre = 0.5 * (glm::dvec3(bounds.lo) + glm::dvec3(bounds.hi));
    g.origin = centre - 0.5 * g.spacing * glm::dvec3(g.dims - 1);
    return g;
}

DensityGrid voxelize(const TriangleMesh& mesh, const VoxelizeSettings& settings, Progress* progress)
{
    const int sc = settings.subcells;
    if (sc < 1 || sc > kVoxelMaxSubcells)
        throw Error("voxelize: subcells is " + std::to_string(sc) + ", must be in 1.." +
                    std::to_string(kVoxelMaxSubcells));
    validateMesh(mesh);
    if (settings.solid) return voxelizeSolid(mesh, settings, progress);
    if (progress) progress->report(0.0, "voxelizing");

    const Bounds3 bounds = meshBounds(mesh);
    DensityGrid grid;
    grid.geometry = gridForMesh(bounds, settings);
    const GridGeometry& g = grid.geometry;
    grid.density.assign(g.nodeCount(), 0.0f);
    grid.woodFraction.assign(g.nodeCount(), 0.0f);

    // Vertices in sub-cell units: sub-cell (u,v,w) is the closed box [u,u+1] x [v,v+1] x [w,w+1], and
    // node i owns sub-cells i*sc .. i*sc + sc - 1. Computed in double from the bounds corner and rounded
    // once to float, so a point that lies on a sub-cell face in exact arithmetic (the mesh bounds on
    // the axis that sets the spacing, for one) lands exactly on it.
    const double scale = double(sc) / g.spacing;
    glm::dvec3 offset;
    for (int a = 0; a < 3; ++a) offset[a] = (double(bounds.lo[a]) - (g.origin[a] - 0.5 * g.spacing)) * scale;
    auto triangleVertices = [&](size_t t, glm::vec3 p[3]) {
        const glm::uvec3 tri = mesh.triangles[t];
        for (int c = 0; c < 3; ++c)
            for (int a = 0; a < 3; ++a)
                p[c][a] = float((double(mesh.positions[tri[c]][a]) - double(bounds.lo[a])) * scale + offset[a]);
    };
    auto cellRange = [](const glm::vec3 p[3], glm::ivec3& rawLo, glm::ivec3& rawHi) {
        closedCellRange(glm::min(p[0], glm::min(p[1], p[2])), glm::max(p[0], glm::max(p[1], p[2])), rawLo, rawHi);
    };

    // Sub-cells of the interior nodes; margin sub-cells are never marked.
    const glm::ivec3 first(sc), last = (g.dims - 1) * sc - 1;
    const size_t triCount = mesh.triangles.size();

    // Bin triangles into the x node layers (slabs) their interior sub-cell range meets, in triangle order.
    const int slabCount = g.dims.x;
    const size_t chunkCount = (triCount + kBinChunk - 1) / kBinChunk;
    std::vector<size_t> chunkSlab(chunkCount * size_t(slabCount), 0);  // counts, then write offsets
    std::vector<uint16_t> slabLo(triCount), slabHi(triCount);          // lo > hi: no interior sub-cell met
    tbb::parallel_for(tbb::blocked_range<size_t>(0, chunkCount, 1), [&](const tbb::blocked_range<size_t>& r) {
        for (size_t c = r.begin(); c != r.end(); ++c) {
            size_t* counts = &chunkSlab[c * size_t(slabCount)];
            const size_t end = std::min(triCount, (c + 1) * kBinChunk);
            for (size_t t = c * kBinChunk; t < end; ++t) {
                glm::ivec3 lo, hi;
                glm::vec3 p[3];
                triangleVertices(t, p);
                cellRange(p, lo, hi);
                lo = glm::max(lo, first);
                hi = glm::min(hi, last);
                if (lo.x > hi.x || lo.y > hi.y || lo.z > hi.z) {
                    slabLo[t] = 1;
                    slabHi[t] = 0;
                    continue;
                }
                slabLo[t] = uint16_t(lo.x / sc);
                slabHi[t] = uint16_t(hi.x / sc);
                for (int s = slabLo[t]; s <= slabHi[t]; ++s) ++counts[s];
            }
        }
    });
    std::vector<size_t> slabBegin(size_t(slabCount) + 1, 0);
    size_t entryCount = 0;
    for (int s = 0; s < slabCount; ++s) {
        slabBegin[s] = entryCount;
        for (size_t c = 0; c < chunkCount; ++c) {
            const size_t n = chunkSlab[c * size_t(slabCount) + size_t(s)];
            chunkSlab[c * size_t(slabCount) + size_t(s)] = entryCount;
            entryCount += n;
        }
    }
    slabBegin[slabCount] = entryCount;
    // The bins hold copies of the triangles (sub-cell vertices and flags), so that a tile streams
    // through its triangles instead of gathering them from all over the mesh.
    std::vector<BinnedTriangle> entries(entryCount);
    tbb::parallel_for(tbb::blocked_range<size_t>(0, chunkCount, 1), [&](const tbb::blocked_range<size_t>& r) {
        for (size_t c = r.begin(); c != r.end(); ++c) {
            size_t* offsets = &chunkSlab[c * size_t(slabCount)];
            const size_t end = std::min(triCount, (c + 1) * kBinChunk);
            for (size_t t = c * kBinChunk; t < end; ++t) {
                if (slabLo[t] > slabHi[t]) continue;
                BinnedTriangle entry;
                triangleVertices(t, entry.p);
                entry.bits = mesh.isLeafTriangle(t) ? kMarked : uint8_t(kMarked | kWood);
                for (int s = slabLo[t]; s <= slabHi[t]; ++s) entries[offsets[s]++] = entry;
            }
        }
    });
    if (progress) progress->report(kSetupShare, "voxelizing");

    // Tiles: one interior x node layer times a block of interior y node rows, all interior z nodes.
    const int nodesZ = g.dims.z - 2;
    const size_t rowBytes = size_t(sc) * size_t(sc) * size_t(sc) * size_t(nodesZ);
    const int rowsY = g.dims.y - 2;
    const int rowsPerTile = int(std::clamp<size_t>(kTileBytes / rowBytes, 1, size_t(rowsY)));
    const int blocksY = (rowsY + rowsPerTile - 1) / rowsPerTile;
    const size_t tileCount = size_t(g.dims.x - 2) * size_t(blocksY);
    const size_t totalWork = size_t(blocksY) * (slabBegin[slabCount - 1] - slabBegin[1]) + tileCount;
    const int sc3 = sc * sc * sc;

    tbb::enumerable_thread_specific<TileScratch> scratch;
    std::atomic<size_t> doneWork{0};
    std::mutex reportMutex;
    int reportedStep = int(kSetupShare * kProgressSteps);

    auto runTile = [&](size_t tile) {
        const int i = 1 + int(tile / size_t(blocksY));
        const int j0 = 1 + int(tile % size_t(blocksY)) * rowsPerTile;
        const int j1 = std::min(j0 + rowsPerTile - 1, g.dims.y - 2);
        // The tile's sub-cells (global indices wlo..whi) and nodes (i, j0..j1, 1..dims.z-2).
        const glm::ivec3 wlo(i * sc, j0 * sc, sc);
        const glm::ivec3 whi(i * sc + sc - 1, (j1 + 1) * sc - 1, (g.dims.z - 1) * sc - 1);
        const glm::ivec3 wsize = whi - wlo + 1;
        TileScratch& s = scratch.local();
        const size_t tileCells = size_t(wsize.x) * size_t(wsize.y) * size_t(wsize.z);
        const size_t tileNodes = size_t(j1 - j0 + 1) * size_t(nodesZ);
        if (s.flags.size() < tileCells) s.flags.resize(tileCells, 0);
        if (s.marked.size() < tileNodes) {
            s.marked.resize(tileNodes, 0);
            s.wood.resize(tileNodes, 0);
        }
        s.nodeOfV.resize(size_t(wsize.y));
        for (int v = 0; v < wsize.y; ++v) s.nodeOfV[size_t(v)] = uint32_t(v / sc) * uint32_t(nodesZ);
        s.nodeOfW.resize(size_t(wsize.z));
        for (int w = 0; w < wsize.z; ++w) s.nodeOfW[size_t(w)] = uint32_t(w / sc);
        uint8_t* flags = s.flags.data();
        uint16_t* marked = s.marked.data();
        uint16_t* wood = s.wood.data();

        const size_t eBegin = slabBegin[i], eEnd = slabBegin[i + 1];
        for (size_t e = eBegin; e < eEnd; ++e) {
            if (progress && (e - eBegin) % kCancelEvery == kCancelEvery - 1) progress->throwIfCancelled();
            const BinnedTriangle& entry = entries[e];
            const glm::vec3* p = entry.p;
            glm::ivec3 rawLo, rawHi;
            cellRange(p, rawLo, rawHi);
            const glm::ivec3 lo = glm::max(rawLo, wlo), hi = glm::min(rawHi, whi);
            if (lo.x > hi.x || lo.y > hi.y || lo.z > hi.z) continue;
            const uint8_t bits = uint8_t(entry.bits);
            // Marks sub-cell (u, v, w) (global indices), keeping the node counts up to date.
            auto mark = [&](int u, int v, int w) {
                const int lv = v - wlo.y, lw = w - wlo.z;
                const size_t cell = (size_t(u - wlo.x) * size_t(wsize.y) + size_t(lv)) * size_t(wsize.z) + size_t(lw);
                const uint8_t old = flags[cell];
                const uint8_t now = uint8_t(old | bits);
                if (now == old) return;
                flags[cell] = now;
                const uint32_t node = s.nodeOfV[size_t(lv)] + s.nodeOfW[size_t(lw)];
                if (old == 0) {
                    s.setCells.push_back(uint32_t(cell));
                    if (marked[node]++ == 0) s.setNodes.push_back(node);
                }
                if ((now & kWood) && !(old & kWood)) ++wood[node];
            };

            // A triangle inside one sub-cell column (its bounds within one sub-cell along two axes)
            // meets every sub-cell of its bounds range: its projection on the third axis is connected.
            const int thinAxes = int(rawLo.x == rawHi.x) + int(rawLo.y == rawHi.y) + int(rawLo.z == rawHi.z);
            if (thinAxes >= 2) {
                for (int u = lo.x; u <= hi.x; ++u)
                    for (int v = lo.y; v <= hi.y; ++v)
                        for (int w = lo.z; w <= hi.z; ++w) mark(u, v, w);
                continue;
            }
            // Exact test in a frame anchored at the range corner (small coordinates, accurate floats).
            const glm::vec3 anchor(lo);
            const TriBoxSat sat = triBoxPrepare(p[0] - anchor, p[1] - anchor, p[2] - anchor, glm::vec3(0.5f));
            const glm::ivec3 n = hi - lo + 1;
            if (n.x > kBlockSide || n.y > kBlockSide || n.z > kBlockSide) {
                // Large range: per (u,v) column the projected test on the xy plane, then only the
                // boxes near the triangle plane (a w interval widened by one box for rounding), each
                // with the remaining exact tests. Work grows with the columns and the marked boxes.
                const glm::vec3 normal = sat.axis[0];
                for (int u = 0; u < n.x; ++u)
                    for (int v = 0; v < n.y; ++v) {
                        if (!triBoxSatProjectedZ(sat, float(u) + 0.5f, float(v) + 0.5f)) continue;
                        int w0 = 0, w1 = n.z - 1;
                        if (normal.z != 0.0f) {
                            const float base = normal.x * (float(u) + 0.5f) + normal.y * (float(v) + 0.5f);
                            float a = (sat.cmin[0] - base) / normal.z - 0.5f;
                            float b = (sat.cmax[0] - base) / normal.z - 0.5f;
                            if (a > b) std::swap(a, b);
                            // Clamped as floats first: a nearly vertical plane gives huge or infinite bounds.
                            w0 = int(std::clamp(std::ceil(a) - 1.0f, 0.0f, float(n.z)));
                            w1 = int(std::clamp(std::floor(b) + 1.0f, -1.0f, float(n.z - 1)));
                        }
                        for (int w = w0; w <= w1; ++w) {
                            const glm::vec3 centre(float(u) + 0.5f, float(v) + 0.5f, float(w) + 0.5f);
                            if (triBoxSatProjectedX(sat, centre.y, centre.z) && triBoxSatProjectedY(sat, centre.z, centre.x) &&
                                triBoxSatPlane(sat, centre))
                                mark(lo.x + u, lo.y + v, lo.z + w);
                        }
                    }
                continue;
            }
            // Small range (the common case): the three projected tests once per pair of coordinates,
            // then the plane test for the boxes that pass all three.
            bool xy[kBlockSide][kBlockSide], yz[kBlockSide][kBlockSide], zx[kBlockSide][kBlockSide];
            for (int u = 0; u < n.x; ++u)
                for (int v = 0; v < n.y; ++v) xy[u][v] = triBoxSatProjectedZ(sat, float(u) + 0.5f, float(v) + 0.5f);
            for (int v = 0; v < n.y; ++v)
                for (int w = 0; w < n.z; ++w) yz[v][w] = triBoxSatProjectedX(sat, float(v) + 0.5f, float(w) + 0.5f);
            for (int w = 0; w < n.z; ++w)
                for (int u = 0; u < n.x; ++u) zx[w][u] = triBoxSatProjectedY(sat, float(w) + 0.5f, float(u) + 0.5f);
            for (int u = 0; u < n.x; ++u)
                for (int v = 0; v < n.y; ++v) {
                    if (!xy[u][v]) continue;
                    for (int w = 0; w < n.z; ++w)
                        if (yz[v][w] && zx[w][u] &&
                            triBoxSatPlane(sat, glm::vec3(float(u) + 0.5f, float(v) + 0.5f, float(w) + 0.5f)))
                            mark(lo.x + u, lo.y + v, lo.z + w);
                }
        }

        // Write the marked nodes and clear what this tile set.
        for (const uint32_t node : s.setNodes) {
            const uint32_t m = marked[node], w = wood[node];
            const size_t out = g.index(i, j0 + int(node / uint32_t(nodesZ)), 1 + int(node % uint32_t(nodesZ)));
            grid.density[out] = float(m) / float(sc3);
            grid.woodFraction[out] = float(w) / float(m);
            marked[node] = 0;
            wood[node] = 0;
        }
        for (const uint32_t cell : s.setCells) flags[cell] = 0;
        s.setNodes.clear();
        s.setCells.clear();

        if (progress) {
            const size_t done = doneWork.fetch_add(eEnd - eBegin + 1) + (eEnd - eBegin + 1);
            const double fraction = kSetupShare + (1.0 - kSetupShare) * double(done) / double(totalWork);
            const int step = int(fraction * kProgressSteps);
            std::lock_guard lock(reportMutex);
            if (step > reportedStep) {
                reportedStep = step;
                progress->report(double(step) / kProgressSteps, "voxelizing");
            }
        }
    };
    tbb::parallel_for(tbb::blocked_range<size_t>(0, tileCount, 1),
                      [&](const tbb::blocked_range<size_t>& r) {
                          for (size_t tile = r.begin(); tile != r.end(); ++tile) runTile(tile);
                      },
                      tbb::simple_partitioner());
    if (progress) progress->report(1.0, "voxelizing");
    return grid;
}

} // namespace sylva
