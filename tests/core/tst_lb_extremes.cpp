// LB solver at the edges of its parameters: g in [-1, 1] with both limits, sigma_a
// from 0 to 1, sigma_s up to the stability bound, empty / full / random density, axis, diagonal and
// grazing suns, fp32 and fp16: finite, non-negative, photons conserved when nothing absorbs and never
// created otherwise, fp16 neither overflowing nor flushing to zero, |g| -> 1 smooth, bad values refused.
// The long sweeps (512-node grids, steady states) are in tst_lb_extremes_slow.
#include <QTest>

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/base/error.h"
#include "core/base/half.h"
#include "core/grid/grid_compare.h"
#include "tests/core/lb_extremes_common.h"

using namespace sylva;
using namespace sylva::lb;
using namespace sylva::lbx;

class TestLbExtremes : public QObject {
    Q_OBJECT
private Q_SLOTS:
    // One collision at every node, observed through the solver (postCollision): finite, >= 0, and the
    // node's photon count is kept exactly when f_0 is kept (every column of I + rho Omega sums to 1),
    // reduced by exactly the dropped post_0 = f_0 + rho (sigma_a M - f_0) for plants. The state mixes
    // zeros, ones, 1e-30 and 1e4 (fp16: 1e-6 and 1e3) on a random density with medium on the boundary too.
    void collisionConservesAndStaysNonNegative_data()
    {
        QTest::addColumn<float>("g");
        QTest::addColumn<bool>("zeroF0");
        QTest::addColumn<bool>("fp16");
        for (float g : sweepG())
            for (bool z : {false, true})
                for (bool h : {false, true})
                    QTest::newRow(qPrintable(QString("g=%1 %2 %3").arg(double(g), 0, 'g', 7).arg(z ? "zeroF0" : "keepF0").arg(h ? "fp16" : "fp32")))
                        << g << z << h;
    }
    void collisionConservesAndStaysNonNegative()
    {
        QFETCH(float, g);
        QFETCH(bool, zeroF0);
        QFETCH(bool, fp16);
        const glm::ivec3 n{5, 4, 9};
        const DensityGrid d = makeDensity(n, DensityKind::Random, 3);
        std::mt19937 rng(17);
        std::uniform_real_distribution<float> u(0.0f, 1.0f);
        std::vector<float> f(d.geometry.nodeCount() * kDirections);
        for (float& v : f) {
            const float pick = u(rng);
            v = pick < 0.2f ? 0.0f : (pick < 0.3f ? 1.0f : (pick < 0.35f ? 1e-30f : (pick < 0.4f ? 1e4f : u(rng))));
            // fp16: inputs it can hold (1e-6 is a subnormal there), and node sums under its 65504 (solves at
            // unit intensity stay far below: a few times the unobstructed density, ~4).
            if (fp16 && v == 1e-30f) v = 1e-6f;
            if (fp16 && v == 1e4f) v = 1e3f;
        }
        for (const ChannelParams& ch : allChannels()) {
            if (ch.g != g) continue;
            LbParams p;
            p.channels[0] = ch;
            p.zeroF0 = zeroF0;
            p.storage = fp16 ? Storage::Fp16 : Storage::Fp32;
            std::vector<float> in = f;
            if (fp16)   // the input as fp16 storage holds it
                for (float& v : in) v = halfToFloat(floatToHalf(v));
            const std::vector<float> post = postCollision(d, p, in);
            // fp16 rounds each stored value to 11 bits: 2^-11 relative per value.
            const double rel = fp16 ? 1.5e-3 : 2e-6;
            for (size_t node = 0; node < d.geometry.nodeCount(); ++node) {
                const size_t r = node / size_t(n.z), k = node % size_t(n.z);
                double before = 0.0, after = 0.0, scale = 0.0, moving = 0.0;
                for (int m = 0; m < kDirections; ++m) {
                    const size_t idx = (r * kDirections + size_t(m)) * size_t(n.z) + k;
                    const float v = post[idx];
                    LBX_CHECK(std::isfinite(v) && v >= 0.0f, QString("%1: post_%2 = %3 at node %4").arg(channelText(ch).c_str()).arg(m).arg(double(v)).arg(node));
                    before += in[idx];
                    after += v;
                    scale += std::fabs(double(in[idx]));
                    if (m > 0) moving += in[idx];
                }
                double expected = before;
                if (zeroF0) {
                    const double rho = d.density[node], f0 = in[(r * kDirections) * size_t(n.z) + k];
                    expected -= f0 + rho * (double(ch.sigmaA) * moving - f0);
                }
                LBX_CHECK(std::fabs(after - expected) <= rel * scale + 1e-30, QString("%1: node %2 holds %3 after the collision, expected %4 (before %5)")
                                        .arg(channelText(ch).c_str()).arg(node).arg(after, 0, 'g', 10).arg(expected, 0, 'g', 10).arg(before, 0, 'g', 10));
            }
        }
    }

    // Full solves over the sweep on small grids (3^3 and 6x4x11; more shapes, all suns and 512-node
    // grids in the slow test): every g, sigma_a, sigma_s (three channels per solve), axis, diagonal and
    // grazing suns, f_0 kept and zeroed, fp32 and fp16 (which must match fp32 and never flush a visible
    // answer to zero). The bound on the output: 8 x the unobstructed density (measured up to ~2.5).
    void solveSweep_data()
    {
        QTest::addColumn<int>("nx");
        QTest::addColumn<int>("ny");
        QTest::addColumn<int>("nz");
        QTest::addColumn<int>("kind");
        for (glm::ivec3 n : {glm::ivec3(3, 3, 3), glm::ivec3(6, 4, 11)})
            for (DensityKind k : {DensityKind::Zero, DensityKind::One, DensityKind::Random})
                QTest::newRow(qPrintable(QString("%1x%2x%3 %4").arg(n.x).arg(n.y).arg(n.z).arg(densityName(k)))) << n.x << n.y << n.z << int(k);
    }
    void solveSweep()
    {
        QFETCH(int, nx);
        QFETCH(int, ny);
        QFETCH(int, nz);
        QFETCH(int, kind);
        const DensityGrid d = makeDensity({nx, ny, nz}, DensityKind(kind), uint32_t(nx * 100 + nz));
        const std::vector<SunCase>& all = sweepSuns();
        const std::vector<SunCase> suns = {all[0], all[3], all[5], all[6]};   // axis, face and body diagonal, grazing
        const SweepResult r = sweepGrid(d, allChannels(), suns, true, 8.0);
        QVERIFY2(r.failure.isEmpty(), qPrintable(r.failure));
        qInfo("%d solves; largest output / unobstructed %.3f; largest fp16 error %.2e of unobstructed", r.solves, r.maxRatio, r.maxFp16Error);
    }

    // A medium that absorbs everything it touches (sigma_a = 1, rho = 1): boundary nodes absorb in one
    // collision, so the interior stays exactly dark, in fp32 and fp16, whatever g and the sun.
    void totalAbsorberIsExactlyDark()
    {
        const DensityGrid d = makeDensity({7, 5, 9}, DensityKind::One);
        for (Storage s : {Storage::Fp32, Storage::Fp16})
            for (const SunCase& sun : sweepSuns()) {
                LbParams p;
                p.channels = {{{1.0f, 0.0f, -1.0f}, {1.0f, 0.0f, 0.0f}, {1.0f, 0.0f, 1.0f}}};
                p.sun = sun.sun;
                p.storage = s;
                for (bool zeroF0 : {true, false}) {
                    p.zeroF0 = zeroF0;
                    const LightingGrid out = solveLighting(d, p);
                    const glm::ivec3 n = d.geometry.dims;
                    for (int i = 1; i < n.x - 1; ++i)
                        for (int j = 1; j < n.y - 1; ++j)
                            for (int k = 1; k < n.z - 1; ++k)
                                for (int c = 0; c < 3; ++c) QCOMPARE(out.at(i, j, k, c), 0.0f);
                }
            }
    }

    // Nothing interacts with sigma_a = 0 and g = 1 (all scattering goes straight on), nor with g =
    // 0.999999 to float precision: any density is transparent, even at the stability bound.
    void forwardLimitIsTransparent()
    {
        DensityGrid d = makeDensity({8, 6, 10}, DensityKind::Random, 5);
        std::fill(d.woodFraction.begin(), d.woodFraction.end(), 0.0f);   // brown nodes scatter with g = -1
        for (const SunCase& sun : sweepSuns()) {
            LbParams p;
            p.channels = {{{0.0f, 1.0f, 1.0f}, {0.0f, 1.0f, 0.999999f}, {0.0f, 0.5f, 1.0f}}};
            p.zeroF0 = false;
            p.sun = sun.sun;
            const LightingGrid out = solveLighting(d, p);
            const double free = freeDensity(p.sun);
            for (size_t i = 0; i < out.rgb.size(); ++i)
                LBX_CHECK(std::fabs(double(out.rgb[i]) - free) <= 1e-5 * free, QString("sun %1, channel %2: %3 vs unobstructed %4").arg(sun.name.c_str()).arg(i % 3).arg(double(out.rgb[i])).arg(free));
        }
    }

    // Photon balance step by step (docs/LB_MODEL.md "Update"): content(t+1) = content(t) + inflow - outflow -
    // absorbed, where inflow is what boundary nodes send in and outflow what interior nodes send onto
    // the boundary. Nothing absorbs when sigma_a = 0 (absorbed = 0 at every step, the run's inflow =
    // outflow + content) or when f_0 is kept; plants with sigma_a > 0 absorb >= 0 and never more than
    // they hold. Small grids here; the slow test runs 512-node grids into their steady state.
    void photonBalance_data()
    {
        QTest::addColumn<int>("nx");
        QTest::addColumn<int>("ny");
        QTest::addColumn<int>("nz");
        QTest::addColumn<int>("kind");
        QTest::addColumn<float>("sigmaA");
        QTest::addColumn<bool>("zeroF0");
        for (glm::ivec3 n : {glm::ivec3(3, 3, 3), glm::ivec3(6, 5, 4)})
            for (DensityKind k : {DensityKind::One, DensityKind::Random})
                for (float sa : {0.0f, 0.5f, 1.0f})   // 1e-7 in the slow test
                    for (bool z : {true, false}) {
                        if (sa == 0.0f && !z) continue;   // same as zeroF0 with sigma_a = 0: f_0 stays 0
                        QTest::newRow(qPrintable(QString("%1x%2x%3 %4 sigma_a=%5 %6").arg(n.x).arg(n.y).arg(n.z).arg(densityName(k))
                                                     .arg(double(sa)).arg(z ? "zeroF0" : "keepF0")))
                            << n.x << n.y << n.z << int(k) << sa << z;
                    }
    }
    void photonBalance()
    {
        QFETCH(int, nx);
        QFETCH(int, ny);
        QFETCH(int, nz);
        QFETCH(int, kind);
        QFETCH(float, sigmaA);
        QFETCH(bool, zeroF0);
        const glm::ivec3 n{nx, ny, nz};
        const DensityGrid d = makeDensity(n, DensityKind(kind), 11);
        const bool conserving = sigmaA == 0.0f || !zeroF0;
        const int steps = defaultSteps(n);
        for (float g : {-1.0f, -0.999999f, 0.5f, 1.0f})
            for (float ss : sweepSigmaS(sigmaA))
                for (const SunCase& sun : {sweepSuns()[0], sweepSuns()[5], sweepSuns()[6]}) {
                    LbParams p;
                    p.channels[0] = {sigmaA, ss, g};
                    p.zeroF0 = zeroF0;
                    p.sun = sun.sun;
                    const QString what = QString("%1, sun %2").arg(channelText(p.channels[0]).c_str()).arg(sun.name.c_str());
                    std::vector<float> f = initialState(n, p.sun);
                    double totalIn = 0.0, totalOut = 0.0, totalAbs = 0.0;
                    const double start = interiorContent(n, f);
                    for (int t = 0; t < steps; ++t) {
                        const StepBalance b = stepBalance(d, p, f);
                        const double scale = b.content + b.inflow + 1e-30;
                        LBX_CHECK(b.minPost >= 0.0, QString("%1: negative post-collision value %2 at step %3").arg(what).arg(b.minPost).arg(t));
                        LBX_CHECK(b.maxNodeGain <= 1e-6, QString("%1: a collision made %2 photons at step %3").arg(what).arg(b.maxNodeGain).arg(t));
                        if (conserving)
                            LBX_CHECK(std::fabs(b.absorbed) <= 1e-6 * scale, QString("%1: %2 photons lost with nothing absorbing at step %3").arg(what).arg(b.absorbed).arg(t));
                        else
                            LBX_CHECK(b.absorbed >= -1e-6 * scale && b.absorbed <= b.content * (1.0 + 1e-6), QString("%1: absorbed %2 of %3 at step %4").arg(what).arg(b.absorbed).arg(b.content).arg(t));
                        advance(d, p, f, 1);
                        const double next = interiorContent(n, f);
                        const double predicted = b.content + b.inflow - b.outflow - b.absorbed;
                        LBX_CHECK(std::fabs(next - predicted) <= 1e-5 * scale, QString("%1: step %2 content %3, balance predicts %4 (in %5 out %6 absorbed %7)")
                                                .arg(what).arg(t).arg(next, 0, 'g', 10).arg(predicted, 0, 'g', 10).arg(b.inflow).arg(b.outflow).arg(b.absorbed));
                        totalIn += b.inflow;
                        totalOut += b.outflow;
                        totalAbs += b.absorbed;
                    }
                    for (float v : f) LBX_CHECK(std::isfinite(v) && v >= 0.0f, what + ": f not finite or negative");
                    const double end = interiorContent(n, f);
                    // Over the run: what came in went out, stayed, or was absorbed (0 when conserving).
                    LBX_CHECK(std::fabs((totalIn - totalOut - totalAbs) - (end - start)) <= 1e-5 * totalIn, QString("%1: in %2 - out %3 - absorbed %4 != content change %5").arg(what).arg(totalIn).arg(totalOut).arg(totalAbs).arg(end - start));
                    if (conserving) QVERIFY(std::fabs(totalAbs) <= 1e-5 * totalIn);
                }
    }

    // |g| just under 1 approaches the |g| = 1 answer smoothly: the distance to the limit shrinks with
    // 1 - |g| and is at float rounding by 0.999999, in fp32 and fp16.
    void unitGIsApproachedSmoothly()
    {
        const DensityGrid d = makeDensity({12, 10, 9}, DensityKind::Random, 21);
        for (Storage s : {Storage::Fp32, Storage::Fp16})
            for (float sign : {1.0f, -1.0f})
                for (bool zeroF0 : {true, false}) {
                    LbParams p;
                    p.sun = {0.3f, 1.0f, 0.2f};
                    p.storage = s;
                    p.zeroF0 = zeroF0;
                    p.channels = {{{0.2f, 0.8f, sign}, {0.0f, 1.0f, sign}, {0.5f, 0.5f, sign}}};
                    const LightingGrid limit = solveLighting(d, p);
                    double previous = 1e30;
                    for (float eps : {1e-1f, 1e-2f, 1e-3f, 1e-4f, 1e-6f}) {
                        LbParams q = p;
                        for (auto& ch : q.channels) ch.g = sign * (1.0f - eps);
                        const LightingGrid near = solveLighting(d, q);
                        const double dist = relativeL2(near, limit);
                        qInfo("%s g=%+.6f %s: relative L2 to the limit %.3e", s == Storage::Fp16 ? "fp16" : "fp32", double(sign * (1.0f - eps)),
                              zeroF0 ? "zeroF0" : "keepF0", dist);
                        QVERIFY(std::isfinite(dist));
                        // Monotone down to rounding (fp16 steps are 2^-11).
                        const double floor = s == Storage::Fp16 ? 2e-3 : 1e-6;
                        LBX_CHECK(dist <= previous || dist < floor, QString("distance grew to %1 at 1 - |g| = %2").arg(dist).arg(double(eps)));
                        previous = dist;
                    }
                    LBX_CHECK(previous < (s == Storage::Fp16 ? 2e-3 : 1e-6), QString("|g| = 0.999999 is %1 from the limit").arg(previous));
                }
    }

    // fp16 stores the solve at unit intensity, so tiny and large sun intensities neither flush to zero
    // nor overflow: the answer scales with the intensity. Above the documented fp16 cap the solve is refused.
    void fp16IntensityExtremes()
    {
        const DensityGrid d = makeDensity({9, 7, 8}, DensityKind::Random, 2);
        LbParams p = paramsFromPreset(*findPreset("leaf"));
        p.sun = {0.2f, 1.0f, -0.4f};
        const LightingGrid unit = solveLighting(d, p);
        p.storage = Storage::Fp16;
        for (float I : {1e-30f, 1e-8f, 1e-3f, 1.0f, 999.0f}) {
            p.intensity = glm::vec3(I);
            const LightingGrid out = solveLighting(d, p);
            double err = 0.0, norm = 0.0;
            for (size_t i = 0; i < out.rgb.size(); ++i) {
                QVERIFY(std::isfinite(out.rgb[i]) && out.rgb[i] >= 0.0f);
                if (unit.rgb[i] > 0.0f) LBX_CHECK(out.rgb[i] > 0.0f, QString("intensity %1 flushed to zero").arg(double(I)));
                const double ref = double(unit.rgb[i]) * double(I);
                err += (double(out.rgb[i]) - ref) * (double(out.rgb[i]) - ref);
                norm += ref * ref;
            }
            LBX_CHECK(std::sqrt(err / norm) < 5e-3, QString("intensity %1: relative error %2").arg(double(I)).arg(std::sqrt(err / norm)));
        }
        p.intensity = glm::vec3(1e5f);
        try {
            solveLighting(d, p);
            QFAIL("fp16 accepted an intensity above its cap");
        } catch (const Error& e) {
            QVERIFY2(QString(e.what()).contains("fp16") && QString(e.what()).contains("fp32"), e.what());
        }
    }

    // Tolerance mode at the extremes terminates with finite answers (and converges where the fixed
    // run does), including the slow pure-backscatter case and fp16 (whose rounding can stall the change).
    void toleranceModeAtExtremes()
    {
        const DensityGrid d = makeDensity({10, 12, 9}, DensityKind::Random, 8);
        for (Storage s : {Storage::Fp32, Storage::Fp16})
            for (float g : {-1.0f, 0.0f, 1.0f}) {
                LbParams p;
                p.channels = {{{0.0f, 1.0f, g}, {1e-7f, 1.0f - 1e-7f, g}, {1.0f, 0.0f, g}}};
                p.zeroF0 = false;
                p.sun = sunDirection(0.01, 45.0);
                p.storage = s;
                p.tolerance = 1e-4;
                SolveStats st;
                const LightingGrid out = solveLighting(d, p, nullptr, &st);
                for (float v : out.rgb) QVERIFY(std::isfinite(v) && v >= 0.0f);
                QVERIFY(st.steps >= 1 && st.steps <= 4 * 12);
                QVERIFY(std::isfinite(st.lastChange));
            }
    }

    // Parameters outside the stable region are refused by lb::validate with a message naming the
    // parameter and its bound; values exactly on the bounds are accepted.
    void outsideStableRegionIsRefused_data()
    {
        QTest::addColumn<float>("sa");
        QTest::addColumn<float>("ss");
        QTest::addColumn<float>("g");
        QTest::addColumn<QString>("mentions");
        const float nan = std::numeric_limits<float>::quiet_NaN(), inf = std::numeric_limits<float>::infinity();
        const float above1 = std::nextafter(1.0f, 2.0f);
        QTest::newRow("sigma_s = 2") << 0.0f << 2.0f << 0.0f << "stability bound 1";
        QTest::newRow("sigma_t = 1 + 1 ulp (absorption)") << above1 << 0.0f << 0.0f << "stability bound 1";
        QTest::newRow("sigma_t = 1 + 1 ulp (scattering)") << 0.0f << above1 << 0.5f << "stability bound 1";
        QTest::newRow("sigma_t = 1.0000005") << 0.5f << 0.5000005f << 0.0f << "stability bound 1";
        QTest::newRow("negative sigma_a") << -1e-30f << 0.5f << 0.0f << "sigma_a";
        QTest::newRow("negative sigma_s") << 0.5f << -0.1f << 0.0f << "sigma_s";
        QTest::newRow("g = 1 + 1 ulp") << 0.1f << 0.5f << above1 << "[-1, 1]";
        QTest::newRow("g = -1.0000001") << 0.1f << 0.5f << -above1 << "[-1, 1]";
        QTest::newRow("g = 2") << 0.1f << 0.5f << 2.0f << "[-1, 1]";
        QTest::newRow("NaN sigma_a") << nan << 0.5f << 0.0f << "sigma_a";
        QTest::newRow("NaN sigma_s") << 0.1f << nan << 0.0f << "sigma_s";
        QTest::newRow("NaN g") << 0.1f << 0.5f << nan << "[-1, 1]";
        QTest::newRow("inf sigma_a") << inf << 0.0f << 0.0f << "sigma_a";
        QTest::newRow("-inf g") << 0.1f << 0.5f << -inf << "[-1, 1]";
    }
    void outsideStableRegionIsRefused()
    {
        QFETCH(float, sa);
        QFETCH(float, ss);
        QFETCH(float, g);
        QFETCH(QString, mentions);
        for (int c = 0; c < 3; ++c) {
            LbParams p;
            p.channels[size_t(c)] = {sa, ss, g};
            try {
                validate(p);
                QFAIL(qPrintable(QString("accepted %1 in channel %2").arg(channelText(p.channels[size_t(c)]).c_str()).arg(c)));
            } catch (const Error& e) {
                const QString msg = e.what();
                QVERIFY2(msg.contains(mentions), e.what());
                QVERIFY2(msg.contains(QString("channel ") + "RGB"[c]), e.what());
            }
        }
    }
    void boundsThemselvesAreAccepted()
    {
        for (const ChannelParams& ch : allChannels()) {
            LbParams p;
            p.channels = {ch, ch, ch};
            validate(p);
        }
        for (const Preset& preset : presets()) validate(paramsFromPreset(preset));
        LbParams p;
        p.channels[0] = {0.3f, 0.7f, -1.0f};   // decimal inputs summing to 1 round to a float sum of exactly 1
        p.channels[1] = {0.6f, 0.4f, 1.0f};
        p.channels[2] = {0.118f, 0.882f, 0.0f};
        validate(p);
    }
    // The density side of the bound: sigma_t * max rho <= 1 holds because rho is refused outside [0, 1].
    void densityOutsideUnitIntervalIsRefused()
    {
        for (float bad : {std::nextafter(1.0f, 2.0f), -1e-30f, std::numeric_limits<float>::quiet_NaN(), std::numeric_limits<float>::infinity()}) {
            DensityGrid d = makeDensity({4, 4, 4}, DensityKind::One);
            d.density[21] = bad;
            try {
                validateDensity(d);
                QFAIL(qPrintable(QString("accepted density %1").arg(double(bad))));
            } catch (const Error& e) {
                QVERIFY2(QString(e.what()).contains("outside [0, 1]"), e.what());
            }
        }
    }
};

QTEST_APPLESS_MAIN(TestLbExtremes)
#include "tst_lb_extremes.moc"
