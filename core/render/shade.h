// Shading of one camera sample: sun light with shadow rays, LB indirect light, sky (host and device).
#pragma once

#include "core/render/lights.h"
#include "core/render/path_trace.h"
#include "core/render/render_view.h"
#include "core/render/sampling.h"
#include "core/render/trace.h"

namespace sylva {

// Linear RGB of a render mode from a pixel's parts: full = local + indirect, local = sun light only,
// ambient = local + a constant ambient x albedo, lb = indirect only; plus the sky where samples saw it
// (skyCover x the constant sky `sky`, composeSky(scene), plus the other skies' background).
SYLVA_HD SYLVA_INLINE glm::vec3 composeSample(const SampleParts& p, RenderMode mode, const glm::vec3& sky, float ambient)
{
    glm::vec3 c(0.0f);
    switch (mode) {
    case RenderMode::Full: c = p.local + p.indirect; break;
    case RenderMode::Local: c = p.local; break;
    case RenderMode::Ambient: c = p.local + ambient * p.albedo; break;
    case RenderMode::Lb: c = p.indirect; break;
    }
    const glm::vec3 withSky = c + p.skyCover * sky;
    return withSky + p.background;
}

// Shading runs in stages, each a SYLVA_HD function the CPU loop and the GPU kernel chain the same way
// (shadeRay): intersect -> surface -> volume -> background and lights. A new stage or a new kind of
// light goes into this chain once and runs on every backend.

// Stage 1, intersect: the first surface along a camera ray (ground, or a mesh reached through the levels).
SYLVA_HD SYLVA_INLINE bool intersectStage(const RenderView& v, const Ray& ray, Hit& hit) { return traceScene<false>(v, ray, hit); }

// Stage 2, surface: geometry and material at the hit, from the kind that recorded it (trace.h surfaceAt).
SYLVA_HD SYLVA_INLINE SurfacePoint surfaceStage(const RenderView& v, const Ray& ray, const Hit& hit) { return surfaceAt(v, ray, hit); }

// Stage 3, volume: what the media kinds (core/render/surfaces/surface_list.h) along the camera ray's segment
// [ray.tmin, tEnd] add to and take from the parts behind them, each kind's cross<Kind> in the list's order
// (the volumes: surfaces/volumes_trace.h crossVolumes). Without media the parts pass unchanged.
SYLVA_HD inline void volumeStage(const RenderView& v, const Ray& ray, float tEnd, SampleParts& parts)
{
#define SYLVA_X(Kind) cross##Kind(v, ray, tEnd, parts);
    SYLVA_SURFACE_KINDS(SYLVA_KIND_SKIP, SYLVA_X)
#undef SYLVA_X
}

// Stage 4, background and lights: a ray that hit nothing sees the environment (the constant sky through
// skyCover, a Preetham or map sky's radiance toward the ray in `background`, a map filtered to the sample's
// footprint: lights/sky_radiance.h viewSkyBackground); a surface gets each light of the
// list (core/render/lights.h: the sun with a shadow ray, the sky's virtual lights of its interleaved subset)
// and its own indirect light (LB on meshes).
SYLVA_HD SYLVA_INLINE SampleParts backgroundStage(const RenderView& v, const Ray& ray)
{
    SampleParts out{glm::vec3(0.0f), glm::vec3(0.0f), glm::vec3(0.0f), 1.0f, glm::vec3(0.0f), kSkyDepth, glm::vec3(0.0f)};
    if (v.sky.model.kind != sky::SkyKind::Constant) out.background = viewSkyBackground(v, ray.dir);
    return out;
}

// seen: null traces every light's shadow ray here; else seen[i] for the first kPacketLights lights is the
// answer the caller traced (LightQuery::seen).
SYLVA_HD inline SampleParts lightStage(const RenderView& v, const SurfacePoint& s, int px = 0, int py = 0, int sample = 0,
                                       const int* seen = nullptr)
{
    LightContribution light{glm::vec3(0.0f), s.indirect};
    for (uint32_t i = 0; i < v.lightCount; ++i) {
        const LightQuery q{px, py, sample, seen && i < uint32_t(kPacketLights) ? seen[i] : -1};
        lightDirect(v, v.lights[i], s, q, light);
    }
    return SampleParts{light.local, light.indirect, s.albedo, 0.0f, s.ng, glm::dot(s.p, v.camera.forward), glm::vec3(0.0f)};
}

// Stage 4 along paths at a surface: the path tracer (render.integrator path, every bounce up to
// render.max_bounces) or the LB integrator's radiance cache (lighting.bounces > 0: that many bounces, then the
// LB grid's scattered light), core/render/path_trace.h. The first surface's direct light is `local`, the rest
// `indirect`; its albedo, normal and depth as lightStage gives them.
// bounces false: the first surface's direct light alone (render.bounce_samples: shadePixel adds its bounced light).
SYLVA_HD inline SampleParts pathStage(const RenderView& v, const SurfacePoint& s, int px, int py, int sample, bool bounces = true)
{
    const bool path = v.integrator == Integrator::Path;
    const PathLight l = pathRadiance(v, s, px, py, sample, path ? v.maxBounces : v.lightingBounces, !path, !bounces);
    return SampleParts{l.direct, l.indirect, s.albedo, 0.0f, s.ng, glm::dot(s.p, v.camera.forward), glm::vec3(0.0f)};
}

// The stages after intersect for a camera ray whose first hit is known (found; hit and its surface sp where
// found), sample s of pixel (px, py); seen as lightStage takes it.
SYLVA_HD inline SampleParts shadeFound(const RenderView& v, const Ray& ray, bool found, const Hit& hit, const SurfacePoint& sp, int px, int py, int s,
                                       const int* seen = nullptr)
{
    SampleParts out = !found ? backgroundStage(v, ray) : tracesPaths(v) ? pathStage(v, sp, px, py, s) : lightStage(v, sp, px, py, s, seen);
    volumeStage(v, ray, found ? hit.t : ray.tmax, out);
    return out;
}

// Shades one camera ray, sample s of pixel (px, py) (which subset of the sky lights it uses): the stages in order.
SYLVA_HD inline SampleParts shadeRay(const RenderView& v, const Ray& ray, int px = 0, int py = 0, int s = 0)
{
    Hit hit{};
    const bool found = intersectStage(v, ray, hit);
    return shadeFound(v, ray, found, hit, found ? surfaceStage(v, ray, hit) : SurfacePoint{}, px, py, s);
}

// Camera ray through image position (x, y) in pixels (y down, 0..width/height), camera-relative.
SYLVA_HD SYLVA_INLINE Ray cameraRay(const RenderView& v, float x, float y)
{
    const float sx = (2.0f * x / float(v.width) - 1.0f) * v.camera.tanHalfX;
    const float sy = (1.0f - 2.0f * y / float(v.height)) * v.camera.tanHalfY;
    Ray r;
    r.org = glm::vec3(0.0f);
    r.dir = glm::normalize(v.camera.forward + sx * v.camera.right + sy * v.camera.up);
    r.tmin = 0.0f;
    r.tmax = 1e30f;
    return r;
}

// Sample s of spp inside pixel (px, py): one sample at the centre; a stratified n x n grid when spp
// is a square; otherwise jittered random positions.
SYLVA_HD SYLVA_INLINE glm::vec2 samplePosition(int px, int py, int s, int spp)
{
    if (spp == 1) return glm::vec2(float(px) + 0.5f, float(py) + 0.5f);
    int n = int(sqrtf(float(spp)) + 0.5f);
    const float jx = hashToUnit(uint32_t(px), uint32_t(py), uint32_t(2 * s));
    const float jy = hashToUnit(uint32_t(px), uint32_t(py), uint32_t(2 * s + 1));
    if (n * n == spp) {
        const int sx = s % n, sy = s / n;
        return glm::vec2(float(px) + (float(sx) + jx) / float(n), float(py) + (float(sy) + jy) / float(n));
    }
    return glm::vec2(float(px) + jx, float(py) + jy);
}

// A pixel's box filter: the samples summed in order (the depth their minimum), then averaged.
SYLVA_HD SYLVA_INLINE SampleParts pixelSumStart()
{
    return SampleParts{glm::vec3(0.0f), glm::vec3(0.0f), glm::vec3(0.0f), 0.0f, glm::vec3(0.0f), kSkyDepth, glm::vec3(0.0f)};
}
SYLVA_HD SYLVA_INLINE void pixelSumAdd(SampleParts& sum, const SampleParts& p)
{
    sum.local += p.local;
    sum.indirect += p.indirect;
    sum.albedo += p.albedo;
    sum.skyCover += p.skyCover;
    sum.normal += p.normal;
    sum.depth = fminf(sum.depth, p.depth);
    sum.background += p.background;
}
SYLVA_HD SYLVA_INLINE void pixelSumAverage(SampleParts& sum, int samples)
{
    const float inv = 1.0f / float(samples > 0 ? samples : 1);
    sum.local *= inv;
    sum.indirect *= inv;
    sum.albedo *= inv;
    sum.skyCover *= inv;
    sum.normal *= inv;
    sum.background *= inv;
}

// The samples a pixel takes in this view: v.sampleBegin .. sampleEnd (all spp when sampleEnd is 0).
SYLVA_HD SYLVA_INLINE int sampleEndOf(const RenderView& v) { return v.sampleEnd > 0 ? v.sampleEnd : v.spp; }

// Camera ray of sample s of pixel (px, py).
SYLVA_HD SYLVA_INLINE Ray sampleRay(const RenderView& v, int px, int py, int s)
{
    const glm::vec2 pos = samplePosition(px, py, s, v.spp);
    return cameraRay(v, pos.x, pos.y);
}

// Does sample s trace the bounces (render.bounce_samples)? Every bounceStride-th sample of the frame, and the
// first of each pass (a progressive pass always has one).
SYLVA_HD SYLVA_INLINE bool sampleTracesBounces(const RenderView& v, int s) { return s % v.bounceStride == 0 || s == v.sampleBegin; }

// The pixel's samples with render.bounce_samples (the LB integrator's radiance cache, bounceStride > 1): the
// samples that trace the bounces first, then the others with their first surface's direct light only and, as their
// bounced light, their albedo times the traced samples' bounced light over those samples' albedo per channel (a
// ratio estimate: a pixel's surfaces get much the same indirect light, while which leaf a sample meets, and whether
// the sun reaches it, changes from sample to sample). A sample that meets a surface while no traced one has traces
// its bounces too. The media act on each sample after its surface's light, as in shadeRay.
SYLVA_HD inline SampleParts shadeDecoupledPixel(const RenderView& v, int px, int py)
{
    SampleParts sum = pixelSumStart();
    const int sBegin = v.sampleBegin, sEnd = sampleEndOf(v);
    glm::vec3 bounced(0.0f), albedo(0.0f);
    for (int pass = 0; pass < 2; ++pass)
        for (int s = sBegin; s < sEnd; ++s) {
            if (sampleTracesBounces(v, s) != (pass == 0)) continue;
            const Ray ray = sampleRay(v, px, py, s);
            Hit hit{};
            const bool found = intersectStage(v, ray, hit);
            SampleParts p;
            if (!found) {
                p = backgroundStage(v, ray);
            } else {
                const bool known = albedo.x > 0.0f || albedo.y > 0.0f || albedo.z > 0.0f;
                const bool traces = pass == 0 || !known;
                p = pathStage(v, surfaceStage(v, ray, hit), px, py, s, traces);
                if (traces) {
                    bounced += p.indirect;
                    albedo += p.albedo;
                } else {
                    for (int c = 0; c < 3; ++c) p.indirect[c] = albedo[c] > 0.0f ? p.albedo[c] * bounced[c] / albedo[c] : 0.0f;
                }
            }
            volumeStage(v, ray, found ? hit.t : ray.tmax, p);
            pixelSumAdd(sum, p);
        }
    pixelSumAverage(sum, sEnd - sBegin);
    return sum;
}

// All samples of one pixel (or those of v.sampleBegin .. sampleEnd), box-filtered.
SYLVA_HD inline SampleParts shadePixel(const RenderView& v, int px, int py)
{
    if (v.bounceStride > 1 && v.integrator == Integrator::Lb && v.lightingBounces > 0) return shadeDecoupledPixel(v, px, py);
    SampleParts sum = pixelSumStart();
    const int sBegin = v.sampleBegin, sEnd = sampleEndOf(v);
    for (int s = sBegin; s < sEnd; ++s) pixelSumAdd(sum, shadeRay(v, sampleRay(v, px, py, s), px, py, s));
    pixelSumAverage(sum, sEnd - sBegin);
    return sum;
}

} // namespace sylva
