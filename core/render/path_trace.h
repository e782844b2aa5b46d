// The reference path tracer (render.integrator path): from a camera ray's first surface on, every bounce of
// light between the surfaces, with next-event estimation to each light of the list (sample / eval / pdf,
// core/render/lights.h), multiple importance sampling against the BSDF's directions for the lights that are not
// deltas (the sky), and Russian roulette. The same paths cut short and ended in the LB grid's light are the LB
// integrator's radiance cache (lighting.bounces). Surfaces are those the LB model renders: Lambertian reflection
// of the diffuse colour, the leaves' diffuse transmission (kd x ratio, capped as the Blender export's translucent
// BSDF) and the materials' Phong lobe as the renderer's direct light shows it. Paths do not scatter in volumes
// (the path tracer's build refuses them; with the cache, the sun is dimmed by them and the camera segment
// crosses them as in the LB integrator). Host and device.
#pragma once

#include "core/render/lights.h"
#include "core/render/sampling.h"

namespace sylva {

namespace path_detail {

// The numbers a path draws in turn, each decision (a light's direction, a lobe and a direction, the roulette) a
// dimension of its own: low-discrepancy over the pixel's samples (sampling.h lds, scrambled per pixel and
// dimension), so a pixel's samples spread over every decision's domain evenly. A path draws its dimensions
// in the same order at every sample (one pair per light and vertex, then the lobe, the direction and from the
// 4th bounce the roulette), so dimension k is the same decision in all of them.
struct Rng {
    uint32_t pixel, sample, dim;
    SYLVA_HD SYLVA_INLINE float next() { return lds::sample1(sample, lds::mix(pixel, dim++)); }
    SYLVA_HD SYLVA_INLINE glm::vec2 next2() { return lds::sample2(sample, lds::mix(pixel, dim++)); }
};

SYLVA_HD SYLVA_INLINE float average(const glm::vec3& c) { return (c.x + c.y + c.z) * (1.0f / 3.0f); }

// The point a ray toward unit wi leaves s from: off the surface on wi's side.
SYLVA_HD SYLVA_INLINE glm::vec3 originToward(const SurfacePoint& s, const glm::vec3& wi)
{
    return offsetPoint(s.p, glm::dot(s.ng, wi) >= 0.0f ? s.ng : -s.ng, s.extent);
}

// The diffuse lobes' sampling weights: reflection against transmission.
SYLVA_HD SYLVA_INLINE float reflectShare(const SurfacePoint& s)
{
    const float r = average(s.albedo), t = average(s.transmission);
    return r + t > 0.0f ? r / (r + t) : 1.0f;
}

} // namespace path_detail

// The BSDF times |cos| toward unit wi at s (ng faces the viewer, s.viewDir): albedo / pi on the viewer's side
// plus the Phong lobe (the renderer's reflectedLight divided by pi: a light of irradiance E at normal incidence
// shows exactly what the LB integrator's direct light shows of radiance E / pi), transmission / pi behind.
SYLVA_HD inline glm::vec3 bsdfCos(const SurfacePoint& s, const glm::vec3& wi)
{
    const float c = glm::dot(s.ng, wi);
    if (c > 0.0f) return reflectedLight(s, wi, c, glm::vec3(1.0f / sky::kPi));
    return s.transmission * (-c / sky::kPi);
}

// Its diffuse part (what the paths continue by): albedo / pi in front, transmission / pi behind. The Phong lobe,
// unnormalized and unbounded over cos at grazing angles, is met through next-event estimation only: the light
// it reflects of the sun and the sky, not of other surfaces.
SYLVA_HD SYLVA_INLINE glm::vec3 diffuseCos(const SurfacePoint& s, const glm::vec3& wi)
{
    const float c = glm::dot(s.ng, wi);
    return (c > 0.0f ? s.albedo : s.transmission) * (fabsf(c) / sky::kPi);
}

// The density the diffuse lobes' sampling gives unit wi: the lobe's share times cos / pi about its side's normal.
SYLVA_HD inline float bsdfPdf(const SurfacePoint& s, const glm::vec3& wi)
{
    const float c = glm::dot(s.ng, wi), r = path_detail::reflectShare(s);
    return (c > 0.0f ? r : 1.0f - r) * fabsf(c) / sky::kPi;
}

// The power heuristic (Veach's beta = 2) weight of a direction drawn with density a against one with density b.
SYLVA_HD SYLVA_INLINE float powerHeuristic(float a, float b)
{
    const float a2 = a * a, b2 = b * b;
    return a2 + b2 > 0.0f ? a2 / (a2 + b2) : 0.0f;
}

// Is the light sample's source visible from s toward ls.wi (distant lights: the whole ray; others: up to it)?
SYLVA_HD inline bool lightSampleVisible(const RenderView& v, const SurfacePoint& s, const LightSample& ls)
{
    const glm::vec3 o = path_detail::originToward(s, ls.wi);
    if (ls.distance >= 1e30f) return directionVisible(v, o, ls.wi);
    return segmentVisible(v, o, s.p + ls.wi * ls.distance);
}

// What a path brings back to the camera from its first surface: `direct`, the light the first surface gets
// from every light of the list (next-event estimation there); `indirect`, all the rest.
struct PathLight {
    glm::vec3 direct;
    glm::vec3 indirect;
};

// The light a path from the camera's first surface `first` (sample `sample` of pixel (px, py)) brings back:
// at each vertex one sample of every light (multiple importance sampling against the diffuse lobes' directions
// for lights that are not deltas), then a direction from the diffuse lobes, for `bounces` bounces after the
// first surface (Russian roulette from the 4th). At the last vertex no direction is drawn, so its lights count
// whole; with `endInCache` that vertex also adds its own indirect light (SurfacePoint::indirect: the LB grid's
// scattered light on meshes), the radiance cache standing for every bounce the path does not trace
// (lighting.bounces). The reference path tracer is bounces = render.max_bounces without the cache.
// firstOnly: the first surface's lights alone, weighted as on a path that goes on (bounces > 0), so that its
// `direct` is exactly the part of a whole path's light that `indirect` leaves out (render.bounce_samples).
SYLVA_HD inline PathLight pathRadiance(const RenderView& v, const SurfacePoint& first, int px, int py, int sample, int bounces, bool endInCache,
                                       bool firstOnly = false)
{
    path_detail::Rng rng{lds::mix(uint32_t(px), uint32_t(py)), uint32_t(sample), 0u};
    glm::vec3 L(0.0f), beta(1.0f), direct(0.0f);
    SurfacePoint s = first;
    for (int depth = 0;; ++depth) {
        const bool last = depth >= bounces;
        // Next-event estimation: one sample of each light.
        for (uint32_t i = 0; i < v.lightCount; ++i) {
            const LightSample ls = lightSample(v, v.lights[i], s.p, rng.next2());
            if (!(ls.pdf > 0.0f) || !(ls.value.x > 0.0f || ls.value.y > 0.0f || ls.value.z > 0.0f)) continue;
            const glm::vec3 f = bsdfCos(s, ls.wi);
            if (!(f.x > 0.0f || f.y > 0.0f || f.z > 0.0f) || !lightSampleVisible(v, s, ls)) continue;
            // The diffuse part weighted against the paths' own directions (whole at the last vertex, which draws
            // none); the Phong part whole (paths never carry it).
            const glm::vec3 d = diffuseCos(s, ls.wi);
            const float w = ls.delta || last ? 1.0f : powerHeuristic(ls.pdf, bsdfPdf(s, ls.wi));
            glm::vec3 c = beta * (d * w + (f - d)) * ls.value;
            if (ls.distance >= 1e30f) c *= mediaTransmittance(v, s.p, ls.wi);   // cloud shadows (the LB integrator's media)
            if (depth == 0) direct += c;
            else L += c;
        }
        if (firstOnly) break;
        if (last) {
            if (endInCache) L += beta * s.indirect;
            break;
        }
        // The next direction from the diffuse lobes: one by its share, then cosine about its side's normal.
        const float lobe = rng.next();
        const glm::vec2 u = rng.next2();
        const bool reflect = lobe < path_detail::reflectShare(s);
        const glm::vec3 wi = cosineHemisphere(reflect ? s.ng : -s.ng, u.x, u.y);
        const float pdf = bsdfPdf(s, wi);
        if (!(pdf > 0.0f)) break;
        beta *= diffuseCos(s, wi) / pdf;
        if (depth >= 3) {   // Russian roulette
            const float q = fminf(0.95f, fmaxf(beta.x, fmaxf(beta.y, beta.z)));
            if (!(rng.next() < q)) break;
            beta /= q;
        }
        Ray r{path_detail::originToward(s, wi), 0.0f, wi, 1e30f};
        Hit hit{};
        if (!traceScene<false>(v, r, hit)) {
            // The ray escaped: what the lights that are not deltas send along it, weighted against their sampling.
            for (uint32_t i = 0; i < v.lightCount; ++i) {
                const glm::vec3 Le = lightEval(v, v.lights[i], wi);
                if (!(Le.x > 0.0f || Le.y > 0.0f || Le.z > 0.0f)) continue;
                L += beta * Le * powerHeuristic(pdf, lightPdf(v, v.lights[i], wi));
            }
            break;
        }
        s = surfaceAt(v, r, hit);
    }
    return PathLight{direct, L};
}

} // namespace sylva
