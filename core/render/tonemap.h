// Tone mapping: Rec. 709 luminance, the sRGB transfer function and global Reinhard, per pixel for every backend.
#pragma once

#include <cmath>
#include <cstddef>

#include <glm/glm.hpp>

#include "core/base/defines.h"

namespace sylva {

// Rec. 709 / sRGB relative luminance of a linear RGB colour.
SYLVA_HD inline float luminance(glm::vec3 linearRgb)
{
    return 0.2126f * linearRgb.x + 0.7152f * linearRgb.y + 0.0722f * linearRgb.z;
}

// sRGB OETF (IEC 61966-2-1), exact piecewise form. Input clamped to [0,1] (NaN -> 0); output in [0,1].
SYLVA_HD inline float srgbEncode(float linear)
{
    const float v = fminf(fmaxf(linear, 0.0f), 1.0f);
    const float e = v <= 0.0031308f ? 12.92f * v : 1.055f * powf(v, 1.0f / 2.4f) - 0.055f;
    return fminf(fmaxf(e, 0.0f), 1.0f);
}

// Inverse of srgbEncode. Input clamped to [0,1] (NaN -> 0); output in [0,1].
SYLVA_HD inline float srgbDecode(float encoded)
{
    const float e = fminf(fmaxf(encoded, 0.0f), 1.0f);
    const float v = e <= 0.04045f ? e / 12.92f : powf((e + 0.055f) / 1.055f, 2.4f);
    return fminf(fmaxf(v, 0.0f), 1.0f);
}

// Global Reinhard on luminance (Reinhard et al. 2002, eq. 3): L = luminance(rgb) * scale, Ld = L / (1 + L),
// colour scaled by Ld / luminance(rgb) so hue and saturation are kept. The output luminance is in [0, 1);
// a single saturated channel may still exceed 1 (srgbEncode clamps it). Black or negative-luminance
// pixels give 0, never NaN. scale is the exposure, key / log-average luminance, and must be >= 0.
SYLVA_HD inline glm::vec3 reinhard(glm::vec3 rgb, float scale)
{
    const float lin = luminance(rgb);
    if (!(lin > 0.0f)) return glm::vec3(0.0f);
    const float l = lin * scale;
    const float ld = l / (1.0f + l);
    return rgb * (ld / lin);
}

// The per-pixel rules of the tone-map reductions, shared by the host passes and the GPU kernels
// (cuda/render_cuda.cu) so both average the same terms over the same pixels.
inline constexpr double kLogDelta = 1e-4;   // Reinhard's delta: keeps log() finite on black pixels

// One pixel's term of the log-average luminance, log(delta + max(L, 0)) in double; false (the pixel is
// left out of the average) when its luminance is not finite.
SYLVA_HD inline bool logLuminanceTerm(const glm::vec3& linearRgb, double& term)
{
    const float l = luminance(linearRgb);
    if (!(fabsf(l) <= 3.402823466e38f)) return false;   // NaN or infinite
    term = log(kLogDelta + double(l > 0.0f ? l : 0.0f));
    return true;
}

// exp(mean term) over `count` pixels that counted; 0 when none did.
SYLVA_HD inline float logAverageOf(double termSum, double count) { return count > 0.0 ? float(exp(termSum / count)) : 0.0f; }

// The exposure scale for a key (finite, > 0) and a log-average: key / average, 0 for a black image.
SYLVA_HD inline float exposureScale(float key, float logAverage) { return logAverage > 0.0f ? key / logAverage : 0.0f; }

// Exposure setting of toneMapToSrgb: the key is the grey the log-average luminance is mapped to
// before the Reinhard curve (0.18 = "middle grey", Reinhard et al. 2002). 4 bytes.
struct ToneMapParams {
    float key = 0.18f;
};

// Log-average ("geometric mean") luminance of an image, exp(mean(log(delta + L))) with delta = 1e-4 and
// L = max(luminance, 0). rgb points at pixelCount pixels, the first 3 floats of each being linear RGB;
// consecutive pixels are strideFloats floats apart (3 for RGB, 4 for RGBA). Pixels with a non-finite
// luminance are left out; returns 0 when no pixel is left. Deterministic (fixed reduction order), parallel.
// Throws sylva::Error when strideFloats < 3 or rgb is null while pixelCount > 0.
float logAverageLuminance(const float* rgb, size_t pixelCount, size_t strideFloats);

// logAverageLuminance of an image fed in pieces, in pixel order (a frame rendered in bands): the sum
// runs over fixed chunks of pixels counted from the image's first pixel, so feeding the same pixels in
// any split gives exactly the same result as logAverageLuminance over the whole image.
class LogAverageAccumulator {
public:
    // Adds the next pixelCount pixels (layout as logAverageLuminance). Throws Error as it does.
    void add(const float* rgb, size_t pixelCount, size_t strideFloats);
    // The log-average of every pixel added so far (0 when none was finite).
    float value() const;

private:
    double m_total = 0.0;        // sum over the completed chunks, in chunk order
    size_t m_count = 0;          // finite pixels in the completed chunks
    double m_partial = 0.0;      // the chunk being filled
    size_t m_partialCount = 0, m_partialPixels = 0;
};

// Tone maps `pixels` linear RGB pixels (3 floats each) into outRgb01 (3 floats each, sRGB-encoded, in [0,1]):
// scale = key / logAverageLuminance(image), reinhard(rgb, scale), srgbEncode per channel. Parallel over
// pixels; in and out may be the same buffer. Throws sylva::Error when key is not finite and > 0, or a
// buffer is null while pixels > 0.
void toneMapToSrgb(const float* linearRgb, size_t pixels, float* outRgb01, ToneMapParams params = {});

// The two halves of toneMapToSrgb, for an image tone-mapped in pieces: the exposure scale from the
// image's log-average luminance (key / average, 0 for a black image; Error on a bad key), and the
// per-pixel Reinhard + sRGB pass with that scale.
float toneMapScale(float logAverage, ToneMapParams params = {});
void toneMapScaled(const float* linearRgb, size_t pixels, float* outRgb01, float scale);

} // namespace sylva
