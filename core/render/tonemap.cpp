// Whole-image tone mapping on the host: the log-average luminance and the Reinhard + sRGB pass.
#include "core/render/tonemap.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "core/base/error.h"

namespace sylva {

namespace {

constexpr size_t kGrain = 16384;        // pixels per task; fixed so the reduction order is too

struct LogSum {
    double sum = 0.0;
    size_t count = 0;
};

} // namespace

float logAverageLuminance(const float* rgb, size_t pixelCount, size_t strideFloats)
{
    LogAverageAccumulator acc;
    acc.add(rgb, pixelCount, strideFloats);
    return acc.value();
}

void LogAverageAccumulator::add(const float* rgb, size_t pixelCount, size_t strideFloats)
{
    if (strideFloats < 3)
        throw Error("logAverageLuminance: pixel stride " + std::to_string(strideFloats) + " floats is below 3 (RGB)");
    if (pixelCount == 0) return;
    if (!rgb) throw Error("logAverageLuminance: null pixel buffer");
    // One running sum per chunk, continued across calls, so a split chunk adds in the same order.
    auto sumOf = [&](size_t begin, size_t end, LogSum acc) {
        for (size_t i = begin; i != end; ++i) {
            const float* p = rgb + i * strideFloats;
            double term;
            if (!logLuminanceTerm(glm::vec3(p[0], p[1], p[2]), term)) continue;
            acc.sum += term;
            ++acc.count;
        }
        return acc;
    };
    // 1. Finish the chunk an earlier call left open.
    size_t i = 0;
    if (m_partialPixels > 0) {
        const size_t take = std::min(pixelCount, kGrain - m_partialPixels);
        const LogSum head = sumOf(0, take, LogSum{m_partial, m_partialCount});
        m_partial = head.sum;
        m_partialCount = head.count;
        m_partialPixels += take;
        i = take;
        if (m_partialPixels == kGrain) {
            m_total += m_partial;
            m_count += m_partialCount;
            m_partial = 0.0;
            m_partialCount = m_partialPixels = 0;
        }
    }
    // 2. Whole chunks in parallel, added in chunk order.
    const size_t chunks = (pixelCount - i) / kGrain;
    if (chunks > 0) {
        std::vector<LogSum> sums(chunks);
        tbb::parallel_for(size_t(0), chunks, [&](size_t c) { sums[c] = sumOf(i + c * kGrain, i + (c + 1) * kGrain, LogSum{}); });
        for (const LogSum& s : sums) {
            m_total += s.sum;
            m_count += s.count;
        }
        i += chunks * kGrain;
    }
    // 3. The rest opens the next chunk.
    if (i < pixelCount) {
        const LogSum tail = sumOf(i, pixelCount, LogSum{});   // no chunk is open here
        m_partial = tail.sum;
        m_partialCount = tail.count;
        m_partialPixels += pixelCount - i;
    }
}

float LogAverageAccumulator::value() const
{
    return logAverageOf(m_total + m_partial, double(m_count + m_partialCount));
}

void toneMapToSrgb(const float* linearRgb, size_t pixels, float* outRgb01, ToneMapParams params)
{
    if (!std::isfinite(params.key) || !(params.key > 0.0f))
        throw Error("tone map key " + std::to_string(params.key) + " must be finite and > 0");
    if (pixels == 0) return;
    if (!linearRgb || !outRgb01) throw Error("toneMapToSrgb: null pixel buffer");
    toneMapScaled(linearRgb, pixels, outRgb01, toneMapScale(logAverageLuminance(linearRgb, pixels, 3), params));
}

float toneMapScale(float logAverage, ToneMapParams params)
{
    if (!std::isfinite(params.key) || !(params.key > 0.0f))
        throw Error("tone map key " + std::to_string(params.key) + " must be finite and > 0");
    return exposureScale(params.key, logAverage);
}

void toneMapScaled(const float* linearRgb, size_t pixels, float* outRgb01, float scale)
{
    if (pixels == 0) return;
    if (!linearRgb || !outRgb01) throw Error("toneMapToSrgb: null pixel buffer");
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
