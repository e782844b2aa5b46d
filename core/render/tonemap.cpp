// Whole-image tone mapping on the host: the log-average luminance and the Reinhard + sRGB pass.
#include "core/render/tonemap.h"

#include <string>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>

#include "core/base/error.h"

namespace sylva {

namespace {

constexpr double kLogDelta = 1e-4;      // Reinhard's delta: keeps log() finite on black pixels
constexpr size_t kGrain = 16384;        // pixels per task; fixed so the reduction order is too

struct LogSum {
    double sum = 0.0;
    size_t count = 0;
};

} // namespace

float logAverageLuminance(const float* rgb, size_t pixelCount, size_t strideFloats)
{
    if (strideFloats < 3)
        throw Error("logAverageLuminance: pixel stride " + std::to_string(strideFloats) + " floats is below 3 (RGB)");
    if (pixelCount == 0) return 0.0f;
    if (!rgb) throw Error("logAverageLuminance: null pixel buffer");
    const LogSum total = tbb::parallel_deterministic_reduce(
        tbb::blocked_range<size_t>(0, pixelCount, kGrain), LogSum{},
        [&](const tbb::blocked_range<size_t>& r, LogSum acc) {
            for (size_t i = r.begin(); i != r.end(); ++i) {
                const float* p = rgb + i * strideFloats;
                const float l = luminance(glm::vec3(p[0], p[1], p[2]));
                if (!std::isfinite(l)) continue;
                acc.sum += std::log(kLogDelta + double(l > 0.0f ? l : 0.0f));
                ++acc.count;
            }
            return acc;
        },
        [](LogSum a, const LogSum& b) {
            a.sum += b.sum;
            a.count += b.count;
            return a;
        });
    if (total.count == 0) return 0.0f;
    return float(std::exp(total.sum / double(total.count)));
}

void toneMapToSrgb(const float* linearRgb, size_t pixels, float* outRgb01, ToneMapParams params)
{
    if (!std::isfinite(params.key) || !(params.key > 0.0f))
        throw Error("tone map key " + std::to_string(params.key) + " must be finite and > 0");
    if (pixels == 0) return;
    if (!linearRgb || !outRgb01) throw Error("toneMapToSrgb: null pixel buffer");
    const float average = logAverageLuminance(linearRgb, pixels, 3);
    const float scale = average > 0.0f ? params.key / average : 0.0f;
    tbb::parallel_for(tbb::blocked_range<size_t>(0, pixels, kGrain), [&](const tbb::blocked_range<size_t>& r) {
        for (size_t i = r.begin(); i != r.end(); ++i) {
            const float* in = linearRgb + i * 3;
            const glm::vec3 mapped = reinhard(glm::vec3(in[0], in[1], in[2]), scale);
            float* out = outRgb01 + i * 3;
            out[0] = srgbEncode(mapped.x);
            out[1] = srgbEncode(mapped.y);
            out[2] = srgbEncode(mapped.z);
        }
    });
}

} // namespace sylva
