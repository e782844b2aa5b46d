// The frame's lights as one list (RenderView::lights, kinds in core/render/lights/light_list.h): what each
// adds to a surface point, its shadow rays, and sample / eval / pdf for next-event estimation, dispatched on
// the kind in one place (host and device).
#pragma once

#include "core/render/surface_point.h"
#include "core/render/trace.h"

namespace sylva {

// What the lights add to a surface point's parts, each adding its share in the list's order: `local` direct
// light, `indirect` ambient (the constant sky's uniform light on the Lambertian ground).
struct LightContribution {
    glm::vec3 local;
    glm::vec3 indirect;
};

// Where a light's contribution is asked for: sample `sample` of pixel (px, py) (the sky's interleaved subset),
// and `seen`: -1 traces the light's shadow ray here; 0 or 1 is its answer traced by the caller (a packet of a
// tile's shadow rays, core/render/render_cpu.cpp), used only where the light's shadowRay gave a ray.
struct LightQuery {
    int px, py, sample;
    int seen;
};

// A direction toward a light for next-event estimation: the radiance arriving along wi over the density the
// direction was drawn with (a delta light: its irradiance at normal incidence, pdf 1), the distance to the
// light (3e38 for distant ones).
struct LightSample {
    glm::vec3 wi;
    glm::vec3 value;
    float pdf;
    float distance;
    bool delta;
};

// Is the distant light toward unit `dir` visible from camera-relative point p (already offset off its
// surface)? The alpha-tested any-hit query; always with shadows off.
SYLVA_HD inline bool directionVisible(const RenderView& v, const glm::vec3& p, const glm::vec3& dir)
{
    if (!v.shadows) return true;
    Ray r{p, 0.0f, dir, 1e30f};
    Hit h{};
    return !traceScene<true>(v, r, h);
}

// Is camera-relative point `to` visible from p (already offset off its surface)? Always with shadows off.
SYLVA_HD inline bool segmentVisible(const RenderView& v, const glm::vec3& p, const glm::vec3& to)
{
    if (!v.shadows) return true;
    Ray r{p, 0.0f, to - p, 1.0f};
    Hit h{};
    return !traceScene<true>(v, r, h);
}

} // namespace sylva

#include "core/render/lights/distant.h"
#include "core/render/lights/point.h"
#include "core/render/lights/sky.h"

namespace sylva {

#define SYLVA_LIGHT_CASE(Kind, call) \
    case LightKind::Kind: return call;

SYLVA_HD inline void lightDirect(const RenderView& v, const LightRecord& l, const SurfacePoint& s, const LightQuery& q, LightContribution& out)
{
    switch (l.kind) {
#define SYLVA_X(Kind) SYLVA_LIGHT_CASE(Kind, direct##Kind(v, l, s, q, out))
        SYLVA_LIGHT_KINDS(SYLVA_X)
#undef SYLVA_X
    }
}

SYLVA_HD inline bool lightShadowRay(const RenderView& v, const LightRecord& l, const SurfacePoint& s, Ray& r)
{
    switch (l.kind) {
#define SYLVA_X(Kind) SYLVA_LIGHT_CASE(Kind, shadowRay##Kind(v, l, s, r))
        SYLVA_LIGHT_KINDS(SYLVA_X)
#undef SYLVA_X
    }
    return false;
}

SYLVA_HD inline LightSample lightSample(const RenderView& v, const LightRecord& l, const glm::vec3& p, glm::vec2 u)
{
    switch (l.kind) {
#define SYLVA_X(Kind) SYLVA_LIGHT_CASE(Kind, sample##Kind(v, l, p, u))
        SYLVA_LIGHT_KINDS(SYLVA_X)
#undef SYLVA_X
    }
    return LightSample{glm::vec3(0.0f, 1.0f, 0.0f), glm::vec3(0.0f), 0.0f, 0.0f, true};
}

SYLVA_HD inline glm::vec3 lightEval(const RenderView& v, const LightRecord& l, const glm::vec3& dir)
{
    switch (l.kind) {
#define SYLVA_X(Kind) SYLVA_LIGHT_CASE(Kind, eval##Kind(v, l, dir))
        SYLVA_LIGHT_KINDS(SYLVA_X)
#undef SYLVA_X
    }
    return glm::vec3(0.0f);
}

SYLVA_HD inline float lightPdf(const RenderView& v, const LightRecord& l, const glm::vec3& dir)
{
    switch (l.kind) {
#define SYLVA_X(Kind) SYLVA_LIGHT_CASE(Kind, pdf##Kind(v, l, dir))
        SYLVA_LIGHT_KINDS(SYLVA_X)
#undef SYLVA_X
    }
    return 0.0f;
}

#undef SYLVA_LIGHT_CASE

// The lights the packet path traces shadow rays of together (the first ones of the list; the others trace
// their own).
inline constexpr int kPacketLights = 4;

} // namespace sylva
