// The point light (a lamp): light from one camera-relative point falling off as 1 / r^2, a shadow ray to
// it per point (host and device). Its functions as light_list.h names them; included by core/render/lights.h.
#pragma once

namespace sylva {

SYLVA_HD SYLVA_INLINE bool shadowRayPoint(const RenderView& v, const LightRecord& l, const SurfacePoint& s, Ray& r)
{
    if (!v.shadows || !(glm::dot(s.ng, l.position - s.p) > 0.0f)) return false;
    const glm::vec3 o = shadowOrigin(s);
    r = Ray{o, 0.0f, l.position - o, 1.0f};   // t in units of the segment: the light at t = 1
    return true;
}

SYLVA_HD inline void directPoint(const RenderView& v, const LightRecord& l, const SurfacePoint& s, const LightQuery& q, LightContribution& out)
{
    const glm::vec3 d = l.position - s.p;
    const float r2 = glm::dot(d, d);
    if (!(r2 > 0.0f)) return;
    const float r = sqrtf(r2);
    const glm::vec3 wi = d / r;
    const float nl = glm::dot(s.ng, wi);
    if (!(nl > 0.0f)) return;
    if (!(q.seen >= 0 ? q.seen != 0 : segmentVisible(v, shadowOrigin(s), l.position))) return;
    glm::vec3 c = reflectedLight(s, wi, nl, l.radiance / r2);
    c *= mediaTransmittance(v, s.p, wi, r);
    out.local += c;
}

SYLVA_HD SYLVA_INLINE LightSample samplePoint(const RenderView&, const LightRecord& l, const glm::vec3& p, glm::vec2)
{
    const glm::vec3 d = l.position - p;
    const float r2 = glm::dot(d, d);
    if (!(r2 > 0.0f)) return LightSample{glm::vec3(0.0f, 1.0f, 0.0f), glm::vec3(0.0f), 1.0f, 0.0f, true};
    const float r = sqrtf(r2);
    return LightSample{d / r, l.radiance * (sky::kPi / r2), 1.0f, r, true};
}

SYLVA_HD SYLVA_INLINE glm::vec3 evalPoint(const RenderView&, const LightRecord&, const glm::vec3&) { return glm::vec3(0.0f); }
SYLVA_HD SYLVA_INLINE float pdfPoint(const RenderView&, const LightRecord&, const glm::vec3&) { return 0.0f; }

} // namespace sylva
