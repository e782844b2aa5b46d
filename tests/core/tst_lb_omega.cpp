// Omega: mass conservation, the isotropic matrix of Geist & Steele, "A Lighting Model for Fast Rendering of
// Forest Ecosystems", eqs. (5)-(7), the null vector of the appendix of Geist & Westall, "Lattice-Boltzmann
// Lighting Models", pass-through, the |g| -> 1 limit.
#include <QTest>

#include <cmath>
#include <random>

#include "core/lb/lattice.h"
#include "core/lb/lb_node.h"
#include "core/lb/omega.h"

using namespace sylva::lb;

namespace {

double at(const DenseOmega& om, int i, int j) { return om[size_t(i * kDirections + j)]; }

// Geist & Steele's discrete HG phase, written out independently: p_ij with the (1 - g^2) factor, normalized per
// column.
double seedPhase(double g, int i, int j)
{
    auto unit = [](int m) {
        double n = std::sqrt(double(kC[m][0] * kC[m][0] + kC[m][1] * kC[m][1] + kC[m][2] * kC[m][2]));
        return std::array<double, 3>{kC[m][0] / n, kC[m][1] / n, kC[m][2] / n};
    };
    auto p = [&](int a, int b) {
        auto na = unit(a), nb = unit(b);
        double mu = na[0] * nb[0] + na[1] * nb[1] + na[2] * nb[2];
        return (1 - g * g) / std::pow(1 - 2 * g * mu + g * g, 1.5);
    };
    double norm = 0;
    for (int a = 1; a <= 6; ++a) norm += 2 * p(a, j);
    for (int a = 7; a <= 18; ++a) norm += p(a, j);
    return p(i, j) / (norm / 24);
}

} // namespace

class TestLbOmega : public QObject {
    Q_OBJECT
private Q_SLOTS:
    void columnsSumToZero()
    {
        std::mt19937 rng(7);
        std::uniform_real_distribution<float> u(0.0f, 1.0f);
        const float gs[] = {-1.0f, -0.999999f, 0.0f, 0.999999f, 1.0f};
        for (int trial = 0; trial < 200; ++trial) {
            ChannelParams p;
            p.sigmaA = u(rng) * 0.5f;
            p.sigmaS = u(rng) * (1.0f - p.sigmaA);
            p.g = trial < 5 ? gs[trial] : 2.0f * u(rng) - 1.0f;
            const DenseOmega om = buildOmega(p);
            for (int j = 0; j < kDirections; ++j) {
                double sum = 0;
                for (int i = 0; i < kDirections; ++i) {
                    QVERIFY(std::isfinite(at(om, i, j)));
                    sum += at(om, i, j);
                }
                QVERIFY2(std::fabs(sum) < 1e-12, qPrintable(QString("column %1 sums to %2 (g=%3)").arg(j).arg(sum).arg(p.g)));
            }
        }
    }

    void isotropicMatchesSeedEquations()
    {
        const double sa = 0.109, ss = 0.891, st = sa + ss;
        const DenseOmega om = buildOmega({float(sa), float(ss), 0.0f});
        const double saf = double(float(sa)), ssf = double(float(ss)), stf = saf + ssf;
        (void)st;
        for (int i = 0; i < kDirections; ++i)
            for (int j = 0; j < kDirections; ++j) {
                double expected;
                if (i == 0) expected = j == 0 ? -1.0 : saf;                       // (5)
                else if (i <= 6) expected = j == 0 ? 1.0 / 12 : (j == i ? -stf + ssf / 12 : ssf / 12);   // (6)
                else expected = j == 0 ? 1.0 / 24 : (j == i ? -stf + ssf / 24 : ssf / 24);             // (7)
                QVERIFY2(std::fabs(at(om, i, j) - expected) < 1e-12, qPrintable(QString("Omega[%1][%2]").arg(i).arg(j)));
            }
    }

    void anisotropicMatchesSeedPhase()
    {
        for (double g : {-0.75, -0.231, 0.091, 0.5, 0.9, 0.99}) {
            const auto pn = normalizedPhase(g);
            for (int i = 1; i <= 18; ++i)
                for (int j = 1; j <= 18; ++j) {
                    const double ref = seedPhase(g, i, j);
                    QVERIFY(std::fabs(pn[size_t((i - 1) * 18 + j - 1)] - ref) <= 1e-10 * std::max(1.0, ref));
                }
        }
    }

    void nullVectorOfAppendix()
    {
        for (float sa : {0.0f, 0.008f, 0.109f, 0.5f}) {
            const float ss = 0.9f - sa * 0.5f;
            const DenseOmega om = buildOmega({sa, ss, 0.0f});
            double v[kDirections];
            v[0] = sa;
            for (int m = 1; m < kDirections; ++m) v[m] = m <= 6 ? 1.0 / 12 : 1.0 / 24;
            for (int i = 0; i < kDirections; ++i) {
                double r = 0;
                for (int j = 0; j < kDirections; ++j) r += at(om, i, j) * v[j];
                QVERIFY2(std::fabs(r) < 1e-12, qPrintable(QString("(Omega v)[%1] = %2").arg(i).arg(r)));
            }
        }
    }

    void passThroughAtZeroAbsorptionAndForwardScattering()
    {
        // sigma_a = 0, g = 1: Omega f = 0 for any f with f_0 = 0, so the update is a pure pass-through.
        const DenseOmega om = buildOmega({0.0f, 1.0f, 1.0f});
        std::mt19937 rng(3);
        std::uniform_real_distribution<double> u(0.0, 1.0);
        double f[kDirections] = {0};
        for (int m = 1; m < kDirections; ++m) f[m] = u(rng);
        for (int i = 0; i < kDirections; ++i) {
            double r = 0;
            for (int j = 0; j < kDirections; ++j) r += at(om, i, j) * f[j];
            QVERIFY(std::fabs(r) < 1e-12);
        }
    }

    void backwardLimitSendsMassToAntipode()
    {
        const auto pn = normalizedPhase(-1.0);
        for (int j = 1; j <= 18; ++j)
            for (int i = 1; i <= 18; ++i) {
                const double wpn = weight(i) * pn[size_t((i - 1) * 18 + j - 1)];
                QCOMPARE(wpn, i == kOpposite[j] ? 1.0 : 0.0);
            }
    }

    void continuousApproachToUnitG()
    {
        for (double sign : {1.0, -1.0}) {
            const DenseOmega limit = buildOmega({0.1f, 0.9f, float(sign)});
            double previous = 1e30;
            for (double eps : {1e-1, 1e-2, 1e-3, 1e-5, 1e-7}) {
                const auto pn = normalizedPhase(sign * (1.0 - eps));
                double maxDiff = 0;
                for (int i = 1; i <= 18; ++i)
                    for (int j = 1; j <= 18; ++j) {
                        const double v = pn[size_t((i - 1) * 18 + j - 1)];
                        QVERIFY(std::isfinite(v) && v >= 0.0);
                        const double lim = at(limit, i, j) + (i == j ? double(0.1f) + double(0.9f) : 0.0);   // remove -sigma_t
                        maxDiff = std::max(maxDiff, std::fabs(double(0.9f) * weight(i) * v - lim));
                    }
                QVERIFY2(maxDiff < previous || maxDiff < 1e-14, qPrintable(QString("not approaching the limit at eps=%1").arg(eps)));
                previous = maxDiff;
            }
            QVERIFY2(previous < 1e-9, qPrintable(QString("distance to the limit at 1e-7: %1").arg(previous)));
        }
    }

    void compactFormEqualsDense()
    {
        std::mt19937 rng(11);
        std::uniform_real_distribution<float> u(0.0f, 1.0f);
        for (int trial = 0; trial < 50; ++trial) {
            ChannelParams p{0.3f * u(rng), 0.6f * u(rng), 2.0f * u(rng) - 1.0f};
            if (trial == 0) p.g = 1.0f;
            if (trial == 1) p.g = -1.0f;
            const DenseOmega om = buildOmega(p);
            const CompactOmega c = compactOmega(p);
            for (int a = 0; a < kPairs; ++a)
                for (int b = 0; b < kPairs; ++b) {
                    const int ip = kPairPos[a], jp = kPairPos[b], jn = kPairNeg[b];
                    const double diagP = ip == jp ? double(p.sigmaA + p.sigmaS) : 0.0;
                    const double sp = at(om, ip, jp) + diagP, sn = at(om, ip, jn);
                    QVERIFY(std::fabs(c.even[a][b] - 0.5 * (sp + sn)) < 1e-6);
                    QVERIFY(std::fabs(c.odd[a][b] - 0.5 * (sp - sn)) < 1e-6);
                    // Central symmetry that the compact form relies on.
                    QVERIFY(std::fabs(at(om, kPairNeg[a], jn) + (ip == jp ? double(p.sigmaA + p.sigmaS) : 0.0) - sp) < 1e-12);
                }
        }
    }

    // The node update through the octahedral reduction (SymmetricOmega, collideNode) against the dense
    // 19x19 Omega applied in double: equal to float rounding for random optics (g = +-1 included) and
    // random non-negative f, and never negative.
    void symmetricCollisionEqualsDense()
    {
        std::mt19937 rng(23);
        std::uniform_real_distribution<float> u(0.0f, 1.0f);
        for (int trial = 0; trial < 200; ++trial) {
            const float sa = 0.3f * u(rng);
            ChannelParams p{sa, (1.0f - sa) * u(rng), 2.0f * u(rng) - 1.0f};
            if (trial % 50 == 0) p.g = 1.0f;
            if (trial % 50 == 1) p.g = -1.0f;
            if (trial % 50 == 2) p.g = 0.0f;
            const DenseOmega om = buildOmega(p);
            const SymmetricOmega sym = symmetricOmega(p);
            QCOMPARE(sym.sigmaT, p.sigmaA + p.sigmaS);
            const float rho = trial % 7 == 0 ? 1.0f : u(rng);
            const bool zeroF0 = trial % 2 == 0;
            float f[kDirections];
            for (float& v : f) v = u(rng) < 0.2f ? 0.0f : u(rng);
            double expect[kDirections], scale = 0.0;
            for (int i = 0; i < kDirections; ++i) {
                double sum = 0.0;
                for (int j = 0; j < kDirections; ++j) sum += at(om, i, j) * double(f[j]);
                expect[i] = double(f[i]) + double(rho) * sum;
                scale = std::max(scale, std::fabs(double(f[i])));
            }
            if (zeroF0) expect[0] = 0.0;
            collideNode(f, rho, sym, zeroF0);
            for (int i = 0; i < kDirections; ++i) {
                QVERIFY2(f[i] >= 0.0f, qPrintable(QString("trial %1: post_%2 = %3").arg(trial).arg(i).arg(double(f[i]))));
                QVERIFY2(std::fabs(double(f[i]) - expect[i]) <= 4e-6 * scale,
                         qPrintable(QString("trial %1 g=%2: post_%3 = %4, dense %5").arg(trial).arg(double(p.g)).arg(i).arg(double(f[i])).arg(expect[i])));
            }
        }
    }
};

QTEST_APPLESS_MAIN(TestLbOmega)
#include "tst_lb_omega.moc"
