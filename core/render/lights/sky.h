// The sky light: the environment (constant, uniform, Preetham or map sky, RenderView::sky) lighting the scene.
// Surfaces get it as its virtual directional lights (core/sky/virtual_lights.h), a subset per pixel and sample
// with a shadow ray each, and the Lambertian ground the constant sky's uniform ambient besides; meshes get the
// rest of it through their LB grids (host and device). Its functions as light_list.h names them; included by
// core/render/lights.h.
#pragma once

namespace sylva {

// Radiance of the view's Preetham or map sky (without its sun) toward unit direction d; the map's pixels
// are the skyMap array (on the device too).
SYLVA_HD inline glm::vec3 viewSkyRadiance(const RenderView& v, const glm::vec3& d)
{
    if (v.sky.model.kind == sky::SkyKind::Map) {
        sky::EnvMapView m = v.sky.model.map;
        m.rgb = v.skyMap;
        return sky::envMapRadiance(m, d);
    }
    return sky::skyRadiance(v.sky.model, d);
}

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

// Uniform over the sphere (y up).
SYLVA_HD SYLVA_INLINE float pdfSky(const RenderView&, const LightRecord&, const glm::vec3&) { return 1.0f / (4.0f * sky::kPi); }

SYLVA_HD inline LightSample sampleSky(const RenderView& v, const LightRecord& l, const glm::vec3&, glm::vec2 u)
{
    const float y = 1.0f - 2.0f * u.x;
    const float r = sqrtf(fmaxf(0.0f, 1.0f - y * y));
    const float phi = 2.0f * sky::kPi * u.y;
    const glm::vec3 wi(r * cosf(phi), y, r * sinf(phi));
    return LightSample{wi, evalSky(v, l, wi) / pdfSky(v, l, wi), pdfSky(v, l, wi), 3.0e38f, false};
}

} // namespace sylva
