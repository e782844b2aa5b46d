// The distant light (the sun): parallel light from one direction, a shadow ray per point, dimmed by the
// media it crosses (host and device). Its functions as light_list.h names them; included by core/render/lights.h.
#pragma once

namespace sylva {

SYLVA_HD SYLVA_INLINE bool shadowRayDistant(const RenderView& v, const LightRecord& l, const SurfacePoint& s, Ray& r)
{
    if (!v.shadows || !(glm::dot(s.ng, l.direction) > 0.0f)) return false;
    r = Ray{shadowOrigin(s), 0.0f, l.direction, 1e30f};
    return true;
}

SYLVA_HD inline void directDistant(const RenderView& v, const LightRecord& l, const SurfacePoint& s, const LightQuery& q, LightContribution& out)
{
    const float nl = glm::dot(s.ng, l.direction);
    if (!(nl > 0.0f)) return;
    if (!(q.seen >= 0 ? q.seen != 0 : directionVisible(v, shadowOrigin(s), l.direction))) return;
    glm::vec3 c = reflectedLight(s, l.direction, nl, l.radiance);
    c *= mediaTransmittance(v, s.p, l.direction);   // cloud shadows
    out.local += c;
}

SYLVA_HD SYLVA_INLINE LightSample sampleDistant(const RenderView&, const LightRecord& l, const glm::vec3&, glm::vec2)
{
    return LightSample{l.direction, l.radiance * sky::kPi, 1.0f, 3.0e38f, true};
}

SYLVA_HD SYLVA_INLINE glm::vec3 evalDistant(const RenderView&, const LightRecord&, const glm::vec3&) { return glm::vec3(0.0f); }
SYLVA_HD SYLVA_INLINE float pdfDistant(const RenderView&, const LightRecord&, const glm::vec3&) { return 0.0f; }

} // namespace sylva
