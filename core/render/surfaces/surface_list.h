// The kinds of what a ray meets in a scene, one line each: surfaces (S), which end rays, and media (M), which
// rays cross (they take light from what lies behind and add their own). Adding a kind is a record header
// (what RenderView holds of it: its line in RenderView, its arrays' lines in SYLVA_RENDER_ARRAYS), an
// intersector and shader header (<kind>_trace.h, included by core/render/trace.h), a builder (called from the
// scene build's table of contents) and its line here; docs/ARCHITECTURE.md walks through it with the spheres.
//
// Surface kinds are traced in the order listed, each below the closest hit so far (the ground and the terrain
// first, so their hit shortens the rays the plants are traversed with: Dietrich, Marmitt & Slusallek,
// "Terrain Guided Multi-Level Instancing of Highly Complex Plant Populations", section 4.1). Each surface kind
// K provides, in <kind>_trace.h:
//   template <bool AnyHit, bool Kd> SYLVA_HD bool traceK(trace_detail::Query& q, const Ray& ray, float& tmax)
//       its hits below tmax recorded in q.hit (kind K) and tmax shortened; true when an any-hit query is answered;
//   SYLVA_HD void shadeK(const RenderView& v, const Ray& ray, const Hit& hit, SurfacePoint& s)
//       the point, normal, material and indirect light of a hit it recorded;
//   template <bool AnyHit, bool Kd> void tracePacketK(trace_detail::PacketQuery<AnyHit, Kd>& p)
//       (host only) the same for a packet of rays: each ray gets the answer traceK gives it alone.
// Each medium kind K provides, in <kind>_trace.h:
//   SYLVA_HD void crossK(const RenderView& v, const Ray& ray, float tEnd, SampleParts& parts)
//       a camera ray's segment [ray.tmin, tEnd] through it: the parts behind it attenuated, its own light added
//       (the volume stage, core/render/shade.h: media kinds in the list's order, each in front of the ones
//       before it);
//   SYLVA_HD glm::vec3 transmittanceK(const RenderView& v, const glm::vec3& org, const glm::vec3& dir, float tmax)
//       what gets through it along a shadow ray, per channel (mediaTransmittance, core/render/trace.h).
//
// Below the instances kind, what an instance points to is a geometry kind (GeometryKind, render_view.h):
// a mesh or a group of instances (surfaces/instances_trace.h dispatches on it).
#pragma once

#include <cstdint>

#include "core/render/surfaces/atmosphere.h"
#include "core/render/surfaces/ground.h"
#include "core/render/surfaces/landscape.h"
#include "core/render/surfaces/sphere.h"
#include "core/render/surfaces/terrain.h"
#include "core/render/surfaces/volume.h"

#define SYLVA_SURFACE_KINDS(S, M) \
    S(Ground)                     \
    S(Terrain)                    \
    S(Spheres)                    \
    S(Landscape)                  \
    S(Instances)                  \
    M(Volumes)                    \
    M(Atmosphere)

// The expander for the kinds a use of the list leaves out (the media where rays are traced, the surfaces
// where segments are crossed).
#define SYLVA_KIND_SKIP(Kind)

namespace sylva {

// Hit::kind: which surface kind recorded the hit (None: the ray hit nothing).
enum class SurfaceKind : uint16_t {
    None = 0,
#define SYLVA_X(Kind) Kind,
    SYLVA_SURFACE_KINDS(SYLVA_X, SYLVA_KIND_SKIP)
#undef SYLVA_X
};

} // namespace sylva
