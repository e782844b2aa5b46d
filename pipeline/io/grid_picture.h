// Pictures of grids: a montage of slices through density (grey) and lighting (RGB) for eyeballing results.
#pragma once

#include <string>

#include "core/grid/grid.h"
#include "core/image/image.h"

namespace sylva {

// A PNG-ready montage of `slices` slices perpendicular to `axis` (0 = x, 1 = y, 2 = z), at depths
// floor((s + 0.5) * D / slices) for s = 0..slices-1 (D = nodes along the axis; slices is clamped to
// [1, D]). Each slice is a density tile (grey, value clamped to [0,1]) with the lighting tile (RGB
// divided by the 99.5th percentile of the interior nodes' channel values, clamped, sRGB-encoded)
// beside it; with only one grid given, only its tiles. Non-finite values show magenta.
//
// Tile orientation, as seen by a viewer (rows are flipped where an axis points up):
//   axis 0 (x): z to the right, y up        axis 1 (y): x to the right, z down (seen from above)
//   axis 2 (z): x to the right, y up
// Each node is `scale` x `scale` pixels, scale = max(1, tilePixels / longest tile edge in nodes).
// Layout: cols = ceil(sqrt(slices)) slices per row, rows = ceil(slices / cols), tiles per slice
// t = 2 (both grids) or 1, a gap of 2 px (grey 0.25) around and between all tiles:
//   width  = 2 + cols * t * (tileWidth + 2),  height = 2 + rows * (tileHeight + 2)
// Slices run left to right, then top to bottom. Alpha is 1 everywhere.
// Throws Error when both grids are null, their dims differ, or their arrays do not match their dims.
ImageRgba gridMontage(const DensityGrid* density, const LightingGrid* lighting, int axis = 2, int slices = 8,
                      int tilePixels = 64);

// gridMontage written to an image file (PNG by extension, through writeImage: atomic). Throws Error.
void writeGridMontage(const std::string& pngPath, const DensityGrid* density, const LightingGrid* lighting, int axis = 2,
                      int slices = 8, int tilePixels = 64);

} // namespace sylva
