// LDR-FLIP (Andersson, Nilsson, Akenine-Moeller, Oskarsson, Astroem, Fairchild: "FLIP: A Difference
// Evaluator for Alternating Images", HPG 2020), written from the paper: a per-pixel perceptual difference
// in [0, 1] between two sRGB pictures seen at `pixelsPerDegree`.
#pragma once

#include <vector>

#include <glm/glm.hpp>

namespace sylva::study {

struct FlipResult {
    std::vector<float> map;   // per pixel, row-major, in [0, 1]
    double mean = 0.0;        // the paper's pooled value: the mean over the pixels
};

// The paper's default viewing: 0.7 m from a 0.7 m wide 4K monitor, 67 pixels per degree.
inline constexpr double kFlipPixelsPerDegree = 67.0;

// reference and test: sRGB-encoded colours in [0, 1] (clamped), width x height, row-major.
FlipResult flip(const std::vector<glm::vec3>& reference, const std::vector<glm::vec3>& test, int width, int height,
                double pixelsPerDegree = kFlipPixelsPerDegree);

// The colour pipeline's pieces (exposed for the tests): sRGB-encoded -> CIELAB (D65 white = linear
// RGB (1,1,1)), the Hunt adjustment (a, b scaled by L / 100), HyAB, and the remapping of HyAB^0.7 into
// [0, 1] by cmax = HyAB(green, blue)^0.7 (pc = 0.4, pt = 0.95).
glm::dvec3 srgbToLab(const glm::dvec3& srgb);
double flipColorError(const glm::dvec3& srgbA, const glm::dvec3& srgbB);

} // namespace sylva::study
