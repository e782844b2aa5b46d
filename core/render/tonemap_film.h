// A film to the 8-bit picture the studio shows, written once over an executor (core/base/parallel.h):
// the studio's CPU viewport runs it with HostExec, the GPU viewport with CudaExec into a GL pixel buffer.
#pragma once

#include <cstddef>
#include <cstdint>

#include <glm/glm.hpp>

#include "core/base/defines.h"
#include "core/render/render_cpu.h"
#include "core/render/shade.h"
#include "core/render/tonemap.h"

namespace sylva {

// The sums of toneMapFilm, in the executor's memory: [0] sum lum(indirect) and [1] sum lum(albedo) (the
// ambient mode's constant), [2] and [3] the log-luminance terms and counted pixels of the left mode, [4]
// and [5] those of the right mode.
inline constexpr int kToneSums = 6;

namespace tone_detail {

struct AmbientTerms {
    const SampleParts* film;
    SYLVA_HD void operator()(size_t i, double* t) const
    {
        t[0] = double(luminance(film[i].indirect));
        t[1] = double(luminance(film[i].albedo));
    }
};

// The host's per-pixel rule of the log-average (logLuminanceTerm): non-finite pixels are left out.
struct LogTerms {
    const SampleParts* film;
    RenderMode mode;
    glm::vec3 sky;
    const double* acc;
    SYLVA_HD void operator()(size_t i, double* t) const
    {
        double term = 0.0;
        if (logLuminanceTerm(composeSample(film[i], mode, sky, ambientConstant(acc[0], acc[1])), term)) {
            t[0] = term;
            t[1] = 1.0;
        }
    }
};

struct MapPixel {
    const SampleParts* film;
    int width;
    RenderMode left, right;
    glm::vec3 sky;
    float key;
    const double* acc;
    uint32_t* out;
    SYLVA_HD void operator()(size_t i) const
    {
        const bool isRight = right != left && int(i % size_t(width)) >= width / 2;
        const float scale = exposureScale(key, logAverageOf(acc[isRight ? 4 : 2], acc[isRight ? 5 : 3]));
        const glm::vec3 c = reinhard(composeSample(film[i], isRight ? right : left, sky, ambientConstant(acc[0], acc[1])), scale);
        const uint32_t r = uint32_t(srgbEncode(c.x) * 255.0f + 0.5f), g = uint32_t(srgbEncode(c.y) * 255.0f + 0.5f),
                       b = uint32_t(srgbEncode(c.z) * 255.0f + 0.5f);
        out[i] = r | (g << 8) | (b << 16) | (255u << 24);
    }
};

} // namespace tone_detail

// Tone-maps a film (width x height parts, top row first, in the executor's memory) into RGBA8 pixels
// (bytes R, G, B, 255): composeSample in `left` mode, exposure key / log-average luminance of that mode's
// whole picture, Reinhard, sRGB, rounded to 8 bits. With right != left, columns [width/2, width) show the
// right mode, exposed as its own whole picture would be (the side-by-side compare). acc: kToneSums
// doubles of the executor's memory.
template <class Exec>
void toneMapFilm(const Exec& exec, const SampleParts* film, int width, int height, RenderMode left, RenderMode right,
                 const glm::vec3& sky, float key, double* acc, uint32_t* out)
{
    const size_t n = size_t(width) * size_t(height);
    const bool ambient = left == RenderMode::Ambient || right == RenderMode::Ambient;
    exec.template sum<2>(ambient ? n : 0, tone_detail::AmbientTerms{film}, acc);
    exec.template sum<2>(n, tone_detail::LogTerms{film, left, sky, acc}, acc + 2);
    exec.template sum<2>(right != left ? n : 0, tone_detail::LogTerms{film, right, sky, acc}, acc + 4);
    exec.forEach(n, tone_detail::MapPixel{film, width, left, right, sky, key, acc, out});
}

} // namespace sylva
