// Terrain benchmark: the height field's traversal (core/terrain) against Embree 3 on the same triangles as an
// explicit mesh, side by side in one run: build time, memory, camera and shadow rays per second, and the
// hits compared ray for ray.
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include <tbb/blocked_range.h>
#include <tbb/global_control.h>
#include <tbb/parallel_for.h>

#include "core/terrain/height_field.h"
#include "pipeline/io/dem_io.h"
#include "tests/bench/bench_timing.h"

#ifdef SYLVA_HAVE_EMBREE
#include <embree3/rtcore.h>
#endif

using namespace sylva;

namespace {

using bench::now;

struct Hit1 {
    float t;
    uint32_t prim;
};

// Camera rays of a pinhole over the terrain (terrain frame), row-major.
std::vector<Ray> cameraRays(glm::vec3 eye, glm::vec3 target, float fovDeg, int w, int h)
{
    const glm::vec3 f = glm::normalize(target - eye), r = glm::normalize(glm::cross(f, glm::vec3(0, 1, 0))), u = glm::cross(r, f);
    const float ty = std::tan(fovDeg * 0.5f * 3.14159265f / 180.0f), tx = ty * float(w) / float(h);
    std::vector<Ray> rays(size_t(w) * h);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            const float sx = (2.0f * (float(x) + 0.5f) / float(w) - 1.0f) * tx, sy = (1.0f - 2.0f * (float(y) + 0.5f) / float(h)) * ty;
            rays[size_t(y) * w + x] = Ray{eye, 0.0f, glm::normalize(f + sx * r + sy * u), INFINITY};
        }
    return rays;
}

void traceOurs(const HeightFieldView& v, const std::vector<Ray>& rays, std::vector<Hit1>& hits, bool anyHit)
{
    tbb::parallel_for(tbb::blocked_range<size_t>(0, rays.size(), 256), [&](const tbb::blocked_range<size_t>& r) {
        for (size_t i = r.begin(); i != r.end(); ++i) {
            float t = rays[i].tmax, u, w;
            uint32_t prim = kNoHit;
            const bool got = anyHit ? intersectHeightField<true>(v, rays[i], t, prim, u, w) : intersectHeightField<false>(v, rays[i], t, prim, u, w);
            hits[i] = Hit1{got ? t : INFINITY, got ? (anyHit ? 0u : prim) : kNoHit};
        }
    });
}

#ifdef SYLVA_HAVE_EMBREE
std::atomic<long long> g_embreeBytes{0};
bool embreeMemory(void*, ssize_t bytes, bool)
{
    g_embreeBytes.fetch_add(bytes, std::memory_order_relaxed);
    return true;
}

// The same triangles as an indexed mesh (shared vertices, the documented split), one Embree geometry.
struct EmbreeTerrain {
    RTCDevice device = nullptr;
    RTCScene scene = nullptr;
    double buildSeconds = 0.0;
    long long bytes = 0;

    EmbreeTerrain(const HeightField& h, int threads)
    {
        const std::string config = threads > 0 ? "threads=" + std::to_string(threads) : std::string();
        device = rtcNewDevice(config.empty() ? nullptr : config.c_str());
        if (!device) throw std::runtime_error("rtcNewDevice failed");
        rtcSetDeviceMemoryMonitorFunction(device, embreeMemory, nullptr);
        const long long before = g_embreeBytes.load();
        const double t0 = now();
        const uint32_t nx = h.layout.nx, nz = h.layout.nz;
        scene = rtcNewScene(device);
        RTCGeometry g = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
        float* vb = static_cast<float*>(rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float), size_t(nx) * nz));
        for (uint32_t j = 0; j < nz; ++j)
            for (uint32_t i = 0; i < nx; ++i) {
                float* p = vb + 3 * (size_t(j) * nx + i);
                p[0] = float(i) * h.layout.dx, p[1] = h.at(i, j), p[2] = float(j) * h.layout.dz;
            }
        const size_t tris = h.triangleCount();
        uint32_t* ib = static_cast<uint32_t*>(rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(uint32_t), tris));
        for (uint32_t j = 0; j + 1 < nz; ++j)
            for (uint32_t i = 0; i + 1 < nx; ++i) {
                const size_t c = size_t(j) * (nx - 1) + i;
                const uint32_t a = j * nx + i, b = a + 1, d = a + nx, e = d + 1;
                uint32_t* t = ib + 6 * c;
                t[0] = a, t[1] = e, t[2] = b;   // 2c: (p00, p11, p10)
                t[3] = a, t[4] = d, t[5] = e;   // 2c + 1: (p00, p01, p11)
            }
        rtcCommitGeometry(g);
        rtcAttachGeometry(scene, g);
        rtcReleaseGeometry(g);
        rtcCommitScene(scene);
        buildSeconds = now() - t0;
        bytes = g_embreeBytes.load() - before;
    }
    ~EmbreeTerrain()
    {
        if (scene) rtcReleaseScene(scene);
        if (device) rtcReleaseDevice(device);
    }

    void trace(const std::vector<Ray>& rays, std::vector<Hit1>& hits, bool anyHit) const
    {
        tbb::parallel_for(tbb::blocked_range<size_t>(0, rays.size(), 256), [&](const tbb::blocked_range<size_t>& r) {
            RTCIntersectContext ctx;
            rtcInitIntersectContext(&ctx);
            for (size_t i = r.begin(); i != r.end(); ++i) {
                const Ray& q = rays[i];
                RTCRayHit rh{};
                rh.ray.org_x = q.org.x, rh.ray.org_y = q.org.y, rh.ray.org_z = q.org.z;
                rh.ray.dir_x = q.dir.x, rh.ray.dir_y = q.dir.y, rh.ray.dir_z = q.dir.z;
                rh.ray.tnear = q.tmin, rh.ray.tfar = q.tmax, rh.ray.mask = 0xffffffffu;
                if (anyHit) {
                    rtcOccluded1(scene, &ctx, &rh.ray);
                    const bool got = rh.ray.tfar == -INFINITY;
                    hits[i] = Hit1{got ? 0.0f : INFINITY, got ? 0u : kNoHit};
                } else {
                    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
                    rtcIntersect1(scene, &ctx, &rh);
                    const bool got = rh.hit.geomID != RTC_INVALID_GEOMETRY_ID;
                    hits[i] = Hit1{got ? rh.ray.tfar : INFINITY, got ? rh.hit.primID : kNoHit};
                }
            }
        });
    }
};
#endif

// Rays toward the sun from just above each camera hit (0 for the misses: a short ray that hits nothing).
std::vector<Ray> shadowRays(const std::vector<Ray>& camera, const std::vector<Hit1>& hits, glm::vec3 sun, size_t* active)
{
    std::vector<Ray> rays;
    for (size_t i = 0; i < camera.size(); ++i) {
        if (hits[i].prim == kNoHit) continue;
        const glm::vec3 p = camera[i].org + hits[i].t * camera[i].dir;
        rays.push_back(Ray{p + glm::vec3(0.0f, 0.05f, 0.0f), 0.0f, sun, INFINITY});
    }
    *active = rays.size();
    return rays;
}

} // namespace

int main(int argc, char** argv)
{
    std::string dem = std::string(SYLVA_SOURCE_DIR) + "/resources/terrain/sthelens_10m.png";
    int reps = 5, threads = 0, width = 640, height = 480;
    double spacing = 10.0, scale = 0.1;
    for (int a = 1; a < argc; ++a) {
        const std::string s = argv[a];
        const bool more = a + 1 < argc;
        if (s == "--dem" && more) dem = argv[++a];
        else if (s == "--spacing" && more) spacing = std::atof(argv[++a]);
        else if (s == "--height-scale" && more) scale = std::atof(argv[++a]);
        else if (s == "--reps" && more) reps = std::max(1, std::atoi(argv[++a]));
        else if (s == "--threads" && more) threads = std::max(1, std::atoi(argv[++a]));
        else if (s == "--width" && more) width = std::max(8, std::atoi(argv[++a]));
        else if (s == "--height" && more) height = std::max(8, std::atoi(argv[++a]));
        else {
            std::printf("usage: bench_terrain [--dem PATH] [--spacing M] [--height-scale M] [--reps N] [--threads N] [--width W] [--height H]\n"
                        "  default: the bundled St Helens DEM (2000^2 samples, 10 m), 640x480, a panorama from the south-west corner\n");
            return s == "--help" ? 0 : 2;
        }
    }
    std::unique_ptr<tbb::global_control> limit;
    if (threads > 0) limit = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism, threads);
    const int threadsUsed = int(tbb::global_control::active_value(tbb::global_control::max_allowed_parallelism));

    const double t0 = now();
    const HeightField h = loadDem(dem, spacing, scale);
    const double loadSeconds = now() - t0;
    const double sizeX = double(h.layout.nx - 1) * spacing, sizeZ = double(h.layout.nz - 1) * spacing;
    const double t1 = now();
    const HeightField rebuilt = buildHeightField(h.heights, h.layout.nx, h.layout.nz, h.layout.dx, h.layout.dz);   // the pyramid alone
    const double pyramidSeconds = now() - t1;
    const HeightFieldView view = h.view();
    const glm::vec2 range = h.ranges.back();
    std::printf("terrain benchmark: %s, %u x %u samples (%.1f x %.1f km, %.0f M triangles), %dx%d, %d threads, %d reps (median)\n",
                dem.c_str(), h.layout.nx, h.layout.nz, sizeX / 1000.0, sizeZ / 1000.0, double(h.triangleCount()) / 1e6, width, height,
                threadsUsed, reps);
    std::printf("ours: DEM read + pyramid %.3f s (pyramid alone %.3f s), %.1f MB (heights + min/max pyramid)\n", loadSeconds, pyramidSeconds,
                double(h.bytes()) / 1e6);
    (void)rebuilt;

    // A panorama from above the south-west corner toward the far corner, the seed's kind of view.
    const glm::vec3 eye(float(sizeX * 0.02), range.y + 300.0f, float(sizeZ * 0.02));
    const glm::vec3 target(float(sizeX * 0.7), range.x, float(sizeZ * 0.8));
    const std::vector<Ray> cam = cameraRays(eye, target, 60.0f, width, height);
    std::vector<Hit1> ours(cam.size());
    const double ourPrimary = bench::timeReps(reps, [&] { traceOurs(view, cam, ours, false); }).median;
    size_t active = 0;
    const glm::vec3 sun = glm::normalize(glm::vec3(-0.6f, 0.45f, -0.4f));
    const std::vector<Ray> shadow = shadowRays(cam, ours, sun, &active);
    std::vector<Hit1> oursShadow(shadow.size());
    const double ourShadow = bench::timeReps(reps, [&] { traceOurs(view, shadow, oursShadow, true); }).median;
    size_t hitCount = 0, occluded = 0;
    for (const Hit1& x : ours) hitCount += x.prim != kNoHit;
    for (const Hit1& x : oursShadow) occluded += x.prim != kNoHit;
    const double ourPrimaryRate = double(cam.size()) / ourPrimary / 1e6, ourShadowRate = double(shadow.size()) / ourShadow / 1e6;
    std::printf("ours: primary %.3f Mrays/s (%zu of %zu hit), shadow %.3f Mrays/s (%zu of %zu occluded)\n", ourPrimaryRate, hitCount, cam.size(),
                ourShadowRate, occluded, shadow.size());

    double embreePrimaryRate = 0.0, embreeShadowRate = 0.0, embreeBuild = 0.0, embreeMB = 0.0;
    size_t primaryDiffer = 0, shadowDiffer = 0;
#ifdef SYLVA_HAVE_EMBREE
    {
        const EmbreeTerrain peer(h, threads);
        embreeBuild = peer.buildSeconds;
        embreeMB = double(peer.bytes) / 1e6;
        std::vector<Hit1> theirs(cam.size()), theirsShadow(shadow.size());
        const double p = bench::timeReps(reps, [&] { peer.trace(cam, theirs, false); }).median;
        const double s = bench::timeReps(reps, [&] { peer.trace(shadow, theirsShadow, true); }).median;
        embreePrimaryRate = double(cam.size()) / p / 1e6;
        embreeShadowRate = double(shadow.size()) / s / 1e6;
        for (size_t i = 0; i < cam.size(); ++i) {
            const bool a = ours[i].prim != kNoHit, b = theirs[i].prim != kNoHit;
            if (a != b || (a && std::fabs(ours[i].t - theirs[i].t) > 1e-4f * std::max(1.0f, theirs[i].t))) ++primaryDiffer;
        }
        for (size_t i = 0; i < shadow.size(); ++i) shadowDiffer += (oursShadow[i].prim != kNoHit) != (theirsShadow[i].prim != kNoHit);
        std::printf("embree 3: build %.3f s, %.1f MB; primary %.3f Mrays/s, shadow %.3f Mrays/s\n", embreeBuild, embreeMB, embreePrimaryRate,
                    embreeShadowRate);
        std::printf("hits: %zu of %zu primary rays differ (hit/miss or t beyond 1e-4 relative), %zu of %zu shadow rays\n", primaryDiffer,
                    cam.size(), shadowDiffer, shadow.size());
        std::printf("ours / embree: primary %.2fx, shadow %.2fx, memory %.3fx\n", ourPrimaryRate / embreePrimaryRate,
                    ourShadowRate / embreeShadowRate, double(h.bytes()) / 1e6 / embreeMB);
    }
#else
    std::printf("embree 3: not built in (libembree-dev not found at configure time)\n");
#endif
    std::printf("terrain_samples=%zu\nterrain_triangles=%zu\nours_mb=%.3f\nours_pyramid_s=%.4f\nours_primary_mrays=%.4f\nours_shadow_mrays=%.4f\n",
                h.heights.size(), h.triangleCount(), double(h.bytes()) / 1e6, pyramidSeconds, ourPrimaryRate, ourShadowRate);
    std::printf("embree_build_s=%.4f\nembree_mb=%.3f\nembree_primary_mrays=%.4f\nembree_shadow_mrays=%.4f\nprimary_differ=%zu\nshadow_differ=%zu\n", embreeBuild,
                embreeMB, embreePrimaryRate, embreeShadowRate, primaryDiffer, shadowDiffer);
    if (embreePrimaryRate > 0.0)
        std::printf("primary_ratio=%.4f\nshadow_ratio=%.4f\nmemory_ratio=%.4f\n", ourPrimaryRate / embreePrimaryRate, ourShadowRate / embreeShadowRate,
                    double(h.bytes()) / 1e6 / embreeMB);
    return 0;
}
