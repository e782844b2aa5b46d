// Slices of a species' density and LB lighting grids for the volume inspector: which node a slice
// pixel shows, the value a channel reads there, and the colour map that draws it.
#pragma once

#include <QImage>
#include <QString>

#include "pipeline/render/render_job.h"

namespace sylva {

enum class SliceAxis { XY, XZ, YZ };                                      // the plane shown
enum class VolumeChannel { Red, Green, Blue, Luminance, Density, Wood };  // what is shown

const char* sliceAxisName(SliceAxis axis);          // "XY", "XZ", "YZ"
const char* volumeChannelName(VolumeChannel c);     // "R", "G", "B", "luminance", "density", "wood fraction"
// Whether the grids hold the channel (lighting channels need a lighting grid, wood a wood fraction).
bool hasChannel(const SpeciesGrids& grids, VolumeChannel c);

// Size of a slice in nodes: XY is dims.x by dims.y, XZ dims.x by dims.z, YZ dims.y by dims.z
// (first axis to the right, second one up); depth runs along the third axis.
QSize sliceSize(const GridGeometry& g, SliceAxis axis);
int sliceDepthCount(const GridGeometry& g, SliceAxis axis);
// The node that slice pixel (column, row) shows at `depth`; row 0 is the top of the picture, the
// second axis' last node.
glm::ivec3 sliceNode(const GridGeometry& g, SliceAxis axis, int depth, int column, int row);

// The channel's value at a node: lighting R/G/B (photon density as solved), luminance
// (0.2126 R + 0.7152 G + 0.0722 B), density rho, wood fraction.
float nodeValue(const SpeciesGrids& grids, VolumeChannel c, const glm::ivec3& node);

// A slice: values row by row (row 0 on top), with their range.
struct Slice {
    QSize size;
    std::vector<float> values;
    float min = 0.0f, max = 0.0f;
    float at(int column, int row) const { return values[size_t(row) * size_t(size.width()) + size_t(column)]; }
};
Slice extractSlice(const SpeciesGrids& grids, VolumeChannel c, SliceAxis axis, int depth);

// The colour map: a perceptually ordered ramp (dark blue-violet through orange to pale yellow), t in [0,1]
// (clamped); t = 0 is (0, 0, 4) and t = 1 is (252, 255, 164).
QRgb colourMap(float t);
// Where a value falls in [min, max] (0 when the range is empty).
float mapToUnit(float value, float min, float max);
// The slice drawn with the colour map over its own range, one pixel per node.
QImage sliceImage(const Slice& slice);
// A horizontal legend bar, `width` x `height` pixels: the colour map from 0 (left) to 1 (right).
QImage legendImage(int width, int height);

} // namespace sylva
