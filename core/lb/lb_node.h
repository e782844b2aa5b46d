// The per-node LB collision, written once for every backend: T is float (reference, GPU) or a SIMD vector (CPU).
#pragma once

#include "core/base/defines.h"
#include "core/lb/lattice.h"
#include "core/lb/omega.h"

namespace sylva::lb {

// In place: f[m] <- f[m] + rho * (Omega f)[m] for all 19 directions (LB_MODEL.md "Update"), using the
// even/odd split of the scattering part (162 multiply-adds instead of 324). With zeroF0 the rest
// direction is returned as 0 (plants: absorbed light leaves the visible band).
// Om is CompactOmega (float coefficients) or a layout with the same members whose even/odd entries
// are already broadcast to T (the CPU passes 8-wide vectors so no broadcast sits in the inner loop).
// The products run as outer products over q so that the nine accumulators stay in registers.
template <typename T, typename Om>
SYLVA_HD SYLVA_INLINE void collideNode(T (&f)[kDirections], T rho, const Om& om, bool zeroF0)
{
    T s[kPairs], a[kPairs], b[kPairs];
    T moving = T{};
    SYLVA_UNROLL
    for (int q = 0; q < kPairs; ++q) {
        s[q] = f[pairPos(q)] + f[pairNeg(q)];
        moving = moving + s[q];
    }
    SYLVA_UNROLL
    for (int p = 0; p < kPairs; ++p) a[p] = s[0] * om.even[p][0];
    SYLVA_UNROLL
    for (int q = 1; q < kPairs; ++q) {
        SYLVA_UNROLL
        for (int p = 0; p < kPairs; ++p) a[p] = a[p] + s[q] * om.even[p][q];
    }
    SYLVA_UNROLL
    for (int q = 0; q < kPairs; ++q) s[q] = f[pairPos(q)] - f[pairNeg(q)];   // s now holds the differences d
    SYLVA_UNROLL
    for (int p = 0; p < kPairs; ++p) b[p] = s[0] * om.odd[p][0];
    SYLVA_UNROLL
    for (int q = 1; q < kPairs; ++q) {
        SYLVA_UNROLL
        for (int p = 0; p < kPairs; ++p) b[p] = b[p] + s[q] * om.odd[p][q];
    }
    const T f0 = f[0];
    SYLVA_UNROLL
    for (int p = 0; p < kPairs; ++p) {
        const float w = p < 3 ? 1.0f / 12.0f : 1.0f / 24.0f;
        const T common = a[p] + f0 * w;
        const int ip = pairPos(p), in = pairNeg(p);
        f[ip] = f[ip] + rho * (common + b[p] - f[ip] * om.sigmaT);
        f[in] = f[in] + rho * (common - b[p] - f[in] * om.sigmaT);
    }
    if (zeroF0) f[0] = T{};
    else f[0] = f0 + rho * (moving * om.sigmaA - f0);
}

} // namespace sylva::lb
