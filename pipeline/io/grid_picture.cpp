// Montage of density and lighting slices (layout and orientation in grid_picture.h).
#include "pipeline/io/grid_picture.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "core/base/error.h"
#include "pipeline/io/image_io.h"

namespace sylva {

namespace {

constexpr int kGap = 2;
constexpr float kGapGrey = 0.25f;
constexpr double kRobustQuantile = 0.995;
constexpr size_t kMaxQuantileSamples = size_t(1) << 22;

float srgbEncode(float linear)
{
    const float x = std::clamp(linear, 0.0f, 1.0f);
    return x <= 0.0031308f ? 12.92f * x : 1.055f * std::pow(x, 1.0f / 2.4f) - 0.055f;
}

std::string dimsText(glm::ivec3 d)
{
    return std::to_string(d.x) + "x" + std::to_string(d.y) + "x" + std::to_string(d.z);
}

// 99.5th percentile of the finite channel values at interior nodes (all nodes along an axis with
// fewer than 3), from at most kMaxQuantileSamples evenly strided samples; 1 when not positive.
float robustMax(const LightingGrid& grid)
{
    const glm::ivec3 d = grid.geometry.dims;
    glm::ivec3 lo, hi;
    for (int a = 0; a < 3; ++a) {
        lo[a] = d[a] >= 3 ? 1 : 0;
        hi[a] = d[a] >= 3 ? d[a] - 1 : d[a];
    }
    const size_t interior = size_t(hi.x - lo.x) * size_t(hi.y - lo.y) * size_t(hi.z - lo.z) * 3;
    const size_t stride = std::max<size_t>(1, interior / kMaxQuantileSamples);
    std::vector<float> values;
    values.reserve(interior / stride + 1);
    size_t counter = 0;
    for (int i = lo.x; i < hi.x; ++i)
        for (int j = lo.y; j < hi.y; ++j)
            for (int k = lo.z; k < hi.z; ++k)
                for (int c = 0; c < 3; ++c, ++counter) {
                    if (counter % stride != 0) continue;
                    const float v = grid.at(i, j, k, c);
                    if (std::isfinite(v)) values.push_back(v);
                }
    if (values.empty()) return 1.0f;
    const size_t q = size_t(kRobustQuantile * double(values.size() - 1));
    std::nth_element(values.begin(), values.begin() + std::ptrdiff_t(q), values.end());
    const float m = values[q];
    return m > 0.0f && std::isfinite(m) ? m : 1.0f;
}

} // namespace

ImageRgba gridMontage(const DensityGrid* density, const LightingGrid* lighting, int axis, int slices, int tilePixels)
{
    if (!density && !lighting) throw Error("grid picture: neither a density nor a lighting grid was given");
    if (axis < 0 || axis > 2) throw Error("grid picture: axis must be 0 (x), 1 (y) or 2 (z), not " + std::to_string(axis));
    const glm::ivec3 dims = density ? density->geometry.dims : lighting->geometry.dims;
    if (dims.x <= 0 || dims.y <= 0 || dims.z <= 0) throw Error("grid picture: the grid has empty dims " + dimsText(dims));
    if (density && lighting && density->geometry.dims != lighting->geometry.dims)
        throw Error("grid picture: the density grid (" + dimsText(density->geometry.dims) + ") and the lighting grid (" +
                    dimsText(lighting->geometry.dims) + ") differ in dims");
    const size_t nodes = size_t(dims.x) * size_t(dims.y) * size_t(dims.z);
    if (density && density->density.size() != nodes) throw Error("grid picture: the density array does not match dims " + dimsText(dims));
    if (lighting && lighting->rgb.size() != nodes * 3) throw Error("grid picture: the lighting array does not match dims " + dimsText(dims));

    // In-plane axes: u runs to the right, v down the rows (flipped when v points up).
    const int uAxis = axis == 0 ? 2 : 0;
    const int vAxis = axis == 1 ? 2 : 1;
    const bool flipV = axis != 1;
    const int uN = dims[uAxis], vN = dims[vAxis], depthN = dims[axis];
    const int scale = std::max(1, std::max(1, tilePixels) / std::max(uN, vN));
    const int tileW = uN * scale, tileH = vN * scale;
    const int count = std::clamp(slices, 1, depthN);
    const int cols = int(std::ceil(std::sqrt(double(count))));
    const int rows = (count + cols - 1) / cols;
    const int perSlice = (density && lighting) ? 2 : 1;
    const int width = kGap + cols * perSlice * (tileW + kGap);
    const int height = kGap + rows * (tileH + kGap);
    if (size_t(width) * size_t(height) > (size_t(1) << 28)) throw Error("grid picture: the montage would be too large");

    ImageRgba image(width, height, glm::vec4(kGapGrey, kGapGrey, kGapGrey, 1.0f));
    const GridGeometry& g = density ? density->geometry : lighting->geometry;
    const float lightScale = lighting ? 1.0f / robustMax(*lighting) : 1.0f;

    for (int s = 0; s < count; ++s) {
        const int depth = int((double(s) + 0.5) * double(depthN) / double(count));
        const int x0 = kGap + (s % cols) * perSlice * (tileW + kGap);
        const int y0 = kGap + (s / cols) * (tileH + kGap);
        for (int py = 0; py < tileH; ++py) {
            const int row = py / scale;
            const int v = flipV ? vN - 1 - row : row;
            for (int px = 0; px < tileW; ++px) {
                glm::ivec3 c;
                c[axis] = depth;
                c[uAxis] = px / scale;
                c[vAxis] = v;
                const size_t node = g.index(c.x, c.y, c.z);
                int x = x0 + px;
                if (density) {
                    const float raw = density->density[node];
                    float* p = image.at(x, y0 + py);
                    if (std::isfinite(raw)) {
                        const float grey = std::clamp(raw, 0.0f, 1.0f);
                        p[0] = p[1] = p[2] = grey;
                    } else {
                        p[0] = 1.0f, p[1] = 0.0f, p[2] = 1.0f;
                    }
                    x += tileW + kGap;
                }
                if (lighting) {
                    const float* rgb = &lighting->rgb[node * 3];
                    float* p = image.at(x, y0 + py);
                    if (std::isfinite(rgb[0]) && std::isfinite(rgb[1]) && std::isfinite(rgb[2])) {
                        for (int ch = 0; ch < 3; ++ch) p[ch] = srgbEncode(rgb[ch] * lightScale);
                    } else {
                        p[0] = 1.0f, p[1] = 0.0f, p[2] = 1.0f;
                    }
                }
            }
        }
    }
    return image;
}

void writeGridMontage(const std::string& pngPath, const DensityGrid* density, const LightingGrid* lighting, int axis, int slices,
                      int tilePixels)
{
    ImageRgba image;
    try {
        image = gridMontage(density, lighting, axis, slices, tilePixels);
    } catch (const Error& e) {
        throw Error(pngPath + ": " + e.what());
    }
    writeImage(pngPath, image, 3);
}

} // namespace sylva
