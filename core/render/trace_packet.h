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
    // Origins for the first n rays (the others zero); the tile frame's are packed per cell (CellLanes).
    void setOrigins(int n, const glm::vec3* o)
    {
        for (int i = 0; i < kPacketRays; ++i) {
            const glm::vec3 po = i < n ? o[i] : glm::vec3(0.0f);
            ox[i] = po.x, oy[i] = po.y, oz[i] = po.z;
        }
    }
    glm::vec3 org(int i) const { return glm::vec3(ox[i], oy[i], oz[i]); }
    glm::vec3 inv(int i) const { return glm::vec3(ix[i], iy[i], iz[i]); }
};

// The rays of `mask` that enter each of the K boxes [lo[k], hi[k]] within their [tmin, tmax], in out[k]: for
// every ray exactly `rayBoxEntry(...) <= tmax` (the same operations, 8 rays a vector; the rays loaded once for
// all K boxes).
template <int K>
inline void packetBoxMasks(const glm::vec3* lo, const glm::vec3* hi, const PacketFrame& f, const float* tmin, const float* tmax, uint64_t mask,
                           uint64_t* out)
{
    using F8 = detail::FloatVec<8>::type;
    for (int k = 0; k < K; ++k) out[k] = 0;
    // The groups of 8 lanes with a ray of `mask`: bit 8g set where group g has one.
    uint64_t groups = mask | mask >> 4;
    groups |= groups >> 2;
    groups = (groups | groups >> 1) & 0x0101010101010101ull;
    for (; groups != 0; groups &= groups - 1) {
        const int b = __builtin_ctzll(groups);
        const uint32_t bits = uint32_t(mask >> b) & 0xffu;
        const F8 ox = detail::loadVec<F8>(f.ox + b), oy = detail::loadVec<F8>(f.oy + b), oz = detail::loadVec<F8>(f.oz + b);
        const F8 ix = detail::loadVec<F8>(f.ix + b), iy = detail::loadVec<F8>(f.iy + b), iz = detail::loadVec<F8>(f.iz + b);
        const F8 t0 = detail::loadVec<F8>(tmin + b), t1 = detail::loadVec<F8>(tmax + b);
        for (int k = 0; k < K; ++k) {
            const F8 tx0 = (lo[k].x - ox) * ix, tx1 = (hi[k].x - ox) * ix;
            const F8 ty0 = (lo[k].y - oy) * iy, ty1 = (hi[k].y - oy) * iy;
            const F8 tz0 = (lo[k].z - oz) * iz, tz1 = (hi[k].z - oz) * iz;
            using detail::maxVec;
            using detail::minVec;
            const F8 tnear = maxVec(maxVec(minVec(tx0, tx1), minVec(ty0, ty1)), maxVec(minVec(tz0, tz1), t0));
            const F8 tfar = minVec(minVec(maxVec(tx0, tx1), maxVec(ty0, ty1)), minVec(maxVec(tz0, tz1), t1));
            const auto in = tnear <= tfar;
#if defined(__AVX__)
            const uint32_t m = uint32_t(_mm256_movemask_ps(reinterpret_cast<__m256>(in)));
#else
            uint32_t m = 0;
            for (int j = 0; j < 8; ++j) m |= uint32_t(in[j] != 0) << j;
#endif
            out[k] |= uint64_t(m & bits) << b;
        }
    }
    for (uint64_t z = f.zeroAxis & mask; z != 0; z &= z - 1) {
        const int i = __builtin_ctzll(z);
        const uint64_t bit = uint64_t(1) << i;
        for (int k = 0; k < K; ++k)
            out[k] = rayBoxEntry(lo[k], hi[k], f.org(i), f.inv(i), tmin[i], tmax[i]) <= tmax[i] ? out[k] | bit : out[k] & ~bit;
    }
}

// The rays of `mask` that enter box [lo, hi] within their [tmin, tmax] (packetBoxMasks for one box).
inline uint64_t packetBoxMask(const glm::vec3& lo, const glm::vec3& hi, const PacketFrame& f, const float* tmin, const float* tmax, uint64_t mask)
{
    uint64_t out;
    packetBoxMasks<1>(&lo, &hi, f, tmin, tmax, mask, &out);
    return out;
}

// The rays of a packet that reach one cell, packed into the first lanes: their tile frame, each ray's segment
// in the cell's column and the packet lane it stands for. Lanes past `count` up to the next group of 8 are zero.
struct CellLanes {
    PacketFrame f;
    alignas(32) float segMin[kPacketRays], segMax[kPacketRays];
    uint8_t lane[kPacketRays];
    int count = 0;
};

// One packet's walk: the world frame, each ray's limits and hit, and the rays whose any-hit query is answered.
template <bool AnyHit, bool Kd>
struct LandPacket {
    const RenderView& v;
    int n;
    const glm::vec3* o;     // camera-relative origins
    const glm::vec3* d;     // directions
    Hit* hits;
    alignas(32) float tmin[kPacketRays], tmax[kPacketRays], tAlpha[kPacketRays];
    PacketFrame world, tile;   // tile: the directions only (each cell packs its rays' origins, CellLanes)
    glm::vec3 meanDir;      // orders the children (near first for most rays)
    uint64_t done = 0;      // AnyHit: rays occluded

    // Cell `cell`'s plants for the rays of `mask`, each along its segment in the cell's column (traceLandCell for
    // each of them), the rays packed into the first lanes so that few rays test few groups.
    void cell(uint32_t cell, uint64_t mask)
    {
        const LandCell c = v.landCells[cell];
        const TileRecord& tr = v.tileRecords[c.tile];
        if (tr.plantCount == 0) return;
        const uint32_t cx = cell % v.land.cellsX, cz = cell / v.land.cellsX;
        const LandCellFrame f(v, c, cx, cz);
        CellLanes L;
        float limit[kPacketRays];
        int k = 0;
        uint64_t zero = 0;
        for (uint64_t m = mask; m != 0; m &= m - 1) {
            const int i = __builtin_ctzll(m);
            float t0 = tmin[i], t1 = tmax[i];
            if (!landCellSegment(v, cx, cz, o[i], world.inv(i), t0, t1)) continue;
            const glm::vec3 ot = (o[i] - f.corner) * f.ik;   // the tile frame (traceLandTile's)
            L.f.ox[k] = ot.x, L.f.oy[k] = ot.y, L.f.oz[k] = ot.z;
            L.f.ix[k] = tile.ix[i], L.f.iy[k] = tile.iy[i], L.f.iz[k] = tile.iz[i];
            zero |= (tile.zeroAxis >> i & 1u) << k;
            L.segMin[k] = t0;
            L.segMax[k] = limit[k] = landCellLimit(tmax[i], t1);
            L.lane[k++] = uint8_t(i);
        }
        if (k == 0) return;
        SYLVA_COUNT(g_pkCells);
        SYLVA_COUNT_ADD(g_pkCellLanes, k);
        L.count = k;
        L.f.zeroAxis = zero;
        for (int j = k; j < ((k + 7) & ~7); ++j) L.f.ox[j] = L.f.oy[j] = L.f.oz[j] = L.f.ix[j] = L.f.iy[j] = L.f.iz[j] = L.segMin[j] = L.segMax[j] = 0.0f;
        tilePlants(cell, cx, cz, f, tr, L);
        for (int j = 0; j < k; ++j)
            if (L.segMax[j] < limit[j]) tmax[L.lane[j]] = L.segMax[j];   // the column's closest hit is the ray's closest so far
    }

    // The tile's plants for the cell's rays L, each within [segMin, segMax] (traceLandTile for each of them); a hit
    // shortens segMax.
    void tilePlants(uint32_t cell, uint32_t cx, uint32_t cz, const LandCellFrame& f, const TileRecord& tr, CellLanes& L)
    {
        uint32_t stackNode[64];
        uint64_t stackMask[64];
        int top = 0;
        uint32_t node = tr.nodeOffset;
        uint64_t stopped = 0;   // lanes of L whose any-hit query is answered
        uint64_t cur = L.count == kPacketRays ? ~uint64_t(0) : (uint64_t(1) << L.count) - 1;
        {
            glm::vec3 lo, hi;
            f.nodeBox(v.tileNodes[node], lo, hi);
            SYLVA_COUNT(g_pkTileTests);
            SYLVA_COUNT_ADD(g_pkTileLanes, __builtin_popcountll(cur));
            cur = packetBoxMask(lo, hi, L.f, L.segMin, L.segMax, cur);
        }
        const HeightFieldView heights = landHeights(v);
        while (cur != 0) {
            const TileNode& nd = v.tileNodes[node];
            bool descended = false;
            if (nd.count == 0) {
                const TileNode &a = v.tileNodes[nd.first], &b = v.tileNodes[nd.first + 1];
                glm::vec3 lo[2], hi[2];
                f.nodeBox(a, lo[0], hi[0]);
                f.nodeBox(b, lo[1], hi[1]);
                SYLVA_COUNT_ADD(g_pkTileTests, 2);
                SYLVA_COUNT_ADD(g_pkTileLanes, 2 * __builtin_popcountll(cur));
                uint64_t mab[2];
                packetBoxMasks<2>(lo, hi, L.f, L.segMin, L.segMax, cur, mab);
                const uint64_t ma = mab[0], mb = mab[1];
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
                    SYLVA_COUNT(g_pkPlantTests);
                    SYLVA_COUNT_ADD(g_pkPlantLanes, __builtin_popcountll(cur));
                    uint64_t m = packetBoxMask(lo, hi, L.f, L.segMin, L.segMax, cur);
                    if (m == 0) continue;
                    SYLVA_COUNT(g_pkRootReads);
                    float y;
                    uint32_t tri;
                    if (!landPlantHeight(v.land, heights, cx, cz, p, y, tri)) continue;
                    const glm::vec3 root = landRootAt(v, f.corner, p, y);
                    int kept = -1;
                    for (; m != 0; m &= m - 1) {
                        const int j = __builtin_ctzll(m), i = L.lane[j];
                        const glm::vec3 op = (o[i] - root) * f.ik;   // the plant-centred tile frame
                        if (!(rayBoxEntry(p.lo, p.hi, op, L.f.inv(j), L.segMin[j], L.segMax[j]) <= L.segMax[j])) continue;
                        if (kept < 0) kept = landPlantKept(v.land, heights, v.terrainSnowY, v.terrainRockCos, p, y, tri) ? 1 : 0;
                        if (kept == 0) break;
                        Query q{v, L.segMin[j], tAlpha[i], hits[i], {kLandscapeInst, 0, 0}};
                        if (traceLandPlant<AnyHit, Kd>(q, cell, k, p, op, d[i] * f.ik, L.segMax[j])) {
                            done |= uint64_t(1) << i;
                            stopped |= uint64_t(1) << j;
                            cur &= ~(uint64_t(1) << j);
                        }
                    }
                }
            }
            if (descended) continue;
            // The next deferred node with rays still live. It is not tested again: a closer hit found meanwhile
            // rarely culls a whole box (measured: it cost a fifth of the tests), and its children test the new limits.
            cur = 0;
            while (cur == 0 && top > 0) {
                --top;
                node = stackNode[top];
                cur = stackMask[top] & ~stopped;
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
            SYLVA_COUNT(g_pkLandTests);
            SYLVA_COUNT_ADD(g_pkLandLanes, __builtin_popcountll(live));
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
        P.world.setOrigins(n, o);
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
