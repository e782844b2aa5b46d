// A regular height field as a terrain surface (Dietrich et al.'s ("Terrain Guided Multi-Level Instancing of
// Highly Complex Plant Populations") ground mesh without its vertex arrays): heights plus a min/max pyramid of
// blocks, ray-intersected through the triangles the grid implies (host and device).
#pragma once

#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "core/accel/ray.h"
#include "core/base/defines.h"
#include "core/base/traversal_stats.h"

namespace sylva {

// The terrain's own frame: +Y up, sample (i, j) at (i * dx, height, j * dz), i along x (columns), j along z
// (rows, heights[j * nx + i]). Cell (i, j) spans samples i..i+1, j..j+1 and holds two triangles split
// along its (i, j)-(i+1, j+1) diagonal: triangle 2c = (p00, p11, p10), 2c + 1 = (p00, p01, p11) with
// c = j * (nx - 1) + i. The pyramid's level 0 has one min/max per block of `block` x `block` cells (the
// block's samples, edges included); each level above merges 2 x 2 blocks, up to one block.
// kHeightBlock, the default block: intersectBlock's per-cell test is cheaper than a pyramid level, so few
// levels over large blocks trace fastest (docs/PERFORMANCE.md, Terrain: blocks of 2 to 64 measured).
inline constexpr uint32_t kHeightBlock = 32;
inline constexpr uint32_t kMaxHeightBlock = 1024;
inline constexpr int kMaxHeightLevels = 20;   // 32 x 2^19 cells a side at the default block: beyond any DEM in memory

// The shape of a height field and its pyramid (no pointers: the arrays travel with the render scene's
// other arrays, RenderView::terrainHeights and terrainRanges).
struct HeightFieldLayout {
    uint32_t nx, nz;             // samples per row / column (>= 2 each)
    float dx, dz;                // sample spacing, metres (> 0)
    uint32_t block;              // cells a side of a level-0 block (1 .. kMaxHeightBlock)
    uint32_t levels;             // pyramid levels (>= 1; the last has one block)
    uint32_t levelOffset[kMaxHeightLevels];
    uint32_t levelWidth[kMaxHeightLevels];   // blocks per row at each level (columns: levelDepth)
    uint32_t levelDepth[kMaxHeightLevels];
};

// A height field to trace: its layout, nx * nz heights and the pyramid's (min, max) heights (level 0
// first, rows of blocks).
// The traversal's frame is the terrain frame moved to sample (baseI, baseJ): sample (i, j) lies at
// ((i - baseI) dx, height, (j - baseJ) dz), so points near the base (the camera) keep float precision however
// far the terrain extends (the renderer places the base under the camera; 0, 0: the terrain frame itself).
struct HeightFieldView {
    const HeightFieldLayout& layout;
    const float* heights;
    const glm::vec2* ranges;
    int32_t baseI = 0, baseJ = 0;
};

// Host storage of a height field and its pyramid; view() points into it.
struct HeightField {
    HeightFieldLayout layout{};
    std::vector<float> heights;
    std::vector<glm::vec2> ranges;

    HeightFieldView view() const { return HeightFieldView{layout, heights.data(), ranges.data()}; }
    float at(uint32_t i, uint32_t j) const { return heights[size_t(j) * layout.nx + i]; }
    size_t triangleCount() const { return size_t(layout.nx - 1) * size_t(layout.nz - 1) * 2; }
    size_t bytes() const { return heights.size() * sizeof(float) + ranges.size() * sizeof(glm::vec2); }
};

// The height of the triangulated surface at (x, z) of the terrain frame (on the triangle over that
// point, as the traversal sees it); NaN outside the samples' footprint [0, (nx-1) dx] x [0, (nz-1) dz].
double surfaceHeight(const HeightField& h, double x, double z);

// Builds the pyramid over `heights` (nx * nz finite samples, row j = z) with level-0 blocks of `block` cells a
// side. Throws Error when nx or nz < 2, the sizes disagree, a sample is not finite, a spacing is not finite and
// > 0, or block is outside 1 .. kMaxHeightBlock.
HeightField buildHeightField(std::vector<float> heights, uint32_t nx, uint32_t nz, float dx, float dz, uint32_t block = kHeightBlock);

namespace height_detail {

SYLVA_HD SYLVA_INLINE float sampleAt(const HeightFieldView& h, uint32_t i, uint32_t j) { return h.heights[size_t(j) * h.layout.nx + i]; }

// The two triangles of cell (i, j): the closer hit in (tmin, tmax) updates t, prim and returns true.
SYLVA_HD SYLVA_INLINE bool intersectCell(const HeightFieldView& h, uint32_t i, uint32_t j, const glm::vec3& org, const glm::vec3& dir,
                                         float tmin, float& tmax, uint32_t& prim, float& u, float& v)
{
    const float x0 = float(int(i) - h.baseI) * h.layout.dx, x1 = float(int(i) + 1 - h.baseI) * h.layout.dx;
    const float z0 = float(int(j) - h.baseJ) * h.layout.dz, z1 = float(int(j) + 1 - h.baseJ) * h.layout.dz;
    const glm::vec3 p00(x0, sampleAt(h, i, j), z0), p10(x1, sampleAt(h, i + 1, j), z0);
    const glm::vec3 p01(x0, sampleAt(h, i, j + 1), z1), p11(x1, sampleAt(h, i + 1, j + 1), z1);
    const uint32_t c = j * (h.layout.nx - 1) + i;
    bool got = false;
    float t, uu, vv;
    if (intersectTriangle(org, dir, p00, p11 - p00, p10 - p00, tmin, tmax, t, uu, vv)) {
        tmax = t, prim = 2 * c, u = uu, v = vv, got = true;
    }
    if (intersectTriangle(org, dir, p00, p01 - p00, p11 - p00, tmin, tmax, t, uu, vv)) {
        tmax = t, prim = 2 * c + 1, u = uu, v = vv, got = true;
    }
    return got;
}

// The cells of level-0 block (bi, bj) along the ray in [t0, t1] (the ray's span over the block), nearest
// first (a 2D DDA over the cells' columns): the first cell with a hit holds the block's closest hit,
// because a cell's triangles lie inside its column.
SYLVA_HD SYLVA_INLINE bool intersectBlock(const HeightFieldView& h, uint32_t bi, uint32_t bj, const glm::vec3& org, const glm::vec3& dir,
                                          float t0, float t1, float tmin, float& tmax, uint32_t& prim, float& u, float& v)
{
    const uint32_t B = h.layout.block;
    const int ci0 = int(bi * B), cj0 = int(bj * B);
    const int ci1 = int(minf(float((bi + 1) * B), float(h.layout.nx - 1))) - 1;
    const int cj1 = int(minf(float((bj + 1) * B), float(h.layout.nz - 1))) - 1;
    const glm::vec3 p = org + t0 * dir;   // where the ray enters the block's box
    int ci = int(floorf(p.x / h.layout.dx)) + h.baseI, cj = int(floorf(p.z / h.layout.dz)) + h.baseJ;
    ci = ci < ci0 ? ci0 : (ci > ci1 ? ci1 : ci);
    cj = cj < cj0 ? cj0 : (cj > cj1 ? cj1 : cj);
    const int si = dir.x > 0.0f ? 1 : (dir.x < 0.0f ? -1 : 0), sj = dir.z > 0.0f ? 1 : (dir.z < 0.0f ? -1 : 0);
    // Distance to the next column boundary on each axis, and between boundaries.
    const float big = 3.0e38f;
    const float ddx = si != 0 ? h.layout.dx / fabsf(dir.x) : big, ddz = sj != 0 ? h.layout.dz / fabsf(dir.z) : big;
    float nextX = si > 0 ? (float(ci + 1 - h.baseI) * h.layout.dx - org.x) / dir.x : (si < 0 ? (float(ci - h.baseI) * h.layout.dx - org.x) / dir.x : big);
    float nextZ = sj > 0 ? (float(cj + 1 - h.baseJ) * h.layout.dz - org.z) / dir.z : (sj < 0 ? (float(cj - h.baseJ) * h.layout.dz - org.z) / dir.z : big);
    float tIn = t0;
    for (;;) {
        const float tExit = minf(nextX, nextZ);
        // Only where the ray's height over the cell's column overlaps the cell's samples (padded for
        // rounding) can it meet the cell's triangles: most cells under a ray are skipped here.
        const float ya = dir.y != 0.0f ? org.y + tIn * dir.y : org.y, yb = dir.y != 0.0f ? org.y + minf(tExit, t1) * dir.y : org.y;
        const float s00 = sampleAt(h, uint32_t(ci), uint32_t(cj)), s10 = sampleAt(h, uint32_t(ci) + 1, uint32_t(cj));
        const float s01 = sampleAt(h, uint32_t(ci), uint32_t(cj) + 1), s11 = sampleAt(h, uint32_t(ci) + 1, uint32_t(cj) + 1);
        const float clo = minf(minf(s00, s10), minf(s01, s11)), chi = maxf(maxf(s00, s10), maxf(s01, s11));
        const float pad = 1e-5f * (fabsf(ya) + fabsf(yb) + fabsf(clo) + fabsf(chi)) + 1e-6f;
        SYLVA_COUNT(g_terrainCellTests);
        if (!(minf(ya, yb) > chi + pad || maxf(ya, yb) < clo - pad) &&
            intersectCell(h, uint32_t(ci), uint32_t(cj), org, dir, tmin, tmax, prim, u, v))
            return true;
        if (tExit > t1 || tExit >= tmax) return false;
        tIn = tExit;
        if (nextX < nextZ) {
            ci += si;
            nextX += ddx;
            if (ci < ci0 || ci > ci1) return false;
        } else {
            cj += sj;
            nextZ += ddz;
            if (cj < cj0 || cj > cj1) return false;
        }
    }
}

} // namespace height_detail

// The closest (or, AnyHit, any) hit of a ray in the terrain frame with t in (tmin, tmax): writes tmax = t,
// prim (triangle, see above), u, v (that triangle's barycentrics of its 2nd and 3rd vertex) and returns
// true. Top-down through the pyramid: a block is entered only where the ray passes between its min and
// max height, children nearest first; blocks beyond the closest hit so far are skipped.
template <bool AnyHit>
SYLVA_HD SYLVA_INLINE bool intersectHeightField(const HeightFieldView& h, const Ray& ray, float& tmax, uint32_t& prim, float& u, float& v)
{
    const glm::vec3 inv = safeReciprocal(ray.dir);
    struct Entry {
        uint32_t level, bi, bj;
    };
    Entry stack[3 * kMaxHeightLevels + 1];
    int top = 0;
    stack[top++] = Entry{h.layout.levels - 1, 0, 0};
    bool got = false;
    const float cellsX = float(h.layout.nx - 1), cellsZ = float(h.layout.nz - 1);
    while (top > 0) {
        const Entry e = stack[--top];
        SYLVA_COUNT(g_terrainBlockVisits);
        const float span = float(h.layout.block << e.level);
        const glm::vec2 r = h.ranges[h.layout.levelOffset[e.level] + e.bj * h.layout.levelWidth[e.level] + e.bi];
        const float bx = float(h.baseI), bz = float(h.baseJ);
        const glm::vec3 lo((float(e.bi) * span - bx) * h.layout.dx, r.x, (float(e.bj) * span - bz) * h.layout.dz);
        const glm::vec3 hi((minf(float(e.bi + 1) * span, cellsX) - bx) * h.layout.dx, r.y, (minf(float(e.bj + 1) * span, cellsZ) - bz) * h.layout.dz);
        const float tNear = rayBoxEntry(lo, hi, ray.org, inv, ray.tmin, tmax);
        if (!(tNear <= tmax)) continue;
        if (e.level == 0) {
            // Where the ray leaves the block's columns, or a rising ray rises above the block's highest sample
            // (no triangle of the block lies higher), padded by at least what intersectBlock pads a cell's test
            // with there (its four terms are at most max(|lo.y|, |hi.y|) each); an axis the ray does not move
            // along sets no limit (the box test above found the ray inside that slab).
            const float txFar = ray.dir.x != 0.0f ? maxf((lo.x - ray.org.x) * inv.x, (hi.x - ray.org.x) * inv.x) : 3.0e38f;
            const float tzFar = ray.dir.z != 0.0f ? maxf((lo.z - ray.org.z) * inv.z, (hi.z - ray.org.z) * inv.z) : 3.0e38f;
            const float pad = 4e-5f * maxf(fabsf(lo.y), fabsf(hi.y)) + 1e-6f;
            const float tAbove = ray.dir.y > 0.0f ? (hi.y + pad - ray.org.y) * inv.y : 3.0e38f;
            const float tFar = minf(minf(txFar, tzFar), minf(tAbove, tmax));
            if (height_detail::intersectBlock(h, e.bi, e.bj, ray.org, ray.dir, tNear, tFar, ray.tmin, tmax, prim, u, v)) {
                got = true;
                if (AnyHit) return true;
            }
            continue;
        }
        // Children: (2bi + a, 2bj + b) for the ones that exist at the level below, pushed far first.
        const uint32_t cl = e.level - 1, w = h.layout.levelWidth[cl], d = h.layout.levelDepth[cl];
        const uint32_t fi = ray.dir.x < 0.0f ? 1u : 0u, fj = ray.dir.z < 0.0f ? 1u : 0u;   // the nearer child per axis
        for (int k = 3; k >= 0; --k) {
            const uint32_t a = (uint32_t(k) & 1u) ^ fi, b = (uint32_t(k) >> 1) ^ fj;
            const uint32_t ci = 2 * e.bi + a, cj = 2 * e.bj + b;
            if (ci < w && cj < d) stack[top++] = Entry{cl, ci, cj};
        }
    }
    return got;
}

// The geometric normal of triangle `prim` (unit, pointing up: +Y component >= 0).
SYLVA_HD inline glm::vec3 heightFieldNormal(const HeightFieldView& h, uint32_t prim)
{
    const uint32_t c = prim >> 1, i = c % (h.layout.nx - 1), j = c / (h.layout.nx - 1);
    const float x0 = float(i) * h.layout.dx, x1 = float(i + 1) * h.layout.dx, z0 = float(j) * h.layout.dz, z1 = float(j + 1) * h.layout.dz;
    const glm::vec3 p00(x0, height_detail::sampleAt(h, i, j), z0), p11(x1, height_detail::sampleAt(h, i + 1, j + 1), z1);
    const glm::vec3 other = (prim & 1u) ? glm::vec3(x0, height_detail::sampleAt(h, i, j + 1), z1) : glm::vec3(x1, height_detail::sampleAt(h, i + 1, j), z0);
    const glm::vec3 n = glm::normalize(glm::cross(p11 - p00, other - p00));
    return n.y < 0.0f ? -n : n;
}

} // namespace sylva
