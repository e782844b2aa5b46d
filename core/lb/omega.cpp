// Omega with the normalized Henyey-Greenstein phase and the |g| = 1 limits.
#include "core/lb/omega.h"

#include <algorithm>
#include <cmath>
#include <initializer_list>
#include <string>
#include <utility>

#include "core/base/error.h"
#include "core/lb/lb_node.h"

namespace sylva::lb {

namespace {

double dotUnit(int i, int j)
{
    const double ni = std::sqrt(double(kC[i][0] * kC[i][0] + kC[i][1] * kC[i][1] + kC[i][2] * kC[i][2]));
    const double nj = std::sqrt(double(kC[j][0] * kC[j][0] + kC[j][1] * kC[j][1] + kC[j][2] * kC[j][2]));
    return double(kC[i][0] * kC[j][0] + kC[i][1] * kC[j][1] + kC[i][2] * kC[j][2]) / (ni * nj);
}

} // namespace

std::array<double, 18 * 18> normalizedPhase(double g)
{
    std::array<double, 18 * 18> pn{};
    for (int j = 1; j <= 18; ++j) {
        // The factor (1 - g^2) of p_ij cancels in the normalization; keep only
        // q_ij = (1 - 2 g mu + g^2)^(-3/2), finite for |g| < 1 even very close to 1.
        double q[19] = {};
        bool singular = false;
        for (int i = 1; i <= 18; ++i) {
            double mu = dotUnit(i, j);
            double base = 1.0 - 2.0 * g * mu + g * g;
            if (!(base > 0.0)) {
                singular = true;   // g = +-1 and c_i (anti)parallel to c_j: the limit case
                break;
            }
            q[i] = std::pow(base, -1.5);
        }
        if (singular) {
            // All scattered mass goes to i with mu = sign(g): w_i pn_ij = 1 there, 0 elsewhere.
            const int target = g > 0 ? j : kOpposite[j];
            pn[size_t((target - 1) * 18 + (j - 1))] = 1.0 / weight(target);
            continue;
        }
        double norm = 0.0;
        for (int i = 1; i <= 18; ++i) norm += (isAxial(i) ? 2.0 : 1.0) * q[i];
        norm /= 24.0;
        for (int i = 1; i <= 18; ++i) pn[size_t((i - 1) * 18 + (j - 1))] = q[i] / norm;
    }
    return pn;
}

DenseOmega buildOmega(const ChannelParams& p)
{
    DenseOmega om{};
    const double sa = p.sigmaA, ss = p.sigmaS, st = sa + ss;
    const auto pn = normalizedPhase(p.g);
    om[0] = -1.0;
    for (int j = 1; j < kDirections; ++j) om[size_t(j)] = sa;
    for (int i = 1; i < kDirections; ++i) {
        om[size_t(i * kDirections)] = weight(i);
        for (int j = 1; j < kDirections; ++j)
            om[size_t(i * kDirections + j)] = ss * weight(i) * pn[size_t((i - 1) * 18 + (j - 1))];
        om[size_t(i * kDirections + i)] -= st;
    }
    return om;
}

namespace {

// The even and odd 9x9 blocks in double (see CompactOmega).
struct Blocks {
    double even[kPairs][kPairs];
    double odd[kPairs][kPairs];
};

Blocks compactBlocks(const ChannelParams& p)
{
    Blocks c{};
    const auto pn = normalizedPhase(p.g);
    auto scatter = [&](int i, int j) { return double(p.sigmaS) * weight(i) * pn[size_t((i - 1) * 18 + (j - 1))]; };
    for (int a = 0; a < kPairs; ++a)
        for (int b = 0; b < kPairs; ++b) {
            const double sp = scatter(kPairPos[a], kPairPos[b]);
            const double sn = scatter(kPairPos[a], kPairNeg[b]);
            c.even[a][b] = 0.5 * (sp + sn);
            c.odd[a][b] = 0.5 * (sp - sn);
        }
    return c;
}

void apply(const double (&m)[kPairs][kPairs], const double (&x)[kPairs], double (&y)[kPairs])
{
    for (int a = 0; a < kPairs; ++a) {
        y[a] = 0.0;
        for (int b = 0; b < kPairs; ++b) y[a] += m[a][b] * x[b];
    }
}

// SymmetricOmega's members in double, for the derivation check.
struct SymmetricOmegaD {
    double ass, asg, bss, bsg, ags, agg, bgs, bgg, dd, oDD, oDV, oVD, oVV, oWW;
};

} // namespace

CompactOmega compactOmega(const ChannelParams& p)
{
    const Blocks b = compactBlocks(p);
    CompactOmega c{};
    for (int i = 0; i < kPairs; ++i)
        for (int j = 0; j < kPairs; ++j) {
            c.even[i][j] = float(b.even[i][j]);
            c.odd[i][j] = float(b.odd[i][j]);
        }
    c.sigmaA = p.sigmaA;
    c.sigmaT = p.sigmaA + p.sigmaS;
    return c;
}

SymmetricOmega symmetricOmega(const ChannelParams& p)
{
    // Pairs (lattice.h): 0-2 axial x, y, z; 3, 4 plane xy (e_x+e_y, e_x-e_y); 5, 6 plane xz (e_x+e_z,
    // e_x-e_z); 7, 8 plane yz (e_y+e_z, e_y-e_z). Each coefficient is read off the blocks' response to one
    // coordinate vector; the check below then compares the whole reduced product with the blocks.
    const Blocks B = compactBlocks(p);
    SymmetricOmegaD o{};
    double x[kPairs], y[kPairs];
    auto unit = [&](std::initializer_list<std::pair<int, double>> entries) {
        for (double& v : x) v = 0.0;
        for (const auto& [q, v] : entries) x[q] = v;
    };
    // Even, input s_x = 1: S = 1. Axial outputs ass + bss (x), bss (y); plane sums ags + bgs (g_x), bgs.
    unit({{0, 1.0}});
    apply(B.even, x, y);
    o.bss = y[1];
    o.ass = y[0] - y[1];
    o.bgs = 0.5 * (y[3] + y[4]);              // g_z: plane xy, halved
    o.ags = 0.5 * (y[7] + y[8]) - o.bgs;      // g_x: plane yz
    // Even, input g_x = 1 (s_7 = s_8 = 1/2): G = 1.
    unit({{7, 0.5}, {8, 0.5}});
    apply(B.even, x, y);
    o.bsg = y[1];
    o.asg = y[0] - y[1];
    o.bgg = 0.5 * (y[3] + y[4]);
    o.agg = 0.5 * (y[7] + y[8]) - o.bgg;
    // Even, input difference of plane yz = 1 (s_7 = 1/2, s_8 = -1/2).
    unit({{7, 0.5}, {8, -0.5}});
    apply(B.even, x, y);
    o.dd = 0.5 * (y[7] - y[8]);
    // Odd, input d_x = 1. Output V_x = (b3 + b4) + (b5 + b6), quartered.
    unit({{0, 1.0}});
    apply(B.odd, x, y);
    o.oDD = y[0];
    o.oVD = 0.25 * (y[3] + y[4] + y[5] + y[6]);
    // Odd, input V_x = 1: d_q = (c_q)_x / 4 on the four diagonals with an x component.
    unit({{3, 0.25}, {4, 0.25}, {5, 0.25}, {6, 0.25}});
    apply(B.odd, x, y);
    o.oDV = y[0];
    o.oVV = 0.25 * (y[3] + y[4] + y[5] + y[6]);
    // Odd, input W_x = 1: +1/4 on plane xy's x-carrying pairs, -1/4 on plane xz's.
    unit({{3, 0.25}, {4, 0.25}, {5, -0.25}, {6, -0.25}});
    apply(B.odd, x, y);
    o.oWW = 0.25 * ((y[3] + y[4]) - (y[5] + y[6]));

    // The reduced products must equal the blocks on every pair vector (a basis suffices: both are linear).
    double scale = 0.0;
    for (int a = 0; a < kPairs; ++a)
        for (int b = 0; b < kPairs; ++b) scale = std::max({scale, std::fabs(B.even[a][b]), std::fabs(B.odd[a][b])});
    for (int q = 0; q < kPairs; ++q) {
        double s[kPairs] = {}, d[kPairs] = {}, ea[kPairs], ob[kPairs], ra[kPairs], rb[kPairs];
        s[q] = 1.0;
        d[q] = 1.0;
        apply(B.even, s, ea);
        apply(B.odd, d, ob);
        symmetricScatter(s, d, 0.0, ra, rb, o);
        for (int a = 0; a < kPairs; ++a)
            if (std::fabs(ra[a] - ea[a]) > 1e-12 * (1.0 + scale) || std::fabs(rb[a] - ob[a]) > 1e-12 * (1.0 + scale))
                throw Error("internal: the symmetric form of Omega does not reproduce its blocks (g = " + std::to_string(p.g) + ")");
    }
    SymmetricOmega r{};
    r.ass = float(o.ass);
    r.asg = float(o.asg);
    r.bss = float(o.bss);
    r.bsg = float(o.bsg);
    r.ags = float(o.ags);
    r.agg = float(o.agg);
    r.bgs = float(o.bgs);
    r.bgg = float(o.bgg);
    r.dd = float(o.dd);
    r.oDD = float(o.oDD);
    r.oDV = float(o.oDV);
    r.oVD = float(o.oVD);
    r.oVV = float(o.oVV);
    r.oWW = float(o.oWW);
    r.sigmaA = p.sigmaA;
    r.sigmaT = p.sigmaA + p.sigmaS;
    return r;
}

} // namespace sylva::lb
