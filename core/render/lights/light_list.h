// The light kinds, one line each, and the record a frame's light list (RenderView::lights) holds. Adding a
// light is a header <kind>.h in this folder (included by core/render/lights.h) with its functions, its line
// here and the record fields it needs; docs/ARCHITECTURE.md walks through it with the point light. Each kind K
// provides, for the shading code on every backend:
//   SYLVA_HD void directK(const RenderView&, const LightRecord&, const SurfacePoint&, const LightQuery&, LightContribution&)
//       what it adds to a surface point's parts (`local`: direct light; `indirect`: the uniform sky's ambient on
//       the ground), with its shadow rays (or the answer the packet path traced, LightQuery::seen);
//   SYLVA_HD bool shadowRayK(const RenderView&, const LightRecord&, const SurfacePoint&, Ray&)
//       its one shadow ray from the point where it has one (the packet path traces those together);
//   SYLVA_HD LightSample sampleK(const RenderView&, const LightRecord&, const glm::vec3& p, glm::vec2 u)
//       a direction toward it from camera-relative p for next-event estimation: the radiance arriving along it
//       over the sample's density (delta lights: their irradiance at normal incidence, pdf 1);
//   SYLVA_HD glm::vec3 evalK(const RenderView&, const LightRecord&, const glm::vec3& dir)
//       the radiance a ray that escapes the scene toward unit dir sees of it (0 for delta lights);
//   SYLVA_HD float pdfK(const RenderView&, const LightRecord&, const glm::vec3& dir)
//       the solid-angle density sampleK gives dir (0 for delta lights).
#pragma once

#include <cstdint>

#include <glm/glm.hpp>

#include "core/sky/sky.h"
#include "core/sky/virtual_lights.h"

#define SYLVA_LIGHT_KINDS(X) \
    X(Distant)               \
    X(Sky)                   \
    X(Point)

namespace sylva {

enum class LightKind : uint32_t {
#define SYLVA_X(Kind) Kind,
    SYLVA_LIGHT_KINDS(SYLVA_X)
#undef SYLVA_X
};

// One light of the frame. Units as the renderer's sun: a surface of albedo a lit at normal incidence shows
// a x radiance (distant), a x radiance / r^2 (point, r in metres). 48 bytes.
struct LightRecord {
    LightKind kind;
    glm::vec3 direction;     // Distant: toward the light, unit
    glm::vec3 position;      // Point: camera-relative
    uint32_t pad0;
    glm::vec3 radiance;      // Distant, Point: linear RGB as above; Sky: unused (RenderView::sky)
    uint32_t pad1;
};
static_assert(sizeof(LightRecord) == 48);

// The environment (RenderView::sky): what the Sky light draws behind everything and lights the scene with.
struct SkyRecord {
    glm::vec3 constant;          // the constant sky (model.kind Constant), else 0: drawn as skyCover x it, and
                                 // the uniform ambient of the Lambertian ground
    sky::SkyView model;          // the sky camera rays see; Map: its pixels are RenderView::skyMap (model.map.rgb unused)
    uint32_t lightCount;         // RenderView::skyLights, its virtual directional lights (0: none)
    sky::Interleave interleave;  // the K subsets of skyLights over pixels and samples
    uint32_t samplingRows;       // RenderView::skySampling: rows of the sky's sampling distribution (0: uniform, lights/sky.h)
};

// The sky's sampling distribution (lights/sky.h sampleSky): equal-area cells, kSkySamplingRows bands of equal
// height in y (the cosine of the zenith angle) by kSkySamplingCols sectors of azimuth, each drawn with a
// probability in proportion to the sky's luminance over it. RenderView::skySampling holds the rows' CDF (rows + 1
// values) and then each row's CDF over its cells (cols + 1 values a row).
inline constexpr uint32_t kSkySamplingRows = 32, kSkySamplingCols = 64;

} // namespace sylva
