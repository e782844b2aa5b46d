// RGBA float image in memory: textures, films, pictures of grids.
#pragma once

#include <cstddef>
#include <vector>

#include <glm/glm.hpp>

namespace sylva {

// Row-major, top row first, 4 floats per pixel (RGBA) in [0,1] for LDR data; 16 bytes per pixel.
// Values are as stored in the file (sRGB-encoded for 8-bit colour textures); alpha is linear coverage.
struct ImageRgba {
    int width = 0;
    int height = 0;
    std::vector<float> pixels;

    ImageRgba() = default;
    ImageRgba(int w, int h, glm::vec4 fill = glm::vec4(0.0f)) : width(w), height(h), pixels(size_t(w) * size_t(h) * 4)
    {
        for (size_t p = 0; p < size_t(w) * size_t(h); ++p)
            for (int c = 0; c < 4; ++c) pixels[p * 4 + size_t(c)] = fill[c];
    }
    bool empty() const { return width <= 0 || height <= 0; }
    float* at(int x, int y) { return &pixels[(size_t(y) * size_t(width) + size_t(x)) * 4]; }
    const float* at(int x, int y) const { return &pixels[(size_t(y) * size_t(width) + size_t(x)) * 4]; }
};

// Cut-outs: a texel whose alpha (coverage) is below kCutoutThreshold lets rays through (the renderer's 1-bit alpha
// masks); a cut-out image with no such texel is opaque and gets no mask. The glTF export's alphaCutoff.
inline constexpr float kCutoutThreshold = 0.5f;
inline bool hasClearTexels(const ImageRgba& img)
{
    for (size_t p = 0; p < size_t(img.width) * size_t(img.height); ++p)
        if (img.pixels[p * 4 + 3] < kCutoutThreshold) return true;
    return false;
}

} // namespace sylva
