// The landscape's traversal (Dietrich, Marmitt & Slusallek, "Terrain Guided Multi-Level Instancing of Highly
// Complex Plant Populations", sections 4.1-4.3): the top-level 2D kd-tree over cells, top-down and nearest
// first, skipping nodes the ray passes above or below; in a cell its tile's 2D tree with the tile's height
// raised by the cell's ground range; plants lifted onto the height field and thinned by the density rule as
// they are reached; the landscape surface kind's query and surface (host and device). Hit: nested[0] = the
// cell, nested[1] = the plant (tilePlants), prim = the triangle of the plant's mesh, (u, v) its barycentrics.
#pragma once

#include "core/render/surfaces/mesh_trace.h"
#include "core/terrain/landscape.h"

namespace sylva {

namespace trace_detail {

SYLVA_HD SYLVA_INLINE HeightFieldView landHeights(const RenderView& v) { return HeightFieldView{v.terrain.layout, v.terrainHeights, v.terrainRanges}; }

// The camera-relative corner of cell (cx, cz): from the camera's base cell (placed in double on the host),
// so a cell's frame is as precise near the camera wherever the terrain lies.
SYLVA_HD SYLVA_INLINE glm::vec3 landCellCorner(const RenderView& v, uint32_t cx, uint32_t cz)
{
    return v.landscape.base + glm::vec3(float(int(cx) - v.landscape.baseCell.x) * v.landscape.layout.cellSize, 0.0f, float(int(cz) - v.landscape.baseCell.y) * v.landscape.layout.cellSize);
}

// Plant p's root (camera-relative) in the cell whose corner is `corner`, standing at DEM-frame height y.
SYLVA_HD SYLVA_INLINE glm::vec3 landRootAt(const RenderView& v, const glm::vec3& corner, const TilePlant& p, float y)
{
    return corner + glm::vec3(v.landscape.layout.tileScale * p.x, y, v.landscape.layout.tileScale * p.z);
}

// Plant `plant` (tilePlants) of cell `cell`: whether it grows there, and its root (camera-relative).
SYLVA_HD inline bool landPlantRoot(const RenderView& v, uint32_t cell, const TilePlant& p, glm::vec3& root)
{
    const uint32_t cx = cell % v.landscape.layout.cellsX, cz = cell / v.landscape.layout.cellsX;
    float y;
    if (!landPlantGrows(v.landscape.layout, landHeights(v), v.terrain.snowY, v.terrain.rockCos, cx, cz, p, y)) return false;
    root = landRootAt(v, landCellCorner(v, cx, cz), p, y);
    return true;
}

// The map from the camera-relative frame to plant p's geometry frame (for shading a hit on it).
SYLVA_HD inline InstanceRecord landPlantInstance(const RenderView& v, uint32_t cell, uint32_t plant)
{
    const TilePlant& p = v.tilePlants[plant];
    glm::vec3 root(0.0f);
    landPlantRoot(v, cell, p, root);
    const float ik = v.landscape.layout.invTileScale;
    InstanceRecord outer{};
    outer.row[0] = glm::vec4(ik, 0.0f, 0.0f, -root.x * ik);
    outer.row[1] = glm::vec4(0.0f, ik, 0.0f, -root.y * ik);
    outer.row[2] = glm::vec4(0.0f, 0.0f, ik, -root.z * ik);
    outer.scale = v.landscape.layout.tileScale;
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

// A cell's tile frame (tile metres, the cell corner at the origin, t unchanged) and the bounds of its tile's
// boxes there: every node as tall as its plants raised over the ground's range under it (the cell's plane
// within its deviation, clipped to the cell's range, LandCell). Shared by the single-ray and packet walks.
struct LandCellFrame {
    glm::vec3 corner;   // camera-relative
    float ik;           // 1 / tileScale
    float gLo, gHi;     // the cell's ground range (the cell corner lies at the terrain frame's y = 0)
    float p0, px, pz, pe;   // the ground plane y = p0 + px x + pz z within pe

    SYLVA_HD SYLVA_INLINE LandCellFrame(const RenderView& v, const LandCell& c, uint32_t cx, uint32_t cz)
        : corner(landCellCorner(v, cx, cz)), ik(v.landscape.layout.invTileScale), gLo(c.ground.x * ik), gHi(c.ground.y * ik), p0(c.plane.x * ik),
          px(c.plane.y * ik), pz(c.plane.z * ik), pe(c.plane.w * ik)
    {
    }
    // A node's box: its rectangle, its plants' vertical extent raised anywhere in the ground's range under it.
    SYLVA_HD SYLVA_INLINE void nodeBox(const TileNode& n, glm::vec3& lo, glm::vec3& hi) const
    {
        const float x0 = px * n.lox, x1 = px * n.hix, z0 = pz * n.loz, z1 = pz * n.hiz;
        const float l = maxf(p0 + minf(x0, x1) + minf(z0, z1) - pe, gLo), h = minf(p0 + maxf(x0, x1) + maxf(z0, z1) + pe, gHi);
        lo = glm::vec3(n.lox, l + n.ylo, n.loz);
        hi = glm::vec3(n.hix, h + n.yhi, n.hiz);
    }
    // A plant's box raised anywhere in the ground's range at its root (the plane's bound): tested before the
    // height field is read, so most plants of a leaf are rejected without it.
    SYLVA_HD SYLVA_INLINE void plantBox(const TilePlant& p, glm::vec3& lo, glm::vec3& hi) const
    {
        const float g = p0 + px * p.x + pz * p.z, l = maxf(g - pe, gLo), h = minf(g + pe, gHi);
        lo = glm::vec3(p.x + p.lo.x, l + p.lo.y, p.z + p.lo.z);
        hi = glm::vec3(p.x + p.hi.x, h + p.hi.y, p.z + p.hi.z);
    }
};

// The ray's segment in cell (cx, cz)'s column (its rectangle, any height), in the camera-relative frame (o and
// iw = safeReciprocal(d)): t0 and t1 narrowed to it; false when the ray misses the column. A plant that
// crosses a cell's edge has a copy in each cell it reaches (core/terrain/landscape.cpp), so a cell's tile
// answers for its own column only: neighbours compute their common side's t alike, the segment is taken
// half-open ([t0, t1] with t0 excluded by the meshes' t > tmin) and a ray along a side belongs to the cell
// that starts there. Every point of the ray is then the business of one cell (the columns tile the plane), and
// which copy is hit does not depend on the order the cells are visited in.
SYLVA_HD SYLVA_INLINE bool landCellSegment(const RenderView& v, uint32_t cx, uint32_t cz, const glm::vec3& o, const glm::vec3& iw, float& t0, float& t1)
{
    // The border cells' columns reach out beyond the grid, where their plants overhang the terrain's edge.
    const glm::vec3 a = landCellCorner(v, cx, cz), b = landCellCorner(v, cx + 1, cz + 1);
    const float big = 3.0e38f;
    const float x0 = cx == 0 ? -big : a.x, x1 = cx + 1 == v.landscape.layout.cellsX ? big : b.x;
    const float z0 = cz == 0 ? -big : a.z, z1 = cz + 1 == v.landscape.layout.cellsZ ? big : b.z;
    auto axis = [&](float lo, float hi, float org, float inv) {
        if (inv == 1e30f || inv == -1e30f) return lo <= org && org < hi;
        const float ta = (lo - org) * inv, tb = (hi - org) * inv;
        t0 = maxf(t0, minf(ta, tb));
        t1 = minf(t1, maxf(ta, tb));
        return true;
    };
    return axis(x0, x1, o.x, iw.x) && axis(z0, z1, o.z, iw.z) && t0 <= t1;
}

// The distance limit within a cell: the closest hit so far or the column's far side, inclusive.
SYLVA_HD SYLVA_INLINE float landCellLimit(float tmax, float t1) { return minf(tmax, nextafterf(t1, 3.0e38f)); }

// Plant k (tilePlants) of `cell`, rooted at its lifted root: the ray (op: the plant-centred tile frame, dt: the
// tile frame's direction) traced in its mesh. Returns true when an any-hit query found a hit.
template <bool AnyHit, bool Kd>
SYLVA_HD SYLVA_INLINE bool traceLandPlant(Query& q, uint32_t cell, uint32_t k, const TilePlant& p, const glm::vec3& op, const glm::vec3& dt, float& tmax)
{
    InstanceRecord in{};
    in.row[0] = p.row[0];
    in.row[1] = p.row[1];
    in.row[2] = p.row[2];
    const GeometryRecord& geo = q.v.geometries[p.geometry];
    SYLVA_COUNT(g_plantMeshEntries);
    q.path[1] = cell;
    q.path[2] = k;
    return traceMesh<AnyHit, Kd, 2>(q, geo, toLocalPoint(in, op), toLocalDir(in, dt), tmax);
}

// The plants of cell (cx, cz)'s tile along the ray (camera-relative o, d) within [q.tmin, tmax]: the tile's 2D
// tree in the cell's frame (LandCellFrame); each plant reached is lifted onto the ground, thinned, box-tested
// and traced in its mesh. A hit shortens tmax. Returns true when an any-hit query found a hit.
template <bool AnyHit, bool Kd>
SYLVA_HD inline bool traceLandTile(Query& q, uint32_t cell, uint32_t cx, uint32_t cz, const LandCell& c, const TileRecord& tile, const glm::vec3& o,
                                   const glm::vec3& d, float& tmax)
{
    const RenderView& v = q.v;
    const LandCellFrame f(v, c, cx, cz);
    const float ik = f.ik;
    const glm::vec3 ot = (o - f.corner) * ik, dt = d * ik;   // the tile frame (t unchanged)
    const glm::vec3 inv = safeReciprocal(dt);
    auto entry = [&](const TileNode& n) {
        glm::vec3 lo, hi;
        f.nodeBox(n, lo, hi);
        return rayBoxEntry(lo, hi, ot, inv, q.tmin, tmax);
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
                glm::vec3 lo, hi;
                f.plantBox(p, lo, hi);
                if (!(rayBoxEntry(lo, hi, ot, inv, q.tmin, tmax) <= tmax)) continue;
                // Its root on the ground, its box there, and only then whether it grows (density, snow, rock).
                SYLVA_COUNT(g_plantRootReads);
                float y;
                uint32_t tri;
                if (!landPlantHeight(v.landscape.layout, heights, cx, cz, p, y, tri)) continue;
                const glm::vec3 root = landRootAt(v, f.corner, p, y);
                const glm::vec3 op = (o - root) * ik;   // the plant-centred tile frame
                if (!(rayBoxEntry(p.lo, p.hi, op, inv, q.tmin, tmax) <= tmax)) continue;
                if (!landPlantKept(v.landscape.layout, heights, v.terrain.snowY, v.terrain.rockCos, p, y, tri)) continue;
                if (traceLandPlant<AnyHit, Kd>(q, cell, k, p, op, dt, tmax)) return true;
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

// A node of the cells' 2D kd-tree and the cells it covers, [x0, x1) x [z0, z1).
struct LandRange {
    uint32_t node, x0, z0, x1, z1;
};

// The node's box: camera-relative, its ground and tiles' range.
SYLVA_HD SYLVA_INLINE void landNodeBox(const RenderView& v, const LandRange& r, glm::vec3& lo, glm::vec3& hi)
{
    const LandNode& n = v.landNodes[r.node];
    const glm::vec3 a = landCellCorner(v, r.x0, r.z0), b = landCellCorner(v, r.x1, r.z1);
    lo = glm::vec3(a.x, v.landscape.base.y + n.range.x, a.z);
    hi = glm::vec3(b.x, v.landscape.base.y + n.range.y, b.z);
}

// An inner node's children (its longer side halved), the near one first along direction d.
SYLVA_HD SYLVA_INLINE void landChildren(const LandNode& n, const LandRange& r, const glm::vec3& d, LandRange& nearChild, LandRange& farChild)
{
    LandRange a{n.child, r.x0, r.z0, r.x1, r.z1}, b{n.child + 1, r.x0, r.z0, r.x1, r.z1};
    bool farIsLow;
    if (r.x1 - r.x0 >= r.z1 - r.z0) {
        a.x1 = b.x0 = (r.x0 + r.x1) / 2;
        farIsLow = d.x < 0.0f;
    } else {
        a.z1 = b.z0 = (r.z0 + r.z1) / 2;
        farIsLow = d.z < 0.0f;
    }
    nearChild = farIsLow ? b : a;
    farChild = farIsLow ? a : b;
}

// Cell `cell`'s plants along the ray's segment in its column (landCellSegment; iw = safeReciprocal(d)). A hit
// shortens tmax. Returns true when an any-hit query found a hit.
template <bool AnyHit, bool Kd>
SYLVA_HD inline bool traceLandCell(const Query& q, uint32_t cell, const glm::vec3& o, const glm::vec3& d, const glm::vec3& iw, float& tmax)
{
    const RenderView& v = q.v;
    const LandCell c = v.landCells[cell];
    const TileRecord& tile = v.tileRecords[c.tile];
    if (tile.plantCount == 0) return false;
    const uint32_t cx = cell % v.landscape.layout.cellsX, cz = cell / v.landscape.layout.cellsX;
    float t0 = q.tmin, t1 = tmax;
    if (!landCellSegment(v, cx, cz, o, iw, t0, t1)) return false;
    SYLVA_COUNT(g_landCellVisits);
    Query cq{v, t0, q.tAlpha, q.hit, q.kind, {q.path[0], 0, 0}};
    const float limit = landCellLimit(tmax, t1);
    float t = limit;
    const bool stopped = traceLandTile<AnyHit, Kd>(cq, cell, cx, cz, c, tile, o, d, t);
    if (t < limit) tmax = t;   // the column's closest hit is the ray's closest so far
    return stopped;
}

// The landscape's plants along the ray: its cells' 2D kd-tree top-down, near child first, a node skipped
// where the ray passes above or below its range or beyond the closest hit so far.
template <bool AnyHit, bool Kd>
SYLVA_HD inline bool walkLandscape(Query& q, const glm::vec3& o, const glm::vec3& d, float& tmax)
{
    const RenderView& v = q.v;
    const glm::vec3 inv = safeReciprocal(d);
    LandRange stack[96];
    int top = 0;
    stack[top++] = LandRange{0, 0, 0, v.landscape.layout.cellsX, v.landscape.layout.cellsZ};
    while (top > 0) {
        const LandRange e = stack[--top];
        const LandNode& n = v.landNodes[e.node];
        SYLVA_COUNT(g_landNodeVisits);
        glm::vec3 lo, hi;
        landNodeBox(v, e, lo, hi);
        if (!(rayBoxEntry(lo, hi, o, inv, q.tmin, tmax) <= tmax)) continue;
        if (n.child == 0) {
            if (traceLandCell<AnyHit, Kd>(q, e.z0 * v.landscape.layout.cellsX + e.x0, o, d, inv, tmax)) return true;
            continue;
        }
        landChildren(n, e, d, stack[top + 1], stack[top]);   // the far one deferred
        top += 2;
    }
    return false;
}

// The kind's query (Dietrich et al., sections 4.1, 4.2), below the ground's hit.
template <bool AnyHit, bool Kd>
SYLVA_HD inline bool traceLandscape(Query& q, const Ray& ray, float& tmax)
{
    if (!q.v.landscape.enabled) return false;
    q.kind = SurfaceKind::Landscape;
    q.path[0] = kNoHit;
    return walkLandscape<AnyHit, Kd>(q, ray.org, ray.dir, tmax);
}

} // namespace trace_detail

// The kind's surface: the plant's mesh, its LB light scaled by the landscape's forest grid at the point.
SYLVA_HD inline void shadeLandscape(const RenderView& v, const Ray& ray, const Hit& hit, SurfacePoint& s)
{
    const InstanceRecord in = trace_detail::landPlantInstance(v, hit.nested[0], hit.nested[1]);
    const glm::vec3 lp = toLocalPoint(in, ray.org) + hit.t * toLocalDir(in, ray.dir);
    shadeMesh(v, hit, in, lp, s);
    meshIndirect(v, in, lp, landLightFactor(v.landscape.lightLayout, v.landLight, s.p - v.terrain.origin), s);
}

} // namespace sylva
