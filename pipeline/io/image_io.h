// Image files through OpenImageIO: read any format it knows as RGBA float, write atomically.
#pragma once

#include <string>

#include "core/image/image.h"

namespace sylva {

// Reads an image as RGBA float in [0,1] (8/16-bit data normalized), straight (not premultiplied) alpha. Grey becomes RGB, a missing
// alpha becomes 1, palette PNGs with transparency keep their alpha. Throws Error naming the file.
ImageRgba readImage(const std::string& path);

// Reads only the header; returns true and the channel count when the file has an alpha channel.
bool imageHasAlpha(const std::string& path);

// Writes straight-alpha RGBA; the format follows the extension (.png/.tif 8-bit, .exr half float).
// Written to a temporary file in the same folder, then renamed. Throws Error naming the file.
void writeImage(const std::string& path, const ImageRgba& image, int channels = 4);

} // namespace sylva
