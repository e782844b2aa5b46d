// Pictures of `sylva study truth` (study_image.cpp): the channels of Cycles' multi-layer EXR, the image maths
// the comparison needs (products, sums, relative L2, FLIP) and heat maps of errors.
#pragma once

#include <map>
#include <string>
#include <vector>

#include <glm/vec3.hpp>

namespace sylva::study {

using Image = std::vector<glm::vec3>;
// The channels of a multi-layer EXR by name ("ViewLayer.Combined.R" ...).
using ExrChannels = std::map<std::string, std::vector<float>>;

// Channels of a multi-layer EXR by name, read with OpenImageIO; w, h: its size. Throws Error.
ExrChannels readExrChannels(const std::string& path, int& w, int& h);

// Layer `name` (R, G, B) of a Cycles EXR; empty when absent.
Image layer(const ExrChannels& ch, const std::string& name);

// Pixel by pixel, over the pixels both have.
Image mul(const Image& a, const Image& b);
Image add(const Image& a, const Image& b);

// Relative L2 of all colour channels, a against reference b (of luminance: imageError, study_parts.h).
double relL2Rgb(const Image& a, const Image& b);

// A heat map of values in [0, 1]: black, red, yellow, white.
Image heat(const std::vector<float>& v);

struct Metrics {
    double lum = 0.0, rgb = 0.0, flip = 0.0;
};
// `test` against `ref` (w x h): relative L2 of luminance and colour, and the mean of LDR-FLIP with both pictures
// tone-mapped with `scale` (exposureOf the reference); flipMap: FLIP per pixel.
Metrics compare(const Image& test, const Image& ref, int w, int h, float scale, std::vector<float>* flipMap = nullptr);

// Mean luminance of the pixels `mask` marks.
double meanLum(const Image& im, const std::vector<char>& mask);

} // namespace sylva::study
