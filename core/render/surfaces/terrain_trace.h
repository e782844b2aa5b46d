// The height-field terrain surface kind: its ray query (core/terrain/height_field.h) and its surface (host
// and device). Hit: prim = the height field's triangle, (u, v) its barycentrics.
#pragma once

#include "core/render/surfaces/mesh_trace.h"

namespace sylva {

namespace trace_detail {

template <bool AnyHit, bool Kd>
SYLVA_HD inline bool traceTerrain(Query& q, const Ray& ray, float& tmax)
{
    const TerrainRecord& tr = q.v.terrain;
    if (!tr.enabled) return false;
    const Ray local{ray.org - tr.base, ray.tmin, ray.dir, tmax};
    uint32_t tri = kNoHit;
    float u = 0.0f, w = 0.0f;
    if (!intersectHeightField<AnyHit>(HeightFieldView{tr.layout, q.v.terrainHeights, q.v.terrainRanges, tr.baseI, tr.baseJ}, local, tmax, tri, u,
                                      w))
        return false;
    if (AnyHit) return true;
    Hit& hit = q.hit;
    hit.kind = uint16_t(SurfaceKind::Terrain);
    hit.prim = tri;
    hit.t = tmax;
    hit.u = u;
    hit.v = w;
    return false;
}

} // namespace trace_detail

// The triangle's normal (terrain frame = world orientation) facing the viewer; the colour from slope and
// altitude: rock where steeper than the rock slope, snow above the snow line, the ground's colour elsewhere.
SYLVA_HD inline void shadeTerrain(const RenderView& v, const Ray&, const Hit& hit, SurfacePoint& s)
{
    const TerrainRecord& tr = v.terrain;
    s.ground = true;
    const glm::vec3 n = heightFieldNormal(HeightFieldView{tr.layout, v.terrainHeights, v.terrainRanges}, hit.prim);
    s.ng = glm::dot(n, s.viewDir) < 0.0f ? -n : n;
    const float y = (s.p - tr.origin).y;
    s.albedo = terrainAlbedo(y, n.y, tr.snowY, tr.rockCos, tr.snow, tr.rock, v.ground.color);
    // The hit was computed in the height field's rebased frame, whose heights keep their magnitude.
    const glm::vec3 lp = s.p - tr.base;
    s.extent = fmaxf(fmaxf(fabsf(lp.x), fabsf(lp.y)), fabsf(lp.z));
}

} // namespace sylva
