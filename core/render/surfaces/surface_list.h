// The surface kinds: everything a ray can end on, one line each. Adding a kind is a record header (what
// RenderView holds of it: its line in RenderView, its arrays' lines in SYLVA_RENDER_ARRAYS), an intersector
// and shader header (<kind>_trace.h, included by core/render/trace.h), a builder (called from the scene
// build's table of contents) and its line here; docs/ARCHITECTURE.md walks through it with the spheres.
//
// Scene kinds are traced in the order listed, each below the closest hit so far (the ground and the terrain
// first, so their hit shortens the rays the plants are traversed with: Dietrich, Marmitt & Slusallek,
// "Terrain Guided Multi-Level Instancing of Highly Complex Plant Populations", section 4.1). Each kind name
// K provides, in <kind>_trace.h:
//   template <bool AnyHit, bool Kd> SYLVA_HD bool traceK(trace_detail::Query& q, const Ray& ray, float& tmax)
//       its hits below tmax recorded in q.hit (kind K) and tmax shortened; true when an any-hit query is answered;
//   SYLVA_HD void shadeK(const RenderView& v, const Ray& ray, const Hit& hit, SurfacePoint& s)
//       the point, normal, material and indirect light of a hit it recorded;
//   template <bool AnyHit, bool Kd> void tracePacketK(trace_detail::PacketQuery<AnyHit, Kd>& p)
//       (host only) the same for a packet of rays: each ray gets the answer traceK gives it alone.
//
// Below the instances kind, what an instance points to is a geometry kind (GeometryKind, render_view.h):
// a mesh or a group of instances (surfaces/instances_trace.h dispatches on it).
#pragma once

#include <cstdint>

#include "core/render/surfaces/ground.h"
#include "core/render/surfaces/landscape.h"
#include "core/render/surfaces/sphere.h"
#include "core/render/surfaces/terrain.h"

#define SYLVA_SURFACE_KINDS(X) \
    X(Ground)                  \
    X(Terrain)                 \
    X(Spheres)                 \
    X(Landscape)               \
    X(Instances)

namespace sylva {

// Hit::kind: which kind recorded the hit (None: the ray hit nothing).
enum class SurfaceKind : uint16_t {
    None = 0,
#define SYLVA_X(Kind) Kind,
    SYLVA_SURFACE_KINDS(SYLVA_X)
#undef SYLVA_X
};

} // namespace sylva
