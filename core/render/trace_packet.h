// Packets of up to 64 coherent rays (a tile's camera rays, or their shadow rays toward a light) through the
// surface kinds, host only: each kind in the list's order, with its packet walk where it has one (the
// landscape's, surfaces/landscape_packet.h), else ray by ray. Every ray gets the answer traceScene gives it
// alone, so pictures do not depend on the path.
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

// One packet's query over the surface kinds: the rays, each one's hit, closest distance so far and cut-out
// limit, and the rays whose any-hit query is answered.
struct PacketQuery {
    const RenderView& v;
    const Ray* rays;
    int n;
    Hit* hits;
    alignas(32) float tmax[kPacketRays];
    alignas(32) float tAlpha[kPacketRays];
    uint64_t done = 0;

    // A kind without a walk of its own: each ray not yet answered asks it alone.
    template <bool AnyHit, class Trace>
    void perRay(Trace trace)
    {
        for (int i = 0; i < n; ++i) {
            if (done >> i & 1u) continue;
            Query q{v, rays[i].tmin, tAlpha[i], hits[i], SurfaceKind::None, {}};
            if (trace(q, rays[i], tmax[i]) && AnyHit) done |= uint64_t(1) << i;
        }
    }
};

// A surface kind's packet walk where it has one (specialized in its <kind>_packet.h); the others are traced
// ray by ray.
template <SurfaceKind K>
struct PacketWalk {
    static constexpr bool kHas = false;
    template <bool AnyHit, bool Kd>
    static void run(PacketQuery&) {}
};

} // namespace trace_detail

} // namespace sylva

#include "core/render/surfaces/landscape_packet.h"

namespace sylva {

namespace trace_detail {

template <bool AnyHit, bool Kd>
inline void tracePacket(const RenderView& v, const Ray* rays, int n, Hit* hits, bool* found)
{
    PacketQuery Q{v, rays, n, hits, {}, {}, 0};
    for (int i = 0; i < n; ++i) {
        startHit(hits[i]);
        Q.tmax[i] = rays[i].tmax;
        Q.tAlpha[i] = alphaTestLimit(v, rays[i]);
    }
#define SYLVA_X(Kind)                                                                                                    \
    if constexpr (PacketWalk<SurfaceKind::Kind>::kHas)                                                                   \
        PacketWalk<SurfaceKind::Kind>::template run<AnyHit, Kd>(Q);                                                      \
    else                                                                                                                 \
        Q.perRay<AnyHit>([](Query& q, const Ray& r, float& t) { return trace##Kind<AnyHit, Kd>(q, r, t); });
    SYLVA_SURFACE_KINDS(SYLVA_X, SYLVA_KIND_SKIP)
#undef SYLVA_X
    for (int i = 0; i < n; ++i) found[i] = (Q.done >> i & 1u) || (!AnyHit && hits[i].kind != uint16_t(SurfaceKind::None));
}

} // namespace trace_detail

// traceScene for n <= kPacketRays rays at once: found[i] and hits[i] as traceScene<AnyHit>(v, rays[i], hits[i])
// gives them, the surface kinds asked in the list's order for the whole packet (each with its packet walk where
// it has one). Pays where a landscape is traced by coherent rays; other scenes are traced a ray at a time.
template <bool AnyHit>
inline void traceScenePacket(const RenderView& v, const Ray* rays, int n, Hit* hits, bool* found)
{
    if (!v.landscape.enabled || n < 2) {
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
