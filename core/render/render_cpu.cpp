// CPU render loop: oneTBB over 8x8 tiles calling the shared per-pixel kernel; mode composition.
#include "core/render/render_cpu.h"

#include <algorithm>
#include <atomic>
#include <string>

#include <tbb/parallel_for.h>

#include "core/base/error.h"
#include "core/render/tonemap.h"
#include "core/render/trace_packet.h"

namespace sylva {

namespace {

// The loops' tiles: 8 x 8 pixels, one packet of camera rays.
constexpr int kTile = 8;
static_assert(kTile * kTile <= kPacketRays);

// The pixels [x0, x1) x [y0, y1) of the frame (at most kPacketRays) into out (row length `stride`): exactly
// shadePixel's parts for each. A landscape's tile traces each sample's camera rays as one packet, then for each
// of the first kPacketLights lights the shadow rays of the surfaces they found as another (trace_packet.h: the
// same answers as ray by ray); other scenes, where packets do not pay, and the path tracer shade pixel by pixel.
void shadeTile(const RenderView& v, int x0, int y0, int x1, int y1, SampleParts* out, size_t stride)
{
    const int w = x1 - x0, n = w * (y1 - y0);
    if (!v.landscape.enabled || tracesPaths(v)) {   // paths: no shadow-ray packets
        for (int y = y0; y < y1; ++y)
            for (int x = x0; x < x1; ++x) out[size_t(y - y0) * stride + size_t(x - x0)] = shadePixel(v, x, y);
        return;
    }
    SampleParts sum[kPacketRays];
    Ray cam[kPacketRays], shadow[kPacketRays];
    Hit hit[kPacketRays], shadowHit[kPacketRays];
    SurfacePoint surface[kPacketRays];
    bool found[kPacketRays], occluded[kPacketRays];
    int shadowOf[kPacketRays];
    int seen[kPacketRays][kPacketLights];
    const int packetLights = int(v.lightCount) < kPacketLights ? int(v.lightCount) : kPacketLights;
    const int sBegin = v.sampleBegin, sEnd = sampleEndOf(v);
    for (int i = 0; i < n; ++i) sum[i] = pixelSumStart();
    for (int s = sBegin; s < sEnd; ++s) {
        for (int i = 0; i < n; ++i) cam[i] = sampleRay(v, x0 + i % w, y0 + i / w, s);
        traceScenePacket<false>(v, cam, n, hit, found);
        for (int i = 0; i < n; ++i)
            if (found[i]) surface[i] = surfaceStage(v, cam[i], hit[i]);
        for (int l = 0; l < packetLights; ++l) {
            int shadows = 0;
            for (int i = 0; i < n; ++i) {
                shadowOf[i] = -1;
                if (found[i] && lightShadowRay(v, v.lights[l], surface[i], shadow[shadows])) shadowOf[i] = shadows++;
            }
            traceScenePacket<true>(v, shadow, shadows, shadowHit, occluded);
            for (int i = 0; i < n; ++i) seen[i][l] = shadowOf[i] < 0 ? 1 : (occluded[shadowOf[i]] ? 0 : 1);
        }
        for (int i = 0; i < n; ++i) pixelSumAdd(sum[i], shadeFound(v, cam[i], found[i], hit[i], surface[i], x0 + i % w, y0 + i / w, s, seen[i]));
    }
    for (int i = 0; i < n; ++i) {
        pixelSumAverage(sum[i], sEnd - sBegin);
        out[size_t(i / w) * stride + size_t(i % w)] = sum[i];
    }
}

} // namespace

Film renderFilm(const RenderView& v, Progress* progress) { return renderFilmRows(v, 0, v.height, progress); }

Film renderFilmRows(const RenderView& v, int y0Frame, int y1Frame, Progress* progress)
{
    if (y0Frame < 0 || y1Frame > v.height || y0Frame > y1Frame)
        throw Error("renderFilmRows: rows " + std::to_string(y0Frame) + " to " + std::to_string(y1Frame) + " are outside the " +
                    std::to_string(v.height) + "-row frame");
    Film film;
    film.width = v.width;
    film.height = y1Frame - y0Frame;
    film.pixels.resize(size_t(v.width) * size_t(film.height));
    const int tilesX = (v.width + kTile - 1) / kTile, tilesY = (film.height + kTile - 1) / kTile;
    const int tiles = tilesX * tilesY;
    std::atomic<int> done{0};
    std::atomic<bool> cancelled{false};
    tbb::parallel_for(tbb::blocked_range<int>(0, tiles, 4), [&](const tbb::blocked_range<int>& r) {
        if (cancelled.load(std::memory_order_relaxed)) return;
        for (int tile = r.begin(); tile < r.end(); ++tile) {
            const int x0 = (tile % tilesX) * kTile, y0 = (tile / tilesX) * kTile;
            const int x1 = std::min(x0 + kTile, v.width), y1 = std::min(y0 + kTile, film.height);
            shadeTile(v, x0, y0Frame + y0, x1, y0Frame + y1, &film.pixels[size_t(y0) * size_t(v.width) + size_t(x0)], size_t(v.width));
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

void renderFilmRect(const RenderView& v, int x0, int y0, int x1, int y1, SampleParts* out)
{
    if (x0 < 0 || y0 < 0 || x1 > v.width || y1 > v.height || x0 > x1 || y0 > y1)
        throw Error("renderFilmRect: the rectangle [" + std::to_string(x0) + ", " + std::to_string(x1) + ") x [" + std::to_string(y0) +
                    ", " + std::to_string(y1) + ") is outside the " + std::to_string(v.width) + "x" + std::to_string(v.height) + " frame");
    const int w = x1 - x0;
    const int tilesX = (w + kTile - 1) / kTile, tiles = tilesX * ((y1 - y0 + kTile - 1) / kTile);
    tbb::parallel_for(tbb::blocked_range<int>(0, tiles), [&](const tbb::blocked_range<int>& r) {
        for (int tile = r.begin(); tile < r.end(); ++tile) {
            const int tx = x0 + (tile % tilesX) * kTile, ty = y0 + (tile / tilesX) * kTile;
            shadeTile(v, tx, ty, std::min(tx + kTile, x1), std::min(ty + kTile, y1), out + size_t(ty - y0) * size_t(w) + size_t(tx - x0), size_t(w));
        }
    });
}

// Mean luminance of full = mean of local + a * albedo  =>  a = mean(lum(indirect)) / mean(lum(albedo)).
void accumulateFilm(Film& sum, int sumSamples, const Film& part, int partSamples)
{
    if (sumSamples <= 0 || sum.pixels.empty()) {
        sum = part;
        return;
    }
    if (sum.width != part.width || sum.height != part.height || sum.pixels.size() != part.pixels.size())
        throw Error("accumulateFilm: the films differ in size");
    const float a = float(sumSamples) / float(sumSamples + partSamples), b = 1.0f - a;
    for (size_t i = 0; i < sum.pixels.size(); ++i) {
        SampleParts& s = sum.pixels[i];
        const SampleParts& p = part.pixels[i];
        s.local = s.local * a + p.local * b;
        s.indirect = s.indirect * a + p.indirect * b;
        s.albedo = s.albedo * a + p.albedo * b;
        s.skyCover = s.skyCover * a + p.skyCover * b;
        s.normal = s.normal * a + p.normal * b;
        s.depth = std::min(s.depth, p.depth);
        s.background = s.background * a + p.background * b;
    }
}

void addAmbientSums(const Film& film, double* indirect, double* albedo)
{
    for (const SampleParts& p : film.pixels) {
        *indirect += luminance(p.indirect);
        *albedo += luminance(p.albedo);
    }
}

std::vector<glm::vec3> composeMode(const Film& film, RenderMode mode, const glm::vec3& sky, float* ambientOut)
{
    const size_t n = film.pixels.size();
    std::vector<glm::vec3> out(n);
    float ambient = 0.0f;
    if (mode == RenderMode::Ambient) {
        double ind = 0.0, alb = 0.0;
        addAmbientSums(film, &ind, &alb);
        ambient = ambientConstant(ind, alb);
    }
    for (size_t i = 0; i < n; ++i) out[i] = composeSample(film.pixels[i], mode, sky, ambient);
    if (ambientOut) *ambientOut = ambient;
    return out;
}

} // namespace sylva
