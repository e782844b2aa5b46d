// The collision matrix Omega of the LB lighting model (LB_MODEL.md) and its compact even/odd form for kernels.
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

// Compact form used by the node update (LB_MODEL.md "Cost and structure"): for antipodal pairs
// s_q = f_q+ + f_q-, d_q = f_q+ - f_q-, the scattering part gives out_p+ = (E s)_p + (O d)_p and
// out_p- = (E s)_p - (O d)_p. 9x9 even and odd blocks, plus the absorption terms. 664 bytes.
struct CompactOmega {
    float even[kPairs][kPairs];
    float odd[kPairs][kPairs];
    float sigmaA;
    float sigmaT;
};

CompactOmega compactOmega(const ChannelParams& p);

} // namespace sylva::lb
