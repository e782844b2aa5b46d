// The reference path tracer (render.integrator path): from a camera ray's first surface on, every bounce of
// light between the surfaces, with next-event estimation to each light of the list (sample / eval / pdf,
// core/render/lights.h), multiple importance sampling against the BSDF's directions for the lights that are not
// deltas (the sky), and Russian roulette. Surfaces are those the LB model renders: Lambertian reflection of the
// diffuse colour, the leaves' diffuse transmission (kd x ratio, capped as the Blender export's translucent BSDF)
// and the materials' Phong lobe as the renderer's direct light shows it. Volumes are not traced here (the
// build refuses them). Host and device.
#pragma once

#include "core/render/lights.h"
#include "core/render/sampling.h"

namespace sylva {

namespace path_detail {

// Random numbers a path draws in turn: a hash of pixel, sample and dimension; kDims dimensions per sample
// (2 per light and 4 a bounce).
inline constexpr uint32_t kDims = 65536;
struct Rng {
    uint32_t px, py, base, dim;
    SYLVA_HD SYLVA_INLINE float next() { return hashToUnit(px, py, base + dim++); }
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

// The radiance the camera ray `ray` brings back from its first surface `first` (sample `sample` of pixel
// (px, py)): the light each vertex gets from every light of the list, weighted by the path's throughput.
SYLVA_HD inline glm::vec3 pathRadiance(const RenderView& v, const Ray& ray, const SurfacePoint& first, int px, int py, int sample)
{
    path_detail::Rng rng{uint32_t(px), uint32_t(py), uint32_t(sample) * path_detail::kDims, 0u};
    glm::vec3 L(0.0f), beta(1.0f);
    SurfacePoint s = first;
    Ray r = ray;
    for (int depth = 0;; ++depth) {
        // Next-event estimation: one sample of each light.
        for (uint32_t i = 0; i < v.lightCount; ++i) {
            const float u1 = rng.next(), u2 = rng.next();
            const LightSample ls = lightSample(v, v.lights[i], s.p, glm::vec2(u1, u2));
            if (!(ls.pdf > 0.0f) || !(ls.value.x > 0.0f || ls.value.y > 0.0f || ls.value.z > 0.0f)) continue;
            const glm::vec3 f = bsdfCos(s, ls.wi);
            if (!(f.x > 0.0f || f.y > 0.0f || f.z > 0.0f) || !lightSampleVisible(v, s, ls)) continue;
            // The diffuse part weighted against the paths' own directions; the Phong part whole (paths never carry it).
            const glm::vec3 d = diffuseCos(s, ls.wi);
            const float w = ls.delta ? 1.0f : powerHeuristic(ls.pdf, bsdfPdf(s, ls.wi));
            L += beta * (d * w + (f - d)) * ls.value;
        }
        if (depth >= v.maxBounces) break;
        // The next direction from the diffuse lobes: one by its share, then cosine about its side's normal.
        const float lobe = rng.next(), u1 = rng.next(), u2 = rng.next();
        const bool reflect = lobe < path_detail::reflectShare(s);
        const glm::vec3 wi = cosineHemisphere(reflect ? s.ng : -s.ng, u1, u2);
        const float pdf = bsdfPdf(s, wi);
        if (!(pdf > 0.0f)) break;
        beta *= diffuseCos(s, wi) / pdf;
        if (depth >= 3) {   // Russian roulette
            const float q = fminf(0.95f, fmaxf(beta.x, fmaxf(beta.y, beta.z)));
            if (!(rng.next() < q)) break;
            beta /= q;
        }
        r = Ray{path_detail::originToward(s, wi), 0.0f, wi, 1e30f};
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
    return L;
}

} // namespace sylva
