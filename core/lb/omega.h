// The collision matrix Omega of the LB lighting model (docs/LB_MODEL.md) and its compact even/odd form for kernels.
#pragma once

#include <array>

#include "core/lb/lattice.h"

namespace sylva::lb {

// One channel's optical parameters (per lattice step; sigma_t = sigma_a + sigma_s).
struct ChannelParams {
    float sigmaA = 0.0f;
    float sigmaS = 0.0f;
    float g = 0.0f;   // Henyey-Greenstein asymmetry in [-1,1]
};

// Dense 19x19 Omega in double, row-major: omega[i*19 + j] scatters from c_j into c_i.
using DenseOmega = std::array<double, kDirections * kDirections>;

// Normalized discrete HG phase pn_ij(g) for i,j in 1..18 (row-major 18x18 at [(i-1)*18 + (j-1)]).
// |g| = 1 is its limit: all mass to the parallel (g=1) or antiparallel (g=-1) direction.
std::array<double, 18 * 18> normalizedPhase(double g);

DenseOmega buildOmega(const ChannelParams& p);

// Compact form used by the node update (docs/LB_MODEL.md "Cost and structure"): for antipodal pairs
// s_q = f_q+ + f_q-, d_q = f_q+ - f_q-, the scattering part gives out_p+ = (E s)_p + (O d)_p and
// out_p- = (E s)_p - (O d)_p. 9x9 even and odd blocks, plus the absorption terms. 664 bytes.
struct CompactOmega {
    float even[kPairs][kPairs];
    float odd[kPairs][kPairs];
    float sigmaA;
    float sigmaT;
};

CompactOmega compactOmega(const ChannelParams& p);

// The even and odd blocks reduced by the octahedral symmetry of the lattice (docs/LB_MODEL.md "Cost and
// structure"): both commute with every rotation and reflection of the cube, so in coordinates adapted
// to it they fall apart into tiny blocks (Schur's lemma), 14 coefficients in all.
// Even part, from the pair sums s_q: the axial sums s_x, s_y, s_z; the sums of the two diagonal pairs
// of each coordinate plane, indexed by the plane's normal axis (g_x = plane yz ...); their differences.
// Axial outputs are ass s_k + asg g_k + (bss S + bsg G) with S, G the totals of s and g; the plane
// sums go out the same way (ags, agg, bgs, bgg) and each difference is scaled by dd alone.
// Odd part, from the pair differences d_q: the axial d_k; per axis k the sum V_k and difference W_k
// of the k-components carried by the diagonal pairs of the two planes containing k. (d_k, V_k) mix
// through one 2x2 block, W_k is scaled by oWW. The factors 1/2 and 1/4 that map plane and diagonal
// coordinates back to pairs are folded into the coefficients. 75 arithmetic operations per node and
// channel instead of the 162 multiply-adds of the even/odd blocks.
struct SymmetricOmega {
    float ass, asg, bss, bsg;   // even: axial outputs
    float ags, agg, bgs, bgg;   // even: plane-sum outputs (halved)
    float dd;                   // even: plane differences (halved)
    float oDD, oDV;             // odd: axial outputs
    float oVD, oVV, oWW;        // odd: diagonal outputs (quartered)
    float sigmaA;
    float sigmaT;
};

// Throws if the blocks do not reproduce compactOmega's to double rounding (they always do for a
// symmetric phase; the check guards the derivation).
SymmetricOmega symmetricOmega(const ChannelParams& p);

} // namespace sylva::lb
