// Image files through OpenImageIO: read any format it knows as RGBA float, write atomically.
#pragma once

#include <memory>
#include <string>
#include <vector>

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

// Named float channels, interleaved per pixel (width * height * channels.size() values, top row first),
// written as 32-bit float: a multi-layer EXR when the names follow the "Layer.Channel" convention
// ("Combined.R", "Depth.Z"), which Blender, Nuke and OpenImageIO read as layers. The file is written
// as writeImage writes (same temporary file and rename). attributes: string attributes for the header as
// name, value, name, value, ... (Cryptomatte's metadata). Throws Error naming the file (extension not
// .exr, size mismatch, write failure).
void writeImageChannels(const std::string& path, int width, int height, const std::vector<std::string>& channels,
                        const std::vector<float>& interleaved, const std::vector<std::string>& attributes = {});

// An RGB image written a band of rows at a time, top row first (a frame too large to hold whole):
// .png/.tif/.tiff 8-bit (values clamped to [0,1]), .exr half float. Like writeImage it writes a
// temporary file beside the target and renames it in finish(); a writer destroyed before finish()
// leaves the target untouched. Throws Error naming the file.
class RowImageWriter {
public:
    RowImageWriter(const std::string& path, int width, int height);
    ~RowImageWriter();
    RowImageWriter(const RowImageWriter&) = delete;
    RowImageWriter& operator=(const RowImageWriter&) = delete;
    // The next `rows` rows, width * rows * 3 floats.
    void writeRows(const float* rgb, int rows);
    void finish();

private:
    struct Impl;
    std::unique_ptr<Impl> m;
};

} // namespace sylva
