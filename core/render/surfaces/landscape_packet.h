// The landscape kind's packet walk (host only): each box of the cell tree, the tile trees and the plants'
// raised boxes tested for all the packet's live rays at once (8 lanes a vector), the height field under a plant
// read once for the packet, and each ray that enters a plant's exact box tracing the plant's mesh alone
// (traceLandscape's answer for every ray; only the order nodes are visited in follows the packet's mean
// direction). Included by core/render/trace_packet.h after the packet machinery it uses.
#pragma once

#if !defined(__CUDACC__)

namespace sylva {

namespace trace_detail {

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
        const uint32_t cx = cell % v.landscape.layout.cellsX, cz = cell / v.landscape.layout.cellsX;
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
                    if (!landPlantHeight(v.landscape.layout, heights, cx, cz, p, y, tri)) continue;
                    const glm::vec3 root = landRootAt(v, f.corner, p, y);
                    int kept = -1;
                    for (; m != 0; m &= m - 1) {
                        const int j = __builtin_ctzll(m), i = L.lane[j];
                        const glm::vec3 op = (o[i] - root) * f.ik;   // the plant-centred tile frame
                        if (!(rayBoxEntry(p.lo, p.hi, op, L.f.inv(j), L.segMin[j], L.segMax[j]) <= L.segMax[j])) continue;
                        if (kept < 0) kept = landPlantKept(v.landscape.layout, heights, v.terrain.snowY, v.terrain.rockCos, p, y, tri) ? 1 : 0;
                        if (kept == 0) break;
                        Query q{v, L.segMin[j], tAlpha[i], hits[i], SurfaceKind::Landscape, {kNoHit, 0, 0}};
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
        stack[top] = LandRange{0, 0, 0, v.landscape.layout.cellsX, v.landscape.layout.cellsZ};
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
                cell(e.z0 * v.landscape.layout.cellsX + e.x0, m);
                continue;
            }
            landChildren(nd, e, meanDir, stack[top + 1], stack[top]);   // the far one deferred
            stackMask[top] = stackMask[top + 1] = m;
            top += 2;
        }
    }
};

// The packet path's walk for the landscape kind (trace_packet.h PacketWalk).
template <>
struct PacketWalk<SurfaceKind::Landscape> {
    static constexpr bool kHas = true;
    template <bool AnyHit, bool Kd>
    static void run(PacketQuery& Q)
    {
        const RenderView& v = Q.v;
        if (!v.landscape.enabled) return;
        glm::vec3 o[kPacketRays], d[kPacketRays];
        LandPacket<AnyHit, Kd> P{v, Q.n, o, d, Q.hits, {}, {}, {}, {}, {}, glm::vec3(0.0f), Q.done};
        uint64_t live = 0;
        for (int i = 0; i < kPacketRays; ++i) {
            P.tmin[i] = P.tmax[i] = P.tAlpha[i] = 0.0f;
            if (i >= Q.n) continue;
            const Ray& r = Q.rays[i];
            o[i] = r.org;
            d[i] = r.dir;
            P.tmin[i] = r.tmin;
            P.tmax[i] = Q.tmax[i];
            P.tAlpha[i] = Q.tAlpha[i];
            if (Q.done >> i & 1u) continue;
            live |= uint64_t(1) << i;
            P.meanDir += r.dir;
        }
        if (live == 0) return;
        P.world.setOrigins(Q.n, o);
        P.world.setDirections(Q.n, d, 1.0f);
        P.tile.setDirections(Q.n, d, v.landscape.layout.invTileScale);
        P.walk(live);
        for (int i = 0; i < Q.n; ++i) Q.tmax[i] = P.tmax[i];
        Q.done = P.done;
    }
};

} // namespace trace_detail

} // namespace sylva

#endif
