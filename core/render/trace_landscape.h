// The landscape's traversal (seed 002 sections 4.1-4.3): the top-level 2D kd-tree over cells, top-down and
// nearest first, skipping nodes the ray passes above or below; in a cell its tile's 2D tree with the tile's
// height raised by the cell's ground range; plants lifted onto the height field and thinned by the density
// rule as they are reached. Included by trace.h after trace_detail's mesh traversal (host and device).
#pragma once

#include "core/terrain/landscape.h"

namespace sylva {

namespace trace_detail {

SYLVA_HD SYLVA_INLINE HeightFieldView landHeights(const RenderView& v) { return HeightFieldView{v.terrain, v.terrainHeights, v.terrainRanges}; }

// The camera-relative corner of cell (cx, cz): from the camera's base cell (placed in double on the host),
// so a cell's frame is as precise near the camera wherever the terrain lies.
SYLVA_HD SYLVA_INLINE glm::vec3 landCellCorner(const RenderView& v, uint32_t cx, uint32_t cz)
{
    return v.landBase + glm::vec3(float(int(cx) - v.landBaseCell.x) * v.land.cellSize, 0.0f, float(int(cz) - v.landBaseCell.y) * v.land.cellSize);
}

// Plant `plant` (tilePlants) of cell `cell`: whether it grows there, and its root (camera-relative).
SYLVA_HD inline bool landPlantRoot(const RenderView& v, uint32_t cell, const TilePlant& p, glm::vec3& root)
{
    const uint32_t cx = cell % v.land.cellsX, cz = cell / v.land.cellsX;
    float y;
    if (!landPlantGrows(v.land, landHeights(v), v.terrainSnowY, v.terrainRockCos, cx, cz, p, y)) return false;
    root = landCellCorner(v, cx, cz) + glm::vec3(v.land.tileScale * p.x, y, v.land.tileScale * p.z);
    return true;
}

// The map from the camera-relative frame to plant p's geometry frame (for shading a hit on it).
SYLVA_HD inline InstanceRecord landPlantInstance(const RenderView& v, uint32_t cell, uint32_t plant)
{
    const TilePlant& p = v.tilePlants[plant];
    glm::vec3 root(0.0f);
    landPlantRoot(v, cell, p, root);
    const float ik = v.land.invTileScale;
    InstanceRecord outer{};
    outer.row[0] = glm::vec4(ik, 0.0f, 0.0f, -root.x * ik);
    outer.row[1] = glm::vec4(0.0f, ik, 0.0f, -root.y * ik);
    outer.row[2] = glm::vec4(0.0f, 0.0f, ik, -root.z * ik);
    outer.scale = v.land.tileScale;
    InstanceRecord inner{};
    inner.row[0] = p.row[0];
    inner.row[1] = p.row[1];
    inner.row[2] = p.row[2];
    inner.geometry = p.geometry;
    inner.scale = p.scale;
    InstanceRecord r = composeInstances(inner, outer);
    r.geometry = p.geometry;
    return r;
}

// The plants of cell `cell`'s tile along the ray (camera-relative o, d): the tile's 2D tree, every node as
// tall as its plants raised over the ground's range under it (the cell's plane, LandCell); each plant reached
// is lifted onto the ground, thinned, box-tested and traced in its mesh. Returns true when an any-hit query
// found a hit.
template <bool AnyHit, bool Kd>
SYLVA_HD inline bool traceLandCell(Query& q, uint32_t cell, const glm::vec3& o, const glm::vec3& d, float& tmax)
{
    const RenderView& v = q.v;
    const LandCell c = v.landCells[cell];
    const TileRecord& tile = v.tileRecords[c.tile];
    if (tile.plantCount == 0) return false;
    SYLVA_COUNT(g_landCellVisits);
    const uint32_t cx = cell % v.land.cellsX, cz = cell / v.land.cellsX;
    const float ik = v.land.invTileScale;
    const glm::vec3 corner = landCellCorner(v, cx, cz);
    const glm::vec3 ot = (o - corner) * ik, dt = d * ik;   // the tile frame (t unchanged)
    const glm::vec3 inv = safeReciprocal(dt);
    const float gLo = c.ground.x * ik, gHi = c.ground.y * ik;   // the cell corner lies at the terrain frame's y = 0
    // The ground under tile-frame (x, z): the cell's plane within its deviation, clipped to the cell's range.
    const float p0 = c.plane.x * ik, px = c.plane.y * ik, pz = c.plane.z * ik, pe = c.plane.w * ik;
    // A node's box: its rectangle, its plants' vertical extent raised anywhere in the ground's range under it.
    auto entry = [&](const TileNode& n) {
        const float x0 = px * n.lox, x1 = px * n.hix, z0 = pz * n.loz, z1 = pz * n.hiz;
        const float lo = maxf(p0 + minf(x0, x1) + minf(z0, z1) - pe, gLo), hi = minf(p0 + maxf(x0, x1) + maxf(z0, z1) + pe, gHi);
        return rayBoxEntry(glm::vec3(n.lox, lo + n.ylo, n.loz), glm::vec3(n.hix, hi + n.yhi, n.hiz), ot, inv, q.tmin, tmax);
    };
    // Every node's box is tested once, by its parent (the root here): the stack keeps the entry distance of
    // each deferred child, re-checked against the closest hit when it comes up.
    uint32_t stackNode[64];
    float stackDist[64];
    int top = 0;
    if (!(entry(v.tileNodes[tile.nodeOffset]) <= tmax)) return false;
    uint32_t node = tile.nodeOffset;
    const HeightFieldView heights = landHeights(v);
    for (;;) {
        const TileNode& n = v.tileNodes[node];
        SYLVA_COUNT(g_tileNodeVisits);
        if (n.count == 0) {
            // Nearer child first, the farther one deferred, by entry distance.
            const float ta = entry(v.tileNodes[n.first]), tb = entry(v.tileNodes[n.first + 1]);
            const bool ha = ta <= tmax, hb = tb <= tmax;
            if (ha && hb) {
                const bool aFirst = ta <= tb;
                SYLVA_KERNEL_ASSERT(top < 64);
                stackNode[top] = aFirst ? n.first + 1 : n.first;
                stackDist[top] = aFirst ? tb : ta;
                ++top;
                node = aFirst ? n.first : n.first + 1;
                continue;
            }
            if (ha || hb) {
                node = ha ? n.first : n.first + 1;
                continue;
            }
        } else {
            for (uint32_t k = n.first; k < n.first + n.count; ++k) {
                const TilePlant& p = v.tilePlants[k];
                SYLVA_COUNT(g_plantBoxTests);
                // The plant's box raised anywhere in the ground's range at its root (the plane's bound; tile frame)
                // first: most plants of a leaf are rejected before the height field is read.
                const float g = p0 + px * p.x + pz * p.z, lo = maxf(g - pe, gLo), hi = minf(g + pe, gHi);
                if (!(rayBoxEntry(glm::vec3(p.x + p.lo.x, lo + p.lo.y, p.z + p.lo.z), glm::vec3(p.x + p.hi.x, hi + p.hi.y, p.z + p.hi.z), ot, inv,
                                  q.tmin, tmax) <= tmax))
                    continue;
                // Its root on the ground, its box there, and only then whether it grows (density, snow, rock).
                SYLVA_COUNT(g_plantRootReads);
                float y;
                uint32_t tri;
                if (!landPlantHeight(v.land, heights, cx, cz, p, y, tri)) continue;
                const glm::vec3 root = corner + glm::vec3(v.land.tileScale * p.x, y, v.land.tileScale * p.z);
                const glm::vec3 op = (o - root) * ik;   // the plant-centred tile frame
                if (!(rayBoxEntry(p.lo, p.hi, op, inv, q.tmin, tmax) <= tmax)) continue;
                if (!landPlantKept(v.land, heights, v.terrainSnowY, v.terrainRockCos, p, y, tri)) continue;
                InstanceRecord in{};
                in.row[0] = p.row[0];
                in.row[1] = p.row[1];
                in.row[2] = p.row[2];
                const GeometryRecord& geo = v.geometries[p.geometry];
                SYLVA_COUNT(g_plantMeshEntries);
                q.path[1] = cell;
                q.path[2] = k;
                if (traceMesh<AnyHit, Kd, 2>(q, geo, toLocalPoint(in, op), toLocalDir(in, dt), tmax)) return true;
            }
        }
        // The nearest deferred node still in reach.
        for (;;) {
            if (top == 0) return false;
            --top;
            if (stackDist[top] <= tmax) break;
        }
        node = stackNode[top];
    }
}

// The landscape's plants along the ray: its cells' 2D kd-tree top-down, near child first, a node skipped
// where the ray passes above or below its range or beyond the closest hit so far. Hits are recorded with
// inst = kLandscapeInst, nested[0] = the cell, nested[1] = the plant (tilePlants).
template <bool AnyHit, bool Kd>
SYLVA_HD inline bool traceLandscape(Query& q, const glm::vec3& o, const glm::vec3& d, float& tmax)
{
    const RenderView& v = q.v;
    const glm::vec3 inv = safeReciprocal(d);
    struct Entry {
        uint32_t node, x0, z0, x1, z1;
    };
    Entry stack[96];
    int top = 0;
    stack[top++] = Entry{0, 0, 0, v.land.cellsX, v.land.cellsZ};
    q.path[0] = kLandscapeInst;
    while (top > 0) {
        const Entry e = stack[--top];
        const LandNode& n = v.landNodes[e.node];
        SYLVA_COUNT(g_landNodeVisits);
        const glm::vec3 lo = landCellCorner(v, e.x0, e.z0), hi = landCellCorner(v, e.x1, e.z1);
        if (!(rayBoxEntry(glm::vec3(lo.x, v.landBase.y + n.range.x, lo.z), glm::vec3(hi.x, v.landBase.y + n.range.y, hi.z), o, inv, q.tmin, tmax) <= tmax))
            continue;
        if (n.child == 0) {
            if (traceLandCell<AnyHit, Kd>(q, e.z0 * v.land.cellsX + e.x0, o, d, tmax)) return true;
            continue;
        }
        Entry a{n.child, e.x0, e.z0, e.x1, e.z1}, b{n.child + 1, e.x0, e.z0, e.x1, e.z1};
        bool farIsLow;
        if (e.x1 - e.x0 >= e.z1 - e.z0) {
            a.x1 = b.x0 = (e.x0 + e.x1) / 2;
            farIsLow = d.x < 0.0f;
        } else {
            a.z1 = b.z0 = (e.z0 + e.z1) / 2;
            farIsLow = d.z < 0.0f;
        }
        stack[top++] = farIsLow ? a : b;
        stack[top++] = farIsLow ? b : a;
    }
    return false;
}

} // namespace trace_detail

} // namespace sylva
