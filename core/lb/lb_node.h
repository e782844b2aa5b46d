// The per-node LB collision, written once for every backend: T is float (reference, GPU) or a SIMD vector (CPU).
#pragma once

#include "core/base/defines.h"
#include "core/lb/lattice.h"
#include "core/lb/omega.h"

namespace sylva::lb {

// In place: f[m] <- f[m] + rho * (Omega f)[m] for all 19 directions (LB_MODEL.md "Update"), using the
// even/odd split of the scattering part (162 multiply-adds instead of 324). With zeroF0 the rest
// direction is returned as 0 (plants: absorbed light leaves the visible band).
template <typename T>
SYLVA_HD SYLVA_INLINE void collideNode(T (&f)[kDirections], T rho, const CompactOmega& om, bool zeroF0)
{
    T s[kPairs], d[kPairs];
    T moving = T{};
SYLVA_UNROLL
    for (int q = 0; q < kPairs; ++q) {
        s[q] = f[kPairPos[q]] + f[kPairNeg[q]];
        d[q] = f[kPairPos[q]] - f[kPairNeg[q]];
        moving = moving + s[q];
    }
    const T f0 = f[0];
SYLVA_UNROLL
    for (int p = 0; p < kPairs; ++p) {
        T a = s[0] * om.even[p][0];
        T b = d[0] * om.odd[p][0];
SYLVA_UNROLL
        for (int q = 1; q < kPairs; ++q) {
            a = a + s[q] * om.even[p][q];
            b = b + d[q] * om.odd[p][q];
        }
        const float w = p < 3 ? 1.0f / 12.0f : 1.0f / 24.0f;
        const T common = a + f0 * w;
        const int ip = kPairPos[p], in = kPairNeg[p];
        const T outP = common + b - f[ip] * om.sigmaT;
        const T outN = common - b - f[in] * om.sigmaT;
        f[ip] = f[ip] + rho * outP;
        f[in] = f[in] + rho * outN;
    }
    if (zeroF0) f[0] = T{};
    else f[0] = f0 + rho * (moving * om.sigmaA - f0);
}

} // namespace sylva::lb
