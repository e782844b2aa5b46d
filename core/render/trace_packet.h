// Packets of up to 64 coherent rays (a tile's camera rays, or their shadow rays toward the sun) through the
// landscape's levels, host only: each box of the cell tree, the tile trees and the plants' raised boxes is
// tested for all the packet's live rays at once (8 lanes a vector), the height field under a plant is read
// once for the packet, and each ray that enters a plant's exact box traces the plant's mesh alone. Every
// ray gets the answer traceScene gives it alone (the same boxes tested against its own closest hit; only
// the order nodes are visited in follows the packet's mean direction), so pictures do not depend on the path.
#pragma once

#include "core/render/trace.h"

#if !defined(__CUDACC__)

#include <cstdint>
#if defined(__AVX__)
#include <immintrin.h>
#endif

namespace sylva {

inline constexpr int kPacketRays = 64;

namespace trace_detail {

// A packet's rays in one frame, a component an array: origins and reciprocal directions, each ray's limits.
struct PacketFrame {
    alignas(32) float ox[kPacketRays], oy[kPacketRays], oz[kPacketRays];
    alignas(32) float ix[kPacketRays], iy[kPacketRays], iz[kPacketRays];
    uint64_t zeroAxis = 0;   // rays with a zero direction component: box-tested one by one (rayBoxEntry's rule)

    // Reciprocal directions d * scale for the first n rays (the others zero): once for a packet in a frame's
    // scale (the tile frames of all cells share theirs).
    void setDirections(int n, const glm::vec3* d, float scale)
    {
        zeroAxis = 0;
        for (int i = 0; i < kPacketRays; ++i) {
            const glm::vec3 inv = i < n ? safeReciprocal(d[i] * scale) : glm::vec3(0.0f);
            ix[i] = inv.x, iy[i] = inv.y, iz[i] = inv.z;
            if (i < n && (fabsf(inv.x) == 1e30f || fabsf(inv.y) == 1e30f || fabsf(inv.z) == 1e30f)) zeroAxis |= uint64_t(1) << i;
        }
    }
    // Origins (o - base) * scale for the first n rays (the others zero).
    void setOrigins(int n, const glm::vec3* o, const glm::vec3& base, float scale)
    {
        for (int i = 0; i < kPacketRays; ++i) {
            const glm::vec3 po = i < n ? (o[i] - base) * scale : glm::vec3(0.0f);
            ox[i] = po.x, oy[i] = po.y, oz[i] = po.z;
        }
    }
    glm::vec3 org(int i) const { return glm::vec3(ox[i], oy[i], oz[i]); }
    glm::vec3 inv(int i) const { return glm::vec3(ix[i], iy[i], iz[i]); }
};

// The rays of `mask` that enter box [lo, hi] within their [tmin, tmax]: for every ray exactly
// `rayBoxEntry(...) <= tmax` (the same operations, 8 rays a vector).
inline uint64_t packetBoxMask(const glm::vec3& lo, const glm::vec3& hi, const PacketFrame& f, const float* tmin, const float* tmax, uint64_t mask)
{
    using F8 = detail::FloatVec<8>::type;
    uint64_t out = 0;
    for (int g = 0; g < kPacketRays / 8; ++g) {
        const uint32_t bits = uint32_t(mask >> (8 * g)) & 0xffu;
        if (bits == 0) continue;
        const int b = 8 * g;
        const F8 ox = detail::loadVec<F8>(f.ox + b), oy = detail::loadVec<F8>(f.oy + b), oz = detail::loadVec<F8>(f.oz + b);
        const F8 ix = detail::loadVec<F8>(f.ix + b), iy = detail::loadVec<F8>(f.iy + b), iz = detail::loadVec<F8>(f.iz + b);
        const F8 tx0 = (lo.x - ox) * ix, tx1 = (hi.x - ox) * ix;
        const F8 ty0 = (lo.y - oy) * iy, ty1 = (hi.y - oy) * iy;
        const F8 tz0 = (lo.z - oz) * iz, tz1 = (hi.z - oz) * iz;
        using detail::maxVec;
        using detail::minVec;
        const F8 tnear = maxVec(maxVec(minVec(tx0, tx1), minVec(ty0, ty1)), maxVec(minVec(tz0, tz1), detail::loadVec<F8>(tmin + b)));
        const F8 tfar = minVec(minVec(maxVec(tx0, tx1), maxVec(ty0, ty1)), minVec(maxVec(tz0, tz1), detail::loadVec<F8>(tmax + b)));
        const auto in = tnear <= tfar;
#if defined(__AVX__)
        const uint32_t m = uint32_t(_mm256_movemask_ps(reinterpret_cast<__m256>(in)));
#else
        uint32_t m = 0;
        for (int k = 0; k < 8; ++k) m |= uint32_t(in[k] != 0) << k;
#endif
        out |= uint64_t(m & bits) << b;
    }
    for (uint64_t z = f.zeroAxis & mask; z != 0; z &= z - 1) {
        const int i = __builtin_ctzll(z);
        const uint64_t bit = uint64_t(1) << i;
        out = rayBoxEntry(lo, hi, f.org(i), f.inv(i), tmin[i], tmax[i]) <= tmax[i] ? out | bit : out & ~bit;
    }
    return out;
}

// One packet's walk: the world frame, each ray's limits and hit, and the rays whose any-hit query is answered.
template <bool AnyHit, bool Kd>
struct LandPacket {
    const RenderView& v;
    int n;
    const glm::vec3* o;     // camera-relative origins
    const glm::vec3* d;     // directions
    Hit* hits;
    alignas(32) float tmin[kPacketRays], tmax[kPacketRays], tAlpha[kPacketRays];
    PacketFrame world, tile;
    glm::vec3 meanDir;      // orders the children (near first for most rays)
    uint64_t done = 0;      // AnyHit: rays occluded

    // Cell `cell`'s plants for the rays of `mask`, each along its segment in the cell's column (traceLandCell for
    // each of them).
    void cell(uint32_t cell, uint64_t mask)
    {
        const LandCell c = v.landCells[cell];
        const TileRecord& tr = v.tileRecords[c.tile];
        if (tr.plantCount == 0) return;
        const uint32_t cx = cell % v.land.cellsX, cz = cell / v.land.cellsX;
        alignas(32) float cmin[kPacketRays] = {}, cmax[kPacketRays] = {};
        float limit[kPacketRays];
        uint64_t live = 0;
        for (uint64_t m = mask; m != 0; m &= m - 1) {
            const int i = __builtin_ctzll(m);
            float t0 = tmin[i], t1 = tmax[i];
            if (!landCellSegment(v, cx, cz, o[i], world.inv(i), t0, t1)) continue;
            cmin[i] = t0;
            cmax[i] = limit[i] = landCellLimit(tmax[i], t1);
            live |= uint64_t(1) << i;
        }
        if (live == 0) return;
        tilePlants(cell, cx, cz, c, tr, live, cmin, cmax);
        for (uint64_t m = live; m != 0; m &= m - 1) {
            const int i = __builtin_ctzll(m);
            if (cmax[i] < limit[i]) tmax[i] = cmax[i];   // the column's closest hit is the ray's closest so far
        }
    }

    // The tile's plants for the rays of `mask` within [segMin, segMax] (traceLandTile for each of them); a hit
    // shortens segMax.
    void tilePlants(uint32_t cell, uint32_t cx, uint32_t cz, const LandCell& c, const TileRecord& tr, uint64_t mask, const float* segMin,
                    float* segMax)
    {
        const LandCellFrame f(v, c, cx, cz);
        tile.setOrigins(n, o, f.corner, f.ik);   // its directions: set once (tracePacket)
        auto test = [&](const TileNode& node, uint64_t m) {
            glm::vec3 lo, hi;
            f.nodeBox(node, lo, hi);
            return packetBoxMask(lo, hi, tile, segMin, segMax, m);
        };
        uint32_t stackNode[64];
        uint64_t stackMask[64];
        int top = 0;
        uint32_t node = tr.nodeOffset;
        uint64_t cur = test(v.tileNodes[node], mask);
        const HeightFieldView heights = landHeights(v);
        while (cur != 0) {
            const TileNode& nd = v.tileNodes[node];
            bool descended = false;
            if (nd.count == 0) {
                const TileNode &a = v.tileNodes[nd.first], &b = v.tileNodes[nd.first + 1];
                const uint64_t ma = test(a, cur), mb = test(b, cur);
                if (ma != 0 && mb != 0) {
                    // The child whose centre lies behind along the packet's direction first.
                    const bool aFirst = (b.lox + b.hix - a.lox - a.hix) * meanDir.x + (b.loz + b.hiz - a.loz - a.hiz) * meanDir.z >= 0.0f;
                    SYLVA_KERNEL_ASSERT(top < 64);
                    stackNode[top] = aFirst ? nd.first + 1 : nd.first;
                    stackMask[top] = aFirst ? mb : ma;
                    ++top;
                    node = aFirst ? nd.first : nd.first + 1;
                    cur = aFirst ? ma : mb;
                    descended = true;
                } else if (ma != 0 || mb != 0) {
                    node = ma != 0 ? nd.first : nd.first + 1;
                    cur = ma | mb;
                    descended = true;
                }
            } else {
                for (uint32_t k = nd.first; k < nd.first + nd.count && cur != 0; ++k) {
                    const TilePlant& p = v.tilePlants[k];
                    glm::vec3 lo, hi;
                    f.plantBox(p, lo, hi);
                    uint64_t m = packetBoxMask(lo, hi, tile, segMin, segMax, cur);
                    if (m == 0) continue;
                    float y;
                    uint32_t tri;
                    if (!landPlantHeight(v.land, heights, cx, cz, p, y, tri)) continue;
                    const glm::vec3 root = landRootAt(v, f.corner, p, y);
                    int kept = -1;
                    for (; m != 0; m &= m - 1) {
                        const int i = __builtin_ctzll(m);
                        const glm::vec3 op = (o[i] - root) * f.ik;   // the plant-centred tile frame
                        if (!(rayBoxEntry(p.lo, p.hi, op, tile.inv(i), segMin[i], segMax[i]) <= segMax[i])) continue;
                        if (kept < 0) kept = landPlantKept(v.land, heights, v.terrainSnowY, v.terrainRockCos, p, y, tri) ? 1 : 0;
                        if (kept == 0) break;
                        Query q{v, segMin[i], tAlpha[i], hits[i], {kLandscapeInst, 0, 0}};
                        if (traceLandPlant<AnyHit, Kd>(q, cell, k, p, op, d[i] * f.ik, segMax[i])) {
                            done |= uint64_t(1) << i;
                            cur &= ~(uint64_t(1) << i);
                        }
                    }
                }
            }
            if (descended) continue;
            // The next deferred node with rays still in reach of it.
            cur = 0;
            while (cur == 0 && top > 0) {
                --top;
                node = stackNode[top];
                cur = stackMask[top] & ~done;
                if (cur != 0) cur = test(v.tileNodes[node], cur);
            }
        }
    }

    // The cell tree, top-down, near child first along the packet's direction (traceLandscape for each ray).
    void walk(uint64_t active)
    {
        LandRange stack[96];
        uint64_t stackMask[96];
        int top = 0;
        stack[top] = LandRange{0, 0, 0, v.land.cellsX, v.land.cellsZ};
        stackMask[top++] = active;
        while (top > 0) {
            --top;
            const LandRange e = stack[top];
            const uint64_t live = stackMask[top] & ~done;
            if (live == 0) continue;
            const LandNode& nd = v.landNodes[e.node];
            glm::vec3 lo, hi;
            landNodeBox(v, e, lo, hi);
            const uint64_t m = packetBoxMask(lo, hi, world, tmin, tmax, live);
            if (m == 0) continue;
            if (nd.child == 0) {
                cell(e.z0 * v.land.cellsX + e.x0, m);
                continue;
            }
            landChildren(nd, e, meanDir, stack[top + 1], stack[top]);   // the far one deferred
            stackMask[top] = stackMask[top + 1] = m;
            top += 2;
        }
    }
};

template <bool AnyHit, bool Kd>
inline void tracePacket(const RenderView& v, const Ray* rays, int n, Hit* hits, bool* found)
{
    glm::vec3 o[kPacketRays], d[kPacketRays];
    LandPacket<AnyHit, Kd> P{v, n, o, d, hits, {}, {}, {}, {}, {}, glm::vec3(0.0f), 0};
    uint64_t live = 0;
    for (int i = 0; i < kPacketRays; ++i) {
        P.tmin[i] = P.tmax[i] = P.tAlpha[i] = 0.0f;
        if (i >= n) continue;
        const Ray& r = rays[i];
        o[i] = r.org;
        d[i] = r.dir;
        P.tmin[i] = r.tmin;
        P.tAlpha[i] = alphaTestLimit(v, r);
        if (traceGround<AnyHit>(v, r, hits[i], P.tmax[i])) {
            found[i] = true;
            P.done |= uint64_t(1) << i;
            continue;
        }
        live |= uint64_t(1) << i;
        P.meanDir += r.dir;
    }
    if (live != 0) {
        P.world.setOrigins(n, o, glm::vec3(0.0f), 1.0f);
        P.world.setDirections(n, d, 1.0f);
        P.tile.setDirections(n, d, v.land.invTileScale);
        P.walk(live);
    }
    for (int i = 0; i < n; ++i) {
        if (P.done >> i & 1u) {
            found[i] = true;
            continue;
        }
        found[i] = traceTopLevel<AnyHit, Kd>(v, rays[i], hits[i], P.tmax[i]);
    }
}

} // namespace trace_detail

// traceScene for n <= kPacketRays rays at once: found[i] and hits[i] as traceScene<AnyHit>(v, rays[i], hits[i])
// gives them. Pays where a landscape is traced by coherent rays; other scenes are traced a ray at a time.
template <bool AnyHit>
inline void traceScenePacket(const RenderView& v, const Ray* rays, int n, Hit* hits, bool* found)
{
    if (!v.landscapeEnabled || n < 2) {
        for (int i = 0; i < n; ++i) found[i] = traceScene<AnyHit>(v, rays[i], hits[i]);
        return;
    }
    for (int b = 0; b < n; b += kPacketRays) {
        const int m = n - b < kPacketRays ? n - b : kPacketRays;
        if (v.accel == AccelKind::KdTree) trace_detail::tracePacket<AnyHit, true>(v, rays + b, m, hits + b, found + b);
        else trace_detail::tracePacket<AnyHit, false>(v, rays + b, m, hits + b, found + b);
    }
}

} // namespace sylva

#endif
