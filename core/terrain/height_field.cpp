// The min/max pyramid of a height field.
#include "core/terrain/height_field.h"

#include <algorithm>
#include <cmath>
#include <string>

#include <tbb/parallel_for.h>

#include "core/base/error.h"

namespace sylva {

double surfaceHeight(const HeightField& h, double x, double z)
{
    const HeightFieldLayout& L = h.layout;
    const double u = x / double(L.dx), w = z / double(L.dz);
    if (!(u >= 0.0 && u <= double(L.nx - 1) && w >= 0.0 && w <= double(L.nz - 1))) return std::nan("");
    const uint32_t i = std::min(uint32_t(u), L.nx - 2), j = std::min(uint32_t(w), L.nz - 2);
    const double s = u - double(i), r = w - double(j);
    const double h00 = h.at(i, j), h10 = h.at(i + 1, j), h01 = h.at(i, j + 1), h11 = h.at(i + 1, j + 1);
    // Triangle 2c = (p00, p11, p10) holds s >= r, triangle 2c + 1 = (p00, p01, p11) the rest.
    return s >= r ? h00 + s * (h10 - h00) + r * (h11 - h10) : h00 + r * (h01 - h00) + s * (h11 - h01);
}

HeightField buildHeightField(std::vector<float> heights, uint32_t nx, uint32_t nz, float dx, float dz, uint32_t block)
{
    if (nx < 2 || nz < 2)
        throw Error(std::string("height field: ") + std::to_string(nx) + " x " + std::to_string(nz) + " samples; it needs at least 2 x 2");
    if (heights.size() != size_t(nx) * size_t(nz))
        throw Error(std::string("height field: ") + std::to_string(heights.size()) + " heights for " + std::to_string(nx) + " x " + std::to_string(nz) + " samples");
    if (!std::isfinite(dx) || !(dx > 0.0f) || !std::isfinite(dz) || !(dz > 0.0f))
        throw Error(std::string("height field: sample spacing ") + std::to_string(dx) + " x " + std::to_string(dz) + " must be finite and > 0");
    if (block < 1 || block > kMaxHeightBlock)
        throw Error("height field: block of " + std::to_string(block) + " cells; it must be 1 to " + std::to_string(kMaxHeightBlock));
    for (size_t k = 0; k < heights.size(); ++k)
        if (!std::isfinite(heights[k]))
            throw Error(std::string("height field: sample (") + std::to_string(k % nx) + ", " + std::to_string(k / nx) + ") is not a finite height");
    HeightField h;
    HeightFieldLayout& L = h.layout;
    L.nx = nx;
    L.nz = nz;
    L.dx = dx;
    L.dz = dz;
    L.block = block;
    h.heights = std::move(heights);
    // Level 0: one range per block of cells, over the block's samples (edges shared with neighbours).
    uint32_t w = (nx - 1 + block - 1) / block, d = (nz - 1 + block - 1) / block;
    size_t total = 0;
    for (uint32_t lw = w, ld = d;; lw = (lw + 1) / 2, ld = (ld + 1) / 2) {
        if (L.levels == uint32_t(kMaxHeightLevels)) throw Error("height field: too many samples");
        L.levelOffset[L.levels] = uint32_t(total);
        L.levelWidth[L.levels] = lw;
        L.levelDepth[L.levels] = ld;
        ++L.levels;
        total += size_t(lw) * ld;
        if (lw == 1 && ld == 1) break;
    }
    h.ranges.resize(total);
    const float* s = h.heights.data();
    tbb::parallel_for(uint32_t(0), d, [&](uint32_t bj) {
        for (uint32_t bi = 0; bi < w; ++bi) {
            float lo = INFINITY, hi = -INFINITY;
            const uint32_t i1 = std::min(nx - 1, (bi + 1) * block), j1 = std::min(nz - 1, (bj + 1) * block);
            for (uint32_t j = bj * block; j <= j1; ++j)
                for (uint32_t i = bi * block; i <= i1; ++i) {
                    lo = std::min(lo, s[size_t(j) * nx + i]);
                    hi = std::max(hi, s[size_t(j) * nx + i]);
                }
            h.ranges[size_t(bj) * w + bi] = glm::vec2(lo, hi);
        }
    });
    for (uint32_t l = 1; l < L.levels; ++l) {
        const uint32_t cw = L.levelWidth[l - 1], cd = L.levelDepth[l - 1];
        const glm::vec2* child = &h.ranges[L.levelOffset[l - 1]];
        glm::vec2* out = &h.ranges[L.levelOffset[l]];
        for (uint32_t bj = 0; bj < L.levelDepth[l]; ++bj)
            for (uint32_t bi = 0; bi < L.levelWidth[l]; ++bi) {
                glm::vec2 r(INFINITY, -INFINITY);
                for (uint32_t b = 0; b < 2; ++b)
                    for (uint32_t a = 0; a < 2; ++a) {
                        const uint32_t ci = 2 * bi + a, cj = 2 * bj + b;
                        if (ci >= cw || cj >= cd) continue;
                        r.x = std::min(r.x, child[size_t(cj) * cw + ci].x);
                        r.y = std::max(r.y, child[size_t(cj) * cw + ci].y);
                    }
                out[size_t(bj) * L.levelWidth[l] + bi] = r;
            }
    }
    return h;
}

} // namespace sylva
