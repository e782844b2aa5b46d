// Slice geometry, channel values and the inspector's colour map.
#include "studio/volume_slice.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/base/error.h"

namespace sylva {
namespace {

// Control points of the ramp, evenly spaced in t (an inferno-like sequence: monotonic in lightness).
constexpr int kStops = 9;
constexpr unsigned char kRamp[kStops][3] = {
    {0, 0, 4},     {31, 12, 72},   {85, 15, 109},  {136, 34, 106}, {186, 54, 85},
    {227, 89, 51}, {249, 140, 10}, {249, 201, 50}, {252, 255, 164},
};

} // namespace

const char* sliceAxisName(SliceAxis axis)
{
    switch (axis) {
    case SliceAxis::XY: return "XY";
    case SliceAxis::XZ: return "XZ";
    case SliceAxis::YZ: return "YZ";
    }
    return "?";
}

const char* volumeChannelName(VolumeChannel c)
{
    switch (c) {
    case VolumeChannel::Red: return "R";
    case VolumeChannel::Green: return "G";
    case VolumeChannel::Blue: return "B";
    case VolumeChannel::Luminance: return "luminance";
    case VolumeChannel::Density: return "density";
    case VolumeChannel::Wood: return "wood fraction";
    }
    return "?";
}

bool hasChannel(const SpeciesGrids& grids, VolumeChannel c)
{
    switch (c) {
    case VolumeChannel::Density: return grids.density.density.size() == grids.density.geometry.nodeCount() && !grids.density.density.empty();
    case VolumeChannel::Wood:
        return grids.density.woodFraction.size() == grids.density.geometry.nodeCount() && !grids.density.woodFraction.empty();
    default: return grids.lighting.rgb.size() == grids.lighting.geometry.nodeCount() * 3 && !grids.lighting.rgb.empty();
    }
}

QSize sliceSize(const GridGeometry& g, SliceAxis axis)
{
    switch (axis) {
    case SliceAxis::XY: return {g.dims.x, g.dims.y};
    case SliceAxis::XZ: return {g.dims.x, g.dims.z};
    case SliceAxis::YZ: return {g.dims.y, g.dims.z};
    }
    return {};
}

int sliceDepthCount(const GridGeometry& g, SliceAxis axis)
{
    switch (axis) {
    case SliceAxis::XY: return g.dims.z;
    case SliceAxis::XZ: return g.dims.y;
    case SliceAxis::YZ: return g.dims.x;
    }
    return 0;
}

glm::ivec3 sliceNode(const GridGeometry& g, SliceAxis axis, int depth, int column, int row)
{
    const int up = sliceSize(g, axis).height() - 1 - row;
    switch (axis) {
    case SliceAxis::XY: return {column, up, depth};
    case SliceAxis::XZ: return {column, depth, up};
    case SliceAxis::YZ: return {depth, column, up};
    }
    return {};
}

float nodeValue(const SpeciesGrids& grids, VolumeChannel c, const glm::ivec3& n)
{
    switch (c) {
    case VolumeChannel::Density: return grids.density.density[grids.density.geometry.index(n.x, n.y, n.z)];
    case VolumeChannel::Wood: return grids.density.woodFraction[grids.density.geometry.index(n.x, n.y, n.z)];
    case VolumeChannel::Red: return grids.lighting.at(n.x, n.y, n.z, 0);
    case VolumeChannel::Green: return grids.lighting.at(n.x, n.y, n.z, 1);
    case VolumeChannel::Blue: return grids.lighting.at(n.x, n.y, n.z, 2);
    case VolumeChannel::Luminance:
        return 0.2126f * grids.lighting.at(n.x, n.y, n.z, 0) + 0.7152f * grids.lighting.at(n.x, n.y, n.z, 1) +
               0.0722f * grids.lighting.at(n.x, n.y, n.z, 2);
    }
    return 0.0f;
}

Slice extractSlice(const SpeciesGrids& grids, VolumeChannel c, SliceAxis axis, int depth)
{
    if (!hasChannel(grids, c)) throw Error(std::string("the grids hold no ") + volumeChannelName(c) + " channel");
    const GridGeometry& g = (c == VolumeChannel::Density || c == VolumeChannel::Wood) ? grids.density.geometry
                                                                                      : grids.lighting.geometry;
    const int depths = sliceDepthCount(g, axis);
    if (depth < 0 || depth >= depths)
        throw Error("slice " + std::to_string(depth) + " is outside the grid (0.." + std::to_string(depths - 1) + ")");
    Slice s;
    s.size = sliceSize(g, axis);
    s.values.resize(size_t(s.size.width()) * size_t(s.size.height()));
    s.min = std::numeric_limits<float>::infinity();
    s.max = -std::numeric_limits<float>::infinity();
    for (int row = 0; row < s.size.height(); ++row)
        for (int col = 0; col < s.size.width(); ++col) {
            const float v = nodeValue(grids, c, sliceNode(g, axis, depth, col, row));
            s.values[size_t(row) * size_t(s.size.width()) + size_t(col)] = v;
            if (std::isfinite(v)) {
                s.min = std::min(s.min, v);
                s.max = std::max(s.max, v);
            }
        }
    if (!(s.min <= s.max)) s.min = s.max = 0.0f;
    return s;
}

QRgb colourMap(float t)
{
    if (!(t > 0.0f)) t = 0.0f;   // NaN too
    t = std::min(t, 1.0f);
    const float x = t * float(kStops - 1);
    const int i = std::min(int(x), kStops - 2);
    const float f = x - float(i);
    int rgb[3];
    for (int c = 0; c < 3; ++c)
        rgb[c] = int(std::lround(float(kRamp[i][c]) + f * (float(kRamp[i + 1][c]) - float(kRamp[i][c]))));
    return qRgb(rgb[0], rgb[1], rgb[2]);
}

float mapToUnit(float value, float min, float max)
{
    if (!(max > min)) return 0.0f;
    return std::clamp((value - min) / (max - min), 0.0f, 1.0f);
}

QImage sliceImage(const Slice& slice)
{
    QImage img(slice.size, QImage::Format_RGB32);
    for (int row = 0; row < slice.size.height(); ++row) {
        auto* line = reinterpret_cast<QRgb*>(img.scanLine(row));
        for (int col = 0; col < slice.size.width(); ++col) line[col] = colourMap(mapToUnit(slice.at(col, row), slice.min, slice.max));
    }
    return img;
}

QImage legendImage(int width, int height)
{
    QImage img(std::max(1, width), std::max(1, height), QImage::Format_RGB32);
    for (int x = 0; x < img.width(); ++x) {
        const QRgb c = colourMap(img.width() > 1 ? float(x) / float(img.width() - 1) : 0.0f);
        for (int y = 0; y < img.height(); ++y) img.setPixel(x, y, c);
    }
    return img;
}

} // namespace sylva
