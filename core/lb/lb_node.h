// The per-node LB collision, written once for every backend: T is float (reference, GPU) or a SIMD vector (CPU).
#pragma once

#include "core/base/defines.h"
#include "core/lb/lattice.h"
#include "core/lb/omega.h"

namespace sylva::lb {

// The scattering part of the collision on the antipodal pairs (SymmetricOmega): a = E s, b = O d
// for the pair sums s_q = f_q+ + f_q- and differences d_q = f_q+ - f_q-, through the octahedral
// coordinates (axial, plane sums and differences; axial, V and W) instead of two 9x9 products.
// T is float, double or a SIMD vector; Om has SymmetricOmega's coefficient members (float, double,
// or broadcast vectors so that no broadcast sits in the CPU's inner loop).
// The rest direction's isotropic re-emission, w_p f0 (1/12 axial, 1/24 diagonal), is added to a in
// the two shared terms.
template <typename T, typename Om>
SYLVA_HD SYLVA_INLINE void symmetricScatter(const T (&s)[kPairs], const T (&d)[kPairs], T f0, T (&a)[kPairs], T (&b)[kPairs],
                                            const Om& om)
{
    // Even: plane sums by normal axis (x: plane yz = pairs 7, 8; y: xz = 5, 6; z: xy = 3, 4).
    const T gx = s[7] + s[8], gy = s[5] + s[6], gz = s[3] + s[4];
    const T S = s[0] + s[1] + s[2], G = gx + gy + gz;
    const T ts = S * om.bss + G * om.bsg + f0 * (1.0f / 12.0f);
    const T tg = S * om.bgs + G * om.bgg + f0 * (1.0f / 24.0f);
    a[0] = ts + s[0] * om.ass + gx * om.asg;
    a[1] = ts + s[1] * om.ass + gy * om.asg;
    a[2] = ts + s[2] * om.ass + gz * om.asg;
    const T hx = tg + s[0] * om.ags + gx * om.agg;
    const T hy = tg + s[1] * om.ags + gy * om.agg;
    const T hz = tg + s[2] * om.ags + gz * om.agg;
    const T exy = (s[3] - s[4]) * om.dd, exz = (s[5] - s[6]) * om.dd, eyz = (s[7] - s[8]) * om.dd;
    a[3] = hz + exy;
    a[4] = hz - exy;
    a[5] = hy + exz;
    a[6] = hy - exz;
    a[7] = hx + eyz;
    a[8] = hx - eyz;
    // Odd: the axis components carried by each plane's two diagonals, then V and W per axis.
    const T cxyX = d[3] + d[4], cxyY = d[3] - d[4];
    const T cxzX = d[5] + d[6], cxzZ = d[5] - d[6];
    const T cyzY = d[7] + d[8], cyzZ = d[7] - d[8];
    const T vx = cxyX + cxzX, wx = cxyX - cxzX;
    const T vy = cxyY + cyzY, wy = cxyY - cyzY;
    const T vz = cxzZ + cyzZ, wz = cxzZ - cyzZ;
    b[0] = d[0] * om.oDD + vx * om.oDV;
    b[1] = d[1] * om.oDD + vy * om.oDV;
    b[2] = d[2] * om.oDD + vz * om.oDV;
    const T ovx = d[0] * om.oVD + vx * om.oVV, owx = wx * om.oWW;
    const T ovy = d[1] * om.oVD + vy * om.oVV, owy = wy * om.oWW;
    const T ovz = d[2] * om.oVD + vz * om.oVV, owz = wz * om.oWW;
    const T pxyX = ovx + owx, pxzX = ovx - owx;
    const T pxyY = ovy + owy, pyzY = ovy - owy;
    const T pxzZ = ovz + owz, pyzZ = ovz - owz;
    b[3] = pxyX + pxyY;
    b[4] = pxyX - pxyY;
    b[5] = pxzX + pxzZ;
    b[6] = pxzX - pxzZ;
    b[7] = pyzY + pyzZ;
    b[8] = pyzY - pyzZ;
}

// max(x, 0) for a scalar or a SIMD vector. A backend whose vector type has a one-instruction maximum
// specializes it (the CPU solver: vmaxps); the generic compare-and-select costs two.
template <typename T>
struct Lanes {
    static SYLVA_HD SYLVA_INLINE T nonNegative(T x) { return x > T{} ? x : T{}; }
};

// In place: f[m] <- f[m] + rho * (Omega f)[m] for all 19 directions (docs/LB_MODEL.md "Update"), the
// scattering part through symmetricScatter. With zeroF0 the rest direction is returned as 0 (plants:
// absorbed light leaves the visible band). The exact result is never negative (docs/LB_MODEL.md
// "Stability"), but the reduced products cancel terms, so where it is 0 rounding can leave a few ulps
// below; those are clamped to 0, which is within the same rounding of the exact value.
template <typename T, typename Om>
SYLVA_HD SYLVA_INLINE void collideNode(T (&f)[kDirections], T rho, const Om& om, bool zeroF0)
{
    T s[kPairs], d[kPairs], a[kPairs], b[kPairs];
    SYLVA_UNROLL
    for (int q = 0; q < kPairs; ++q) {
        s[q] = f[pairPos(q)] + f[pairNeg(q)];
        d[q] = f[pairPos(q)] - f[pairNeg(q)];
    }
    T moving = s[0];
    SYLVA_UNROLL
    for (int q = 1; q < kPairs; ++q) moving = moving + s[q];
    const T f0 = f[0];
    symmetricScatter(s, d, f0, a, b, om);
    SYLVA_UNROLL
    for (int p = 0; p < kPairs; ++p) {
        const int ip = pairPos(p), in = pairNeg(p);
        f[ip] = Lanes<T>::nonNegative(f[ip] + rho * (a[p] + b[p] - f[ip] * om.sigmaT));
        f[in] = Lanes<T>::nonNegative(f[in] + rho * (a[p] - b[p] - f[in] * om.sigmaT));
    }
    if (zeroF0) f[0] = T{};
    else f[0] = f0 + rho * (moving * om.sigmaA - f0);
}

} // namespace sylva::lb
