// CPU render loop: oneTBB over 8x8 tiles calling the shared per-pixel kernel; mode composition.
#include "core/render/render_cpu.h"

#include <atomic>

#include <tbb/parallel_for.h>

#include "core/render/tonemap.h"

namespace sylva {

Film renderFilm(const RenderView& v, Progress* progress)
{
    Film film;
    film.width = v.width;
    film.height = v.height;
    film.pixels.resize(size_t(v.width) * size_t(v.height));
    constexpr int kTile = 8;
    const int tilesX = (v.width + kTile - 1) / kTile, tilesY = (v.height + kTile - 1) / kTile;
    const int tiles = tilesX * tilesY;
    std::atomic<int> done{0};
    std::atomic<bool> cancelled{false};
    tbb::parallel_for(tbb::blocked_range<int>(0, tiles, 4), [&](const tbb::blocked_range<int>& r) {
        if (cancelled.load(std::memory_order_relaxed)) return;
        for (int tile = r.begin(); tile < r.end(); ++tile) {
            const int x0 = (tile % tilesX) * kTile, y0 = (tile / tilesX) * kTile;
            const int x1 = std::min(x0 + kTile, v.width), y1 = std::min(y0 + kTile, v.height);
            for (int y = y0; y < y1; ++y)
                for (int x = x0; x < x1; ++x) film.pixels[size_t(y) * size_t(v.width) + size_t(x)] = shadePixel(v, x, y);
        }
        const int d = done.fetch_add(int(r.size())) + int(r.size());
        if (progress && (d % std::max(1, tiles / 100) < int(r.size()) || d == tiles)) {
            try {
                progress->report(double(d) / double(tiles), "tracing");
            } catch (const Cancelled&) {
                cancelled.store(true);
            }
        }
    });
    if (cancelled.load() || (progress && progress->isCancelled())) throw Cancelled();
    return film;
}

std::vector<glm::vec3> composeMode(const Film& film, RenderMode mode, const glm::vec3& sky, float* ambientOut)
{
    const size_t n = film.pixels.size();
    std::vector<glm::vec3> out(n);
    float ambient = 0.0f;
    if (mode == RenderMode::Ambient) {
        // Mean luminance of full = mean of local + a * albedo  =>  a = mean(lum(indirect)) / mean(lum(albedo)).
        double ind = 0.0, alb = 0.0;
        for (const SampleParts& p : film.pixels) {
            ind += luminance(p.indirect);
            alb += luminance(p.albedo);
        }
        ambient = alb > 0.0 ? float(ind / alb) : 0.0f;
    }
    for (size_t i = 0; i < n; ++i) out[i] = composeSample(film.pixels[i], mode, sky, ambient);
    if (ambientOut) *ambientOut = ambient;
    return out;
}

} // namespace sylva
