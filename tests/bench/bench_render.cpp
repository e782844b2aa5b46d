// Renderer benchmark on the default forest: full frame, primary and shadow ray throughput, side by side with Embree 3 on the same geometry.
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include <tbb/global_control.h>
#include <tbb/parallel_for.h>

#include "core/render/render_cpu.h"
#include "core/render/render_scene.h"
#include "core/render/shade.h"
#include "core/render/trace.h"
#include "pipeline/cache/grid_cache.h"
#include "pipeline/render/frame_build.h"
#include "pipeline/render/render_job.h"
#include "tests/bench/bench_timing.h"

#ifdef SYLVA_HAVE_EMBREE
#include "tests/bench/bench_embree.h"
#endif

using namespace sylva;

namespace {

using bench::now;
using bench::Timing;
using bench::timeReps;

// The renderer's schedule: oneTBB over 8x8 pixel tiles, 4 tiles per task. f(x0, y0, x1, y1).
constexpr int kTile = 8;

template <class F>
void forTiles(int width, int height, F&& f)
{
    const int tilesX = (width + kTile - 1) / kTile, tilesY = (height + kTile - 1) / kTile;
    tbb::parallel_for(tbb::blocked_range<int>(0, tilesX * tilesY, 4), [&](const tbb::blocked_range<int>& r) {
        for (int tile = r.begin(); tile < r.end(); ++tile) {
            const int x0 = (tile % tilesX) * kTile, y0 = (tile / tilesX) * kTile;
            f(x0, y0, std::min(x0 + kTile, width), std::min(y0 + kTile, height));
        }
    });
}

// What a primary ray saw, for comparing tracers: instance index (kGroundPrim = ground, kNoHit = sky) and t. 8 bytes.
constexpr uint32_t kGroundPrim = 0xfffffffeu;
struct PrimaryResult {
    uint32_t inst;
    float t;
};

// The shadow ray shadeRay casts for a hit (offset off the face-forwarded normal, toward the sun).
// Returns false where shadeRay casts none (sky, surface facing away from the sun, shadows off).
bool shadowRayFor(const RenderView& v, const Ray& ray, const Hit& hit, Ray& out)
{
    if (!v.shadows || hitKind(hit) == SurfaceKind::None) return false;
    const glm::vec3 p = ray.org + hit.t * ray.dir;
    glm::vec3 ng;
    if (hitKind(hit) == SurfaceKind::Ground) {
        ng = glm::vec3(0.0f, ray.dir.y < 0.0f ? 1.0f : -1.0f, 0.0f);
    } else {
        const InstanceRecord& in = v.instances[hit.inst];
        const glm::uvec3 tv = v.triVerts[hit.prim];
        const float b0 = 1.0f - hit.u - hit.v;
        const glm::vec3 ns = b0 * v.normals[tv.x] + hit.u * v.normals[tv.y] + hit.v * v.normals[tv.z];
        ng = glm::normalize(toWorldNormal(in, ns));
        if (!(glm::dot(ng, ng) > 0.5f)) ng = glm::vec3(0.0f, 1.0f, 0.0f);
        if (glm::dot(ng, -ray.dir) < 0.0f) ng = -ng;
    }
    if (!(glm::dot(ng, lbLight(v).direction) > 0.0f)) return false;
    out = Ray{offsetPoint(p, ng), 0.0f, lbLight(v).direction, 1e30f};
    return true;
}

Ray pixelRay(const RenderView& v, int x, int y) { return cameraRay(v, float(x) + 0.5f, float(y) + 0.5f); }

// Primary results that differ: other instance (or sky / ground), or t off by more than 1e-3 relative.
[[maybe_unused]] size_t primaryMismatches(const std::vector<PrimaryResult>& a, const std::vector<PrimaryResult>& b)
{
    size_t n = 0;
    for (size_t i = 0; i < a.size(); ++i) {
        if (a[i].inst != b[i].inst) ++n;
        else if (a[i].inst != kNoHit && std::fabs(a[i].t - b[i].t) > 1e-3f * std::max(a[i].t, b[i].t)) ++n;
    }
    return n;
}

[[maybe_unused]] size_t shadowMismatches(const std::vector<uint8_t>& a, const std::vector<uint8_t>& b)
{
    size_t n = 0;
    for (size_t i = 0; i < a.size(); ++i) n += a[i] != b[i];
    return n;
}

double mrays(size_t rays, double seconds) { return double(rays) / seconds / 1e6; }

#ifdef SYLVA_HAVE_EMBREE

using bench::embreeAlphaFilter;
using bench::embreeError;
using bench::embreeMemoryMonitor;
using bench::EmbreeGeomData;
using bench::g_embreeBytes;

// The same instanced geometry in Embree: per species an opaque and an alpha-tested triangle geometry
// (unshared vertices v0, v0 + e1, v0 + e2 from the TriAccels), per instance an instance of its species'
// scene with local -> world = the inverse of the InstanceRecord (computed in double), camera-relative.
struct EmbreePeer {
    RTCDevice device = nullptr;
    RTCScene top = nullptr;
    std::vector<RTCScene> species;
    std::vector<std::unique_ptr<EmbreeGeomData>> geomData;
    double speciesBuildSeconds = 0.0, topBuildSeconds = 0.0;
    long long speciesBytes = 0, topBytes = 0;

    EmbreePeer(const RenderScene& rs, const RenderView& v, int threads, RTCBuildQuality quality)
    {
        std::string config = threads > 0 ? "threads=" + std::to_string(threads) : std::string();
        if (const char* extra = std::getenv("EMBREE_CONFIG")) config += (config.empty() ? "" : ",") + std::string(extra);
        device = rtcNewDevice(config.empty() ? nullptr : config.c_str());
        if (!device) throw std::runtime_error("rtcNewDevice failed");
        rtcSetDeviceErrorFunction(device, embreeError, nullptr);
        rtcSetDeviceMemoryMonitorFunction(device, embreeMemoryMonitor, nullptr);
        const long long base = g_embreeBytes.load();

        double t0 = now();
        species = bench::embreeSpeciesScenes(device, rs, v, quality, geomData);   // the forest's geometries are meshes only
        speciesBuildSeconds = now() - t0;
        speciesBytes = g_embreeBytes.load() - base;

        t0 = now();
        top = rtcNewScene(device);
        rtcSetSceneFlags(top, RTC_SCENE_FLAG_NONE);
        rtcSetSceneBuildQuality(top, quality);
        for (size_t i = 0; i < rs.instances.size(); ++i) {
            const InstanceRecord& in = rs.instances[i];
            float xfm[12];
            bench::embreeInstanceTransform(in, xfm);
            RTCGeometry geom = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_INSTANCE);
            rtcSetGeometryInstancedScene(geom, species[in.geometry]);
            rtcSetGeometryTimeStepCount(geom, 1);
            rtcSetGeometryTransform(geom, 0, RTC_FORMAT_FLOAT3X4_COLUMN_MAJOR, xfm);
            rtcCommitGeometry(geom);
            rtcAttachGeometryByID(top, geom, unsigned(i));
            rtcReleaseGeometry(geom);
        }
        rtcCommitScene(top);
        topBuildSeconds = now() - t0;
        topBytes = g_embreeBytes.load() - base - speciesBytes;
    }

    ~EmbreePeer()
    {
        if (top) rtcReleaseScene(top);
        for (RTCScene s : species) rtcReleaseScene(s);
        if (device) rtcReleaseDevice(device);
    }
};

// One ray in Embree's layout (every mode fills its rays through this).
SYLVA_INLINE void embreeRayFrom(RTCRay& r, const Ray& ray, float tfar, unsigned id)
{
    r.org_x = ray.org.x;
    r.org_y = ray.org.y;
    r.org_z = ray.org.z;
    r.tnear = ray.tmin;
    r.dir_x = ray.dir.x;
    r.dir_y = ray.dir.y;
    r.dir_z = ray.dir.z;
    r.time = 0.0f;
    r.tfar = tfar;
    r.mask = 0xffffffffu;
    r.id = id;
    r.flags = 0;
}

// Closest hit of one ray, the ground tested analytically outside Embree exactly as traceBvh does.
SYLVA_INLINE PrimaryResult embreePrimary1(RTCScene scene, const RenderView& v, const Ray& ray)
{
    PrimaryResult res{kNoHit, 0.0f};
    float tmax = ray.tmax;
    if (v.ground.enabled && ray.dir.y != 0.0f) {
        const float tg = (v.ground.y - ray.org.y) / ray.dir.y;
        if (tg > ray.tmin && tg < tmax) {
            tmax = tg;
            res = {kGroundPrim, tg};
        }
    }
    RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    RTCRayHit rh;
    embreeRayFrom(rh.ray, ray, tmax, 0);
    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
    rtcIntersect1(scene, &ctx, &rh);
    if (rh.hit.geomID != RTC_INVALID_GEOMETRY_ID) res = {rh.hit.instID[0], rh.ray.tfar};
    return res;
}

SYLVA_INLINE bool embreeOccluded1(RTCScene scene, const RenderView& v, const Ray& ray)
{
    if (v.ground.enabled && ray.dir.y != 0.0f) {
        const float tg = (v.ground.y - ray.org.y) / ray.dir.y;
        if (tg > ray.tmin && tg < ray.tmax) return true;
    }
    RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    RTCRay r;
    embreeRayFrom(r, ray, ray.tmax, 0);
    rtcOccluded1(scene, &ctx, &r);
    return r.tfar < 0.0f;
}

// Up to 8 rays of a tile row as one packet (lanes past `count` or with active[k] false are off).
void embreePrimary8(RTCScene scene, const RenderView& v, const Ray* rays, int count, PrimaryResult* out)
{
    alignas(32) int valid[8];
    alignas(32) RTCRayHit8 rh;
    PrimaryResult ground[8];
    for (int k = 0; k < 8; ++k) {
        valid[k] = k < count ? -1 : 0;
        const Ray& ray = rays[k < count ? k : 0];
        float tmax = ray.tmax;
        ground[k] = {kNoHit, 0.0f};
        if (v.ground.enabled && ray.dir.y != 0.0f) {
            const float tg = (v.ground.y - ray.org.y) / ray.dir.y;
            if (tg > ray.tmin && tg < tmax) {
                tmax = tg;
                ground[k] = {kGroundPrim, tg};
            }
        }
        rh.ray.org_x[k] = ray.org.x;
        rh.ray.org_y[k] = ray.org.y;
        rh.ray.org_z[k] = ray.org.z;
        rh.ray.tnear[k] = ray.tmin;
        rh.ray.dir_x[k] = ray.dir.x;
        rh.ray.dir_y[k] = ray.dir.y;
        rh.ray.dir_z[k] = ray.dir.z;
        rh.ray.time[k] = 0.0f;
        rh.ray.tfar[k] = tmax;
        rh.ray.mask[k] = 0xffffffffu;
        rh.ray.id[k] = unsigned(k);
        rh.ray.flags[k] = 0;
        rh.hit.geomID[k] = RTC_INVALID_GEOMETRY_ID;
        rh.hit.instID[0][k] = RTC_INVALID_GEOMETRY_ID;
    }
    RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    ctx.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
    rtcIntersect8(valid, scene, &ctx, &rh);
    for (int k = 0; k < count; ++k)
        out[k] = rh.hit.geomID[k] != RTC_INVALID_GEOMETRY_ID ? PrimaryResult{rh.hit.instID[0][k], rh.ray.tfar[k]} : ground[k];
}

void embreeOccluded8(RTCScene scene, const RenderView& v, const Ray* rays, const uint8_t* active, int count, uint8_t* out)
{
    alignas(32) int valid[8];
    alignas(32) RTCRay8 r;
    bool any = false;
    for (int k = 0; k < 8; ++k) {
        valid[k] = 0;
        if (k >= count || !active[k]) continue;
        const Ray& ray = rays[k];
        out[k] = 0;
        if (v.ground.enabled && ray.dir.y != 0.0f) {
            const float tg = (v.ground.y - ray.org.y) / ray.dir.y;
            if (tg > ray.tmin && tg < ray.tmax) {
                out[k] = 1;
                continue;
            }
        }
        valid[k] = -1;
        any = true;
        r.org_x[k] = ray.org.x;
        r.org_y[k] = ray.org.y;
        r.org_z[k] = ray.org.z;
        r.tnear[k] = ray.tmin;
        r.dir_x[k] = ray.dir.x;
        r.dir_y[k] = ray.dir.y;
        r.dir_z[k] = ray.dir.z;
        r.time[k] = 0.0f;
        r.tfar[k] = ray.tmax;
        r.mask[k] = 0xffffffffu;
        r.id[k] = unsigned(k);
        r.flags[k] = 0;
    }
    if (!any) return;
    RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    rtcOccluded8(valid, scene, &ctx, &r);
    for (int k = 0; k < count; ++k)
        if (valid[k] == -1) out[k] = r.tfar[k] < 0.0f ? 1 : 0;
}

// Embree's stream mode: the rays of one 8x8 tile as one rtcIntersect1M / rtcOccluded1M call with the coherent flag
// (Embree regroups a stream into packets itself). Ground plane outside Embree as in the other modes.
constexpr int kStreamMax = kTile * kTile;

// Camera rays of the tile [x0, x1) x [y0, y1) (at most kStreamMax pixels) into `image` (row length W).
void embreePrimaryStream(RTCScene scene, const RenderView& v, int W, int x0, int y0, int x1, int y1, PrimaryResult* image)
{
    RTCRayHit rh[kStreamMax];
    PrimaryResult* dst[kStreamMax];
    unsigned n = 0;
    for (int y = y0; y < y1; ++y)
        for (int x = x0; x < x1; ++x, ++n) {
            const Ray ray = pixelRay(v, x, y);
            PrimaryResult& out = image[size_t(y) * size_t(W) + size_t(x)];
            out = {kNoHit, 0.0f};
            float tmax = ray.tmax;
            if (v.ground.enabled && ray.dir.y != 0.0f) {
                const float tg = (v.ground.y - ray.org.y) / ray.dir.y;
                if (tg > ray.tmin && tg < tmax) {
                    tmax = tg;
                    out = {kGroundPrim, tg};
                }
            }
            embreeRayFrom(rh[n].ray, ray, tmax, n);
            rh[n].hit.geomID = RTC_INVALID_GEOMETRY_ID;
            rh[n].hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
            dst[n] = &out;
        }
    RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    ctx.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
    rtcIntersect1M(scene, &ctx, rh, n, sizeof(RTCRayHit));
    for (unsigned k = 0; k < n; ++k)
        if (rh[k].hit.geomID != RTC_INVALID_GEOMETRY_ID) *dst[k] = {rh[k].hit.instID[0], rh[k].ray.tfar};
}

// The active shadow rays of the same tile (those not already stopped by the ground) as one stream.
void embreeOccludedStream(RTCScene scene, const RenderView& v, int W, int x0, int y0, int x1, int y1, const Ray* rays,
                          const uint8_t* active, uint8_t* occluded)
{
    RTCRay r[kStreamMax];
    size_t index[kStreamMax];
    unsigned n = 0;
    for (int y = y0; y < y1; ++y)
        for (int x = x0; x < x1; ++x) {
            const size_t i = size_t(y) * size_t(W) + size_t(x);
            if (!active[i]) continue;
            const Ray& ray = rays[i];
            occluded[i] = 0;
            if (v.ground.enabled && ray.dir.y != 0.0f) {
                const float tg = (v.ground.y - ray.org.y) / ray.dir.y;
                if (tg > ray.tmin && tg < ray.tmax) {
                    occluded[i] = 1;
                    continue;
                }
            }
            embreeRayFrom(r[n], ray, ray.tmax, n);
            index[n++] = i;
        }
    if (n == 0) return;
    RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    ctx.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
    rtcOccluded1M(scene, &ctx, r, n, sizeof(RTCRay));
    for (unsigned k = 0; k < n; ++k) occluded[index[k]] = r[k].tfar < 0.0f ? 1 : 0;
}

#endif // SYLVA_HAVE_EMBREE

int usage(int rc)
{
    std::printf("usage: bench_render [--reps N] [--threads N] [--width W] [--height H] [--accel bvh|kdtree]\n"
                "                    [--no-embree] [--embree-quality medium|high]\n"
                "EMBREE_CONFIG (environment) is appended to Embree's device configuration, e.g.\n"
                "EMBREE_CONFIG=tri_accel=bvh4.triangle4v for its 4-wide BVH instead of the 8-wide default on AVX2.\n");
    return rc;
}

} // namespace

int main(int argc, char** argv)
{
    int reps = 5, threads = 0, width = 0, height = 0;
    AccelKind accel = AccelKind::Bvh;
    bool useEmbree = true, highQuality = true;
    for (int a = 1; a < argc; ++a) {
        const std::string s = argv[a];
        const bool more = a + 1 < argc;
        if (s == "--reps" && more) reps = std::max(1, std::atoi(argv[++a]));
        else if (s == "--threads" && more) threads = std::max(1, std::atoi(argv[++a]));
        else if (s == "--width" && more) width = std::max(1, std::atoi(argv[++a]));
        else if (s == "--height" && more) height = std::max(1, std::atoi(argv[++a]));
        else if (s == "--accel" && more) {
            if (!parseAccel(argv[++a], &accel)) return usage(2);
        } else if (s == "--no-embree") useEmbree = false;
        else if (s == "--embree-quality" && more) {
            const std::string q = argv[++a];
            if (q != "medium" && q != "high") return usage(2);
            highQuality = q == "high";
        } else return usage(s == "--help" ? 0 : 2);
    }
    std::unique_ptr<tbb::global_control> limit;
    if (threads > 0) limit = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism, threads);
    const int threadsUsed = int(tbb::global_control::active_value(tbb::global_control::max_allowed_parallelism));

    // The default forest, its assets through the grid cache (reruns load the lighting grids from disk).
    Scene scene = defaultScene();
    if (width > 0) scene.render.width = width;
    if (height > 0) scene.render.height = height;
    scene.render.accel = accel;
    GridCache cache;
    double t0 = now();
    const std::vector<SpeciesAssets> assets = loadSpeciesAssets(scene, &cache, true);
    const double assetSeconds = now() - t0;
    t0 = now();
    const RenderScene rs = buildRenderScene(scene, assets, sunRadiance(scene.sun));
    const double buildSeconds = now() - t0;
    RenderView v = rs.view();
    const int W = v.width, H = v.height;
    const size_t pixels = size_t(W) * size_t(H);
    const AccelStats& st = rs.stats();
    const double ourBytes = double(st.tlasBytes + st.instanceBytes + st.blasBytes + st.triangleBytes + st.wideTlasBytes +
                                   st.wideBlasBytes);
    // What the host's traversal reads: the 8-wide copies instead of the 4-wide nodes (the GPU's).
    const double hostBytes = st.wideBlasBytes > 0 ? ourBytes - double(st.blasBytes + rs.tlasNodes.size() * sizeof(BvhNode)) : ourBytes;
    std::printf("render benchmark: default forest, %dx%d, %d spp, shadows %s, accel %s, %d threads, %d reps (median / min)\n",
                W, H, v.spp, v.shadows ? "on" : "off", accelName(v.accel), threadsUsed, reps);
    size_t alphaTris = 0;
    for (const TriAccel& t : rs.tris) alphaTris += t.alpha != 0u;
    std::printf("scene: %zu species, %zu instances, %zu species triangles (%.1f%% alpha-tested), %.0f instanced triangles; "
                "assets %.2f s (cache %s)\n",
                rs.species.size(), st.instances, st.speciesTriangles, 100.0 * double(alphaTris) / double(rs.tris.size()),
                st.instancedTriangles, assetSeconds, cache.dir().c_str());

    // (a) the full frame, as `sylva render` traces it.
    const Timing frame = timeReps(reps, [&] { (void)renderFilm(v); });
    std::printf("\n%-40s %10.4f s  %10.4f s   (target 0.25 s on 2 cores)\n", "full frame (renderFilm)", frame.median, frame.min);

    // Our primary hits (an untimed pass that also warms the caches) and the shadow rays shadeRay would cast from them.
    // A pass of our camera rays through `view` (hits kept when asked), and of the shadow rays below.
    auto primaryPass = [&](const RenderView& view, std::vector<PrimaryResult>& out, std::vector<Hit>* hitsOut) {
        forTiles(W, H, [&](int x0, int y0, int x1, int y1) {
            for (int y = y0; y < y1; ++y)
                for (int x = x0; x < x1; ++x) {
                    const size_t i = size_t(y) * size_t(W) + size_t(x);
                    Hit h{};
                    traceScene<false>(view, pixelRay(view, x, y), h);
                    if (hitsOut) (*hitsOut)[i] = h;
                    out[i] = {hitKind(h) == SurfaceKind::Ground ? kGroundPrim : (hitKind(h) == SurfaceKind::None ? kNoHit : h.inst), h.t};
                }
        });
    };
    std::vector<Hit> hits(pixels);
    std::vector<PrimaryResult> ours(pixels);
    auto oursPrimaryPass = [&] { primaryPass(v, ours, &hits); };
    oursPrimaryPass();
    std::vector<Ray> shadowRays(pixels);
    std::vector<uint8_t> shadowActive(pixels, 0), oursOccluded(pixels, 0);
    size_t shadowCount = 0, skyCount = 0, groundCount = 0;
    for (int y = 0; y < H; ++y)
        for (int x = 0; x < W; ++x) {
            const size_t i = size_t(y) * size_t(W) + size_t(x);
            shadowActive[i] = shadowRayFor(v, pixelRay(v, x, y), hits[i], shadowRays[i]) ? 1 : 0;
            shadowCount += shadowActive[i];
            skyCount += ours[i].inst == kNoHit;
            groundCount += ours[i].inst == kGroundPrim;
        }
    auto shadowPass = [&](const RenderView& view, std::vector<uint8_t>& occluded) {
        forTiles(W, H, [&](int x0, int y0, int x1, int y1) {
            for (int y = y0; y < y1; ++y)
                for (int x = x0; x < x1; ++x) {
                    const size_t i = size_t(y) * size_t(W) + size_t(x);
                    if (!shadowActive[i]) continue;
                    Hit h{};
                    occluded[i] = traceScene<true>(view, shadowRays[i], h) ? 1 : 0;
                }
        });
    };
    auto oursShadowPass = [&] { shadowPass(v, oursOccluded); };

    // The passes to time: (b) primary and (c) shadow rays, ours and (d) Embree's, interleaved rep by rep so
    // that load from other processes on a shared machine falls on every pass alike.
    struct Pass {
        std::string name;
        std::function<void()> run;
        size_t rays;
        Timing timing;
    };
    std::vector<Pass> passes;
    passes.push_back({"ours primary (traceScene<false>)", oursPrimaryPass, pixels, {}});
    passes.push_back({"ours shadow (traceScene<true>)", oursShadowPass, shadowCount, {}});

    double emBuild = 0.0, emTopBuild = 0.0;
    long long emBytes = 0, emTopBytes = 0;
    bool ranEmbree = false;
#ifdef SYLVA_HAVE_EMBREE
    std::unique_ptr<EmbreePeer> peer;
    std::vector<PrimaryResult> em(pixels), em8(pixels), emStream(pixels);
    std::vector<uint8_t> emOcc(pixels, 0), em8Occ(pixels, 0), emStreamOcc(pixels, 0);
    if (useEmbree) {
        peer = std::make_unique<EmbreePeer>(rs, v, threads, highQuality ? RTC_BUILD_QUALITY_HIGH : RTC_BUILD_QUALITY_MEDIUM);
        emBuild = peer->speciesBuildSeconds;
        emTopBuild = peer->topBuildSeconds;
        emBytes = peer->speciesBytes + peer->topBytes;
        emTopBytes = peer->topBytes;
        ranEmbree = true;
        const RTCScene es = peer->top;
        passes.push_back({"embree primary (rtcIntersect1)", [&, es] {
                              forTiles(W, H, [&](int x0, int y0, int x1, int y1) {
                                  for (int y = y0; y < y1; ++y)
                                      for (int x = x0; x < x1; ++x)
                                          em[size_t(y) * size_t(W) + size_t(x)] = embreePrimary1(es, v, pixelRay(v, x, y));
                              });
                          },
                          pixels, {}});
        passes.push_back({"embree shadow (rtcOccluded1)", [&, es] {
                              forTiles(W, H, [&](int x0, int y0, int x1, int y1) {
                                  for (int y = y0; y < y1; ++y)
                                      for (int x = x0; x < x1; ++x) {
                                          const size_t i = size_t(y) * size_t(W) + size_t(x);
                                          if (shadowActive[i]) emOcc[i] = embreeOccluded1(es, v, shadowRays[i]) ? 1 : 0;
                                      }
                              });
                          },
                          shadowCount, {}});
        passes.push_back({"embree primary (rtcIntersect8, 8x1)", [&, es] {
                              forTiles(W, H, [&](int x0, int y0, int x1, int y1) {
                                  Ray rays[8];
                                  for (int y = y0; y < y1; ++y)
                                      for (int x = x0; x < x1; x += 8) {
                                          const int n = std::min(8, x1 - x);
                                          for (int k = 0; k < n; ++k) rays[k] = pixelRay(v, x + k, y);
                                          embreePrimary8(es, v, rays, n, &em8[size_t(y) * size_t(W) + size_t(x)]);
                                      }
                              });
                          },
                          pixels, {}});
        passes.push_back({"embree shadow (rtcOccluded8, 8x1)", [&, es] {
                              forTiles(W, H, [&](int x0, int y0, int x1, int y1) {
                                  for (int y = y0; y < y1; ++y)
                                      for (int x = x0; x < x1; x += 8) {
                                          const size_t i = size_t(y) * size_t(W) + size_t(x);
                                          embreeOccluded8(es, v, &shadowRays[i], &shadowActive[i], std::min(8, x1 - x), &em8Occ[i]);
                                      }
                              });
                          },
                          shadowCount, {}});
        passes.push_back({"embree primary (rtcIntersect1M, 8x8)", [&, es] {
                              forTiles(W, H, [&](int x0, int y0, int x1, int y1) {
                                  embreePrimaryStream(es, v, W, x0, y0, x1, y1, emStream.data());
                              });
                          },
                          pixels, {}});
        passes.push_back({"embree shadow (rtcOccluded1M, 8x8)", [&, es] {
                              forTiles(W, H, [&](int x0, int y0, int x1, int y1) {
                                  embreeOccludedStream(es, v, W, x0, y0, x1, y1, shadowRays.data(), shadowActive.data(),
                                                       emStreamOcc.data());
                              });
                          },
                          shadowCount, {}});
        passes[2].run();   // warm Embree's structures as ours were warmed
        passes[3].run();
    }
#else
    (void)highQuality;
#endif

    // The same rays through the 4-wide BVHs (what the GPU traverses), for the 8-wide ones' gain.
    RenderView v4 = v;
    v4.blasWideNodes = nullptr;
    v4.tlasWideNodes = nullptr;
    const size_t narrowPass = passes.size();
    std::vector<PrimaryResult> oursNarrow(pixels);
    std::vector<uint8_t> oursNarrowOcc(pixels, 0);
    if (v.blasWideNodes) {
        passes.push_back({"ours primary, 4-wide BVHs", [&] { primaryPass(v4, oursNarrow, nullptr); }, pixels, {}});
        passes.push_back({"ours shadow, 4-wide BVHs", [&] { shadowPass(v4, oursNarrowOcc); }, shadowCount, {}});
    }

    std::vector<std::vector<double>> seconds(passes.size());
    for (int r = 0; r < reps; ++r)
        for (size_t p = 0; p < passes.size(); ++p) {
            const double s0 = now();
            passes[p].run();
            seconds[p].push_back(now() - s0);
        }
    for (size_t p = 0; p < passes.size(); ++p) {
        std::sort(seconds[p].begin(), seconds[p].end());
        passes[p].timing = {seconds[p][seconds[p].size() / 2], seconds[p].front()};
    }

    size_t occluded = 0;
    for (uint8_t o : oursOccluded) occluded += o;
    std::printf("primary rays: %zu (%.1f%% sky, %.1f%% ground); shadow rays: %zu (%.1f%% occluded)\n", pixels,
                100.0 * double(skyCount) / double(pixels), 100.0 * double(groundCount) / double(pixels), shadowCount,
                100.0 * double(occluded) / double(std::max<size_t>(1, shadowCount)));
    std::printf("\n%-40s %12s %12s\n", "rays (Mrays/s), passes interleaved", "median", "best");
    for (const Pass& p : passes)
        std::printf("%-40s %12.2f %12.2f\n", p.name.c_str(), mrays(p.rays, p.timing.median), mrays(p.rays, p.timing.min));
    const double ourPrimary = mrays(pixels, passes[0].timing.median), ourShadow = mrays(shadowCount, passes[1].timing.median);
    double narrowPrimary = 0.0, narrowShadow = 0.0;
    if (v.blasWideNodes) {
        narrowPrimary = mrays(pixels, passes[narrowPass].timing.median);
        narrowShadow = mrays(shadowCount, passes[narrowPass + 1].timing.median);
        std::printf("%-40s %12.2f %12.2f\n", "ratio 8-wide / 4-wide primary", ourPrimary / narrowPrimary,
                    passes[narrowPass].timing.min / passes[0].timing.min);
        std::printf("%-40s %12.2f %12.2f\n", "ratio 8-wide / 4-wide shadow", ourShadow / narrowShadow,
                    passes[narrowPass + 1].timing.min / passes[1].timing.min);
        std::printf("4-wide vs 8-wide: %zu primary hits differ (instance, or t > 1e-3 relative), %zu shadow rays differ\n",
                    primaryMismatches(ours, oursNarrow), shadowMismatches(oursOccluded, oursNarrowOcc));
    }

    double emPrimary = 0.0, emShadow = 0.0, emPrimary8 = 0.0, emShadow8 = 0.0, emPrimaryStream = 0.0, emShadowStream = 0.0;
    double emPrimaryMismatch = 0.0, emShadowMismatch = 0.0;
    size_t streamPrimaryVsSingle = 0, streamShadowVsSingle = 0;
#ifdef SYLVA_HAVE_EMBREE
    if (ranEmbree) {
        emPrimary = mrays(pixels, passes[2].timing.median);
        emShadow = mrays(shadowCount, passes[3].timing.median);
        emPrimary8 = mrays(pixels, passes[4].timing.median);
        emShadow8 = mrays(shadowCount, passes[5].timing.median);
        std::printf("%-40s %12.2f %12.2f\n", "ratio ours / embree primary (single)", ourPrimary / emPrimary,
                    passes[2].timing.min / passes[0].timing.min);
        std::printf("%-40s %12.2f %12.2f\n", "ratio ours / embree shadow (single)", ourShadow / emShadow,
                    passes[3].timing.min / passes[1].timing.min);
        emPrimaryStream = mrays(pixels, passes[6].timing.median);
        emShadowStream = mrays(shadowCount, passes[7].timing.median);
        std::printf("%-40s %12.2f %12.2f\n", "ratio ours / embree primary (packets)", ourPrimary / emPrimary8,
                    passes[4].timing.min / passes[0].timing.min);
        std::printf("%-40s %12.2f %12.2f\n", "ratio ours / embree shadow (packets)", ourShadow / emShadow8,
                    passes[5].timing.min / passes[1].timing.min);
        std::printf("%-40s %12.2f %12.2f\n", "ratio ours / embree primary (stream)", ourPrimary / emPrimaryStream,
                    passes[6].timing.min / passes[0].timing.min);
        std::printf("%-40s %12.2f %12.2f\n", "ratio ours / embree shadow (stream)", ourShadow / emShadowStream,
                    passes[7].timing.min / passes[1].timing.min);

        const size_t pm = primaryMismatches(ours, em), pm8 = primaryMismatches(ours, em8);
        const size_t sm = shadowMismatches(oursOccluded, emOcc), sm8 = shadowMismatches(oursOccluded, em8Occ);
        const double shadows = double(std::max<size_t>(1, shadowCount));
        emPrimaryMismatch = double(pm) / double(pixels);
        emShadowMismatch = double(sm) / shadows;
        std::printf("\ncorrectness vs ours: primary hits differing (instance, or t > 1e-3 relative): %zu single (%.4f%%), %zu packet "
                    "(%.4f%%); shadow rays differing: %zu single (%.4f%%), %zu packet (%.4f%%)\n",
                    pm, 100.0 * emPrimaryMismatch, pm8, 100.0 * double(pm8) / double(pixels), sm, 100.0 * emShadowMismatch, sm8,
                    100.0 * double(sm8) / shadows);
        const size_t pmS = primaryMismatches(ours, emStream), smS = shadowMismatches(oursOccluded, emStreamOcc);
        streamPrimaryVsSingle = primaryMismatches(em, emStream);
        streamShadowVsSingle = shadowMismatches(emOcc, emStreamOcc);
        std::printf("stream (rtcIntersect1M/rtcOccluded1M, 8x8 tiles, coherent): %zu primary hits (%.4f%%) and %zu shadow rays "
                    "(%.4f%%) differ from ours; %zu primary hits and %zu shadow rays differ from Embree's single rays\n",
                    pmS, 100.0 * double(pmS) / double(pixels), smS, 100.0 * double(smS) / shadows, streamPrimaryVsSingle,
                    streamShadowVsSingle);
        std::printf("embree setup: %s build quality on species and top scenes, RTC_SCENE_FLAG_NONE (robust off), "
                    "per species an opaque and an alpha-filtered triangle geometry, ground plane analytic outside "
                    "Embree (as ours), 8-wide packets %s\n",
                    highQuality ? "HIGH" : "MEDIUM",
                    rtcGetDeviceProperty(peer->device, RTC_DEVICE_PROPERTY_NATIVE_RAY8_SUPPORTED) ? "native" : "emulated");
    }
#else
    if (useEmbree) std::printf("\nembree: peer missing (built without Embree 3; apt-get install libembree-dev and reconfigure)\n");
#endif

    std::printf("\n%-40s %12s %14s %14s\n", "build and memory", "build s", "B/inst. tri", "B/instance");
    std::printf("%-40s %12.3f %14.4f %14.1f\n", "ours (buildRenderScene, all arrays)", buildSeconds,
                ourBytes / std::max(1.0, st.instancedTriangles),
                double(st.tlasBytes + st.instanceBytes) / double(std::max<size_t>(1, st.instances)));
    if (ranEmbree)
        std::printf("%-40s %12.3f %14.4f %14.1f   (species %.3f s + top %.3f s; %.1f MB by memory monitor)\n",
                    "embree (species scenes + instances)", emBuild + emTopBuild, double(emBytes) / std::max(1.0, st.instancedTriangles),
                    double(emTopBytes) / double(std::max<size_t>(1, st.instances)), emBuild, emTopBuild, double(emBytes) / 1e6);
    std::printf("ours: %.1f MB (tlas %zu B, instances %zu B, blas %zu B, triangles %zu B, host 8-wide copies: tlas %zu B, "
                "blas %zu B); depth tlas %d, blas %d (8-wide: %d, %d)\n",
                ourBytes / 1e6, st.tlasBytes, st.instanceBytes, st.blasBytes, st.triangleBytes, st.wideTlasBytes, st.wideBlasBytes,
                st.tlasDepth, st.maxBlasDepth, st.wideTlasDepth, st.maxWideBlasDepth);
    std::printf("the host traverses %.1f MB (%.4f B per instanced triangle): 8-wide nodes, instances, triangle blocks\n",
                hostBytes / 1e6, hostBytes / std::max(1.0, st.instancedTriangles));

    std::printf("\nwidth=%d\nheight=%d\nthreads=%d\n", W, H, threadsUsed);
    std::printf("frame_s=%.4f\nframe_min_s=%.4f\n", frame.median, frame.min);
    std::printf("primary_mrays_s=%.3f\nshadow_mrays_s=%.3f\n", ourPrimary, ourShadow);
    if (v.blasWideNodes) {
        std::printf("narrow_primary_mrays_s=%.3f\nnarrow_shadow_mrays_s=%.3f\n", narrowPrimary, narrowShadow);
        std::printf("ratio_wide_narrow_primary=%.3f\nratio_wide_narrow_shadow=%.3f\n", ourPrimary / narrowPrimary,
                    ourShadow / narrowShadow);
    }
    std::printf("shadow_rays=%zu\n", shadowCount);
    if (ranEmbree) {
        std::printf("embree_primary_mrays_s=%.3f\nembree_shadow_mrays_s=%.3f\n", emPrimary, emShadow);
        std::printf("embree_primary8_mrays_s=%.3f\nembree_shadow8_mrays_s=%.3f\n", emPrimary8, emShadow8);
        std::printf("ratio_primary=%.3f\nratio_shadow=%.3f\n", ourPrimary / emPrimary, ourShadow / emShadow);
        std::printf("embree_stream_primary_mrays_s=%.3f\nembree_stream_shadow_mrays_s=%.3f\n", emPrimaryStream, emShadowStream);
        std::printf("ratio_primary8=%.3f\nratio_shadow8=%.3f\n", ourPrimary / emPrimary8, ourShadow / emShadow8);
        std::printf("ratio_primary_stream=%.3f\nratio_shadow_stream=%.3f\n", ourPrimary / emPrimaryStream,
                    ourShadow / emShadowStream);
        std::printf("embree_stream_vs_single_primary_mismatches=%zu\nembree_stream_vs_single_shadow_mismatches=%zu\n",
                    streamPrimaryVsSingle, streamShadowVsSingle);
        std::printf("embree_primary_mismatch_rate=%.6f\nembree_shadow_mismatch_rate=%.6f\n", emPrimaryMismatch, emShadowMismatch);
        std::printf("embree_build_s=%.4f\n", emBuild + emTopBuild);
        std::printf("embree_bytes_per_instanced_triangle=%.4f\nembree_bytes_per_instance=%.1f\n",
                    double(emBytes) / std::max(1.0, st.instancedTriangles),
                    double(emTopBytes) / double(std::max<size_t>(1, st.instances)));
    }
    std::printf("build_s=%.4f\n", buildSeconds);
    std::printf("accel_bytes_per_instanced_triangle=%.4f\n", ourBytes / std::max(1.0, st.instancedTriangles));
    std::printf("host_traversal_bytes_per_instanced_triangle=%.4f\n", hostBytes / std::max(1.0, st.instancedTriangles));
    std::printf("accel_bytes_per_instance=%.1f\n",
                double(st.tlasBytes + st.instanceBytes) / double(std::max<size_t>(1, st.instances)));
    return 0;
}
