// Generated textures for grown trees: per-species leaf cut-outs (alpha 0 outside, 1 inside) and tileable bark.
#pragma once

#include "core/image/image.h"
#include "pipeline/grow/tree_grower.h"

namespace sylva {

// A size x size RGBA leaf card: stem at the bottom row, tip at the top; alpha exactly 0 or 1.
// Broadleaf: ovate with veins; birch: serrated deltoid; conifer: a needle spray; shrub: three-leaflet sprig.
ImageRgba makeLeafTexture(TreeSpecies species, int size = 256);

// A size x size tileable bark texture (alpha 1); u runs around the branch, v along it.
ImageRgba makeBarkTexture(TreeSpecies species, int size = 256);

} // namespace sylva
