// The D3Q19 lattice of the LB lighting model: directions, weights, antipodes (docs/LB_MODEL.md "Lattice").
#pragma once

#include "core/base/defines.h"

namespace sylva::lb {

inline constexpr int kDirections = 19;
inline constexpr int kPairs = 9;   // antipodal pairs of the 18 moving directions

// c_m: 0 rest; 1-6 axial (+x,-x,+y,-y,+z,-z); 7-18 face diagonals.
inline constexpr int kC[kDirections][3] = {
    {0, 0, 0},
    {1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1},
    {1, 1, 0}, {1, -1, 0}, {-1, 1, 0}, {-1, -1, 0},
    {1, 0, 1}, {1, 0, -1}, {-1, 0, 1}, {-1, 0, -1},
    {0, 1, 1}, {0, 1, -1}, {0, -1, 1}, {0, -1, -1},
};

// Opposite direction of each m (c_opp = -c_m).
inline constexpr int kOpposite[kDirections] = {0, 2, 1, 4, 3, 6, 5, 10, 9, 8, 7, 14, 13, 12, 11, 18, 17, 16, 15};

// Antipodal pairs (positive member, negative member); pairs 0-2 axial, 3-8 diagonal.
inline constexpr int kPairPos[kPairs] = {1, 3, 5, 7, 8, 11, 12, 15, 16};
inline constexpr int kPairNeg[kPairs] = {2, 4, 6, 10, 9, 14, 13, 18, 17};

// The same pairs as functions: usable in device code (nvcc does not allow host constexpr arrays there);
// with a constant q (unrolled loops) they fold to a constant.
SYLVA_HD constexpr int pairPos(int q)
{
    switch (q) {
    case 0: return 1;
    case 1: return 3;
    case 2: return 5;
    case 3: return 7;
    case 4: return 8;
    case 5: return 11;
    case 6: return 12;
    case 7: return 15;
    default: return 16;
    }
}
SYLVA_HD constexpr int pairNeg(int q)
{
    switch (q) {
    case 0: return 2;
    case 1: return 4;
    case 2: return 6;
    case 3: return 10;
    case 4: return 9;
    case 5: return 14;
    case 6: return 13;
    case 7: return 18;
    default: return 17;
    }
}

// w_m: 0 for rest (handled by row/column 0 of Omega), 1/12 axial, 1/24 diagonal.
SYLVA_HD constexpr double weight(int m) { return m == 0 ? 0.0 : (m <= 6 ? 1.0 / 12.0 : 1.0 / 24.0); }
SYLVA_HD constexpr bool isAxial(int m) { return m >= 1 && m <= 6; }

} // namespace sylva::lb
