// The sky light: the environment (constant, uniform, Preetham or map sky, RenderView::sky) lighting the scene.
// Surfaces get it as its virtual directional lights (core/sky/virtual_lights.h), a subset per pixel and sample
// with a shadow ray each, and the Lambertian ground the constant sky's uniform ambient besides; meshes get the
// rest of it through their LB grids (host and device). Its functions as light_list.h names them; included by
// core/render/lights.h.
#pragma once

#include "core/render/lights/sky_radiance.h"

namespace sylva {

// Irradiance / pi at camera-relative point p (offset already) with unit normal n from the virtual sky
// lights of the subset pixel (px, py) uses for its sample s (interleaved sampling, core/sky/
// virtual_lights.h): each light of the subset weighted by K, one shadow ray each. A diffuse surface of
// albedo a shows a x this. 0 without sky lights.
SYLVA_HD inline glm::vec3 skyLightIrradiance(const RenderView& v, const glm::vec3& p, const glm::vec3& n, int px, int py, int s)
{
    glm::vec3 e(0.0f);
    const int count = int(v.sky.lightCount);
    if (count == 0) return e;
    const sky::Interleave& il = v.sky.interleave;
    const int subset = sky::interleavedSubset(il, px, py, s);
    const int size = sky::subsetSize(il, subset, count);
    for (int k = 0; k < size; ++k) {
        const sky::VirtualLight& l = v.skyLights[sky::subsetLight(il, subset, k)];
        const float c = glm::dot(n, l.direction);
        if (c > 0.0f && directionVisible(v, p, l.direction)) e += l.power * c;
    }
    return e * (sky::interleaveWeight(il) / sky::kPi);
}

SYLVA_HD SYLVA_INLINE bool shadowRaySky(const RenderView&, const LightRecord&, const SurfacePoint&, Ray&) { return false; }

SYLVA_HD inline void directSky(const RenderView& v, const LightRecord&, const SurfacePoint& s, const LightQuery& q, LightContribution& out)
{
    if (v.sky.lightCount > 0) out.local += s.albedo * skyLightIrradiance(v, shadowOrigin(s), s.ng, q.px, q.py, q.sample);
    if (s.ground) out.indirect += s.albedo * v.sky.constant;
}

// The sky's radiance toward unit dir: the constant sky's colour, else the Preetham or map sky's.
SYLVA_HD SYLVA_INLINE glm::vec3 evalSky(const RenderView& v, const LightRecord&, const glm::vec3& dir)
{
    return v.sky.model.kind == sky::SkyKind::Constant ? v.sky.constant : viewSkyRadiance(v, dir);
}

// The index of the interval of the CDF cdf[0 .. n] (cdf[0] = 0, cdf[n] = 1) that holds u.
SYLVA_HD SYLVA_INLINE uint32_t cdfInterval(const float* cdf, uint32_t n, float u)
{
    uint32_t lo = 0, hi = n;   // cdf[lo] <= u < cdf[hi]
    while (hi - lo > 1) {
        const uint32_t mid = (lo + hi) / 2;
        if (cdf[mid] <= u) lo = mid;
        else hi = mid;
    }
    return lo;
}

// The density of direction dir: the constant sky (and a sky without its distribution) uniform over the sphere;
// a Preetham or map sky by its sampling distribution (light_list.h kSkySamplingRows), its cell's probability
// over the cell's solid angle (4 pi / cells).
SYLVA_HD inline float pdfSky(const RenderView& v, const LightRecord&, const glm::vec3& dir)
{
    const uint32_t R = v.sky.samplingRows, C = kSkySamplingCols;
    if (R == 0) return 1.0f / (4.0f * sky::kPi);
    const float* rows = v.skySampling;
    const uint32_t r = uint32_t(fminf(fmaxf((1.0f - dir.y) * 0.5f * float(R), 0.0f), float(R - 1)));
    float phi = atan2f(dir.z, dir.x);
    if (phi < 0.0f) phi += 2.0f * sky::kPi;
    const uint32_t c = uint32_t(fminf(fmaxf(phi * (float(C) / (2.0f * sky::kPi)), 0.0f), float(C - 1)));
    const float* cdf = rows + (R + 1) + r * (C + 1);
    return (rows[r + 1] - rows[r]) * (cdf[c + 1] - cdf[c]) * float(R * C) / (4.0f * sky::kPi);
}

// A direction by the density pdfSky gives: a row by the rows' CDF, a cell by its row's, then uniform over the cell
// (the numbers' remainders inside the chosen intervals, so stratified numbers stay stratified).
SYLVA_HD inline LightSample sampleSky(const RenderView& v, const LightRecord& l, const glm::vec3&, glm::vec2 u)
{
    const uint32_t R = v.sky.samplingRows, C = kSkySamplingCols;
    float y, phi;
    if (R == 0) {
        y = 1.0f - 2.0f * u.x;
        phi = 2.0f * sky::kPi * u.y;
    } else {
        const float* rows = v.skySampling;
        const uint32_t r = cdfInterval(rows, R, u.x);
        const float fy = fminf((u.x - rows[r]) / fmaxf(rows[r + 1] - rows[r], 1e-30f), 0.99999994f);
        const float* cdf = rows + (R + 1) + r * (C + 1);
        const uint32_t c = cdfInterval(cdf, C, u.y);
        const float fx = fminf((u.y - cdf[c]) / fmaxf(cdf[c + 1] - cdf[c], 1e-30f), 0.99999994f);
        y = 1.0f - 2.0f * (float(r) + fy) / float(R);
        phi = 2.0f * sky::kPi * (float(c) + fx) / float(C);
    }
    const float s = sqrtf(fmaxf(0.0f, 1.0f - y * y));
    const glm::vec3 wi(s * cosf(phi), y, s * sinf(phi));
    const float pdf = pdfSky(v, l, wi);
    return LightSample{wi, pdf > 0.0f ? evalSky(v, l, wi) / pdf : glm::vec3(0.0f), pdf, 3.0e38f, false};
}

} // namespace sylva
