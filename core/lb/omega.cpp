// Omega with the normalized Henyey-Greenstein phase and the |g| = 1 limits.
#include "core/lb/omega.h"

#include <cmath>

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

CompactOmega compactOmega(const ChannelParams& p)
{
    CompactOmega c{};
    const auto pn = normalizedPhase(p.g);
    auto scatter = [&](int i, int j) { return double(p.sigmaS) * weight(i) * pn[size_t((i - 1) * 18 + (j - 1))]; };
    for (int a = 0; a < kPairs; ++a)
        for (int b = 0; b < kPairs; ++b) {
            const double sp = scatter(kPairPos[a], kPairPos[b]);
            const double sn = scatter(kPairPos[a], kPairNeg[b]);
            c.even[a][b] = float(0.5 * (sp + sn));
            c.odd[a][b] = float(0.5 * (sp - sn));
        }
    c.sigmaA = p.sigmaA;
    c.sigmaT = p.sigmaA + p.sigmaS;
    return c;
}

} // namespace sylva::lb
