// Sky models (core/sky): the Preetham sky against the paper's formulas and tables typed again here,
// environment maps (cleaning, the sun's extraction, integrals), virtual lights against direct sums over the
// map's pixels, interleaved sampling's subsets, NOAA's sun position against published values, and the
// sky's shares over lattice directions.
#include <QTest>

#include <cmath>
#include <set>
#include <string>
#include <vector>

#include "core/base/error.h"
#include "core/color/color.h"
#include "core/lb/lattice.h"
#include "core/render/tonemap.h"
#include "core/scene/scene.h"
#include "core/sky/env_map.h"
#include "core/sky/preetham.h"
#include "core/sky/sky.h"
#include "core/sky/sky_light.h"
#include "core/sky/sun_position.h"
#include "core/sky/virtual_lights.h"

using namespace sylva;
using namespace sylva::sky;

namespace {

const std::string kCiePath = std::string(SYLVA_RESOURCES) + "/color/cie1931_2deg_xyz_cmf_360-830_1nm.csv";
constexpr double kPI = 3.14159265358979323846;

// Preetham, Shirley & Smits 1999, Appendix A.2, typed again from the paper for this test.
// Perez coefficients: value = a * T + b. Rows A, B, C, D, E.
const double kY[5][2] = {{0.1787, -1.4630}, {-0.3554, 0.4275}, {-0.0227, 5.3251}, {0.1206, -2.5771}, {-0.0670, 0.3703}};
const double kX[5][2] = {{-0.0193, -0.2592}, {-0.0665, 0.0008}, {-0.0004, 0.2125}, {-0.0641, -0.8989}, {-0.0033, 0.0452}};
const double kYy[5][2] = {{-0.0167, -0.2608}, {-0.0950, 0.0092}, {-0.0079, 0.2102}, {-0.0441, -1.6537}, {-0.0109, 0.0529}};

struct Perez {
    double c[5];
};
Perez perezOf(const double table[5][2], double T)
{
    Perez p;
    for (int k = 0; k < 5; ++k) p.c[k] = table[k][0] * T + table[k][1];
    return p;
}
// F(theta, gamma) = (1 + A e^(B / cos theta)) (1 + C e^(D gamma) + E cos^2 gamma)
double F(const Perez& p, double theta, double gamma)
{
    return (1.0 + p.c[0] * std::exp(p.c[1] / std::cos(theta))) * (1.0 + p.c[2] * std::exp(p.c[3] * gamma) + p.c[4] * std::pow(std::cos(gamma), 2));
}
double zenithY(double T, double ts)
{
    const double chi = (4.0 / 9.0 - T / 120.0) * (kPI - 2.0 * ts);
    return (4.0453 * T - 4.9710) * std::tan(chi) - 0.2155 * T + 2.4192;
}
double zenithX(double T, double ts)
{
    const double t2 = ts * ts, t3 = t2 * ts;
    return T * T * (0.00166 * t3 - 0.00375 * t2 + 0.00209 * ts) + T * (-0.02903 * t3 + 0.06377 * t2 - 0.03202 * ts + 0.00394) +
           (0.11693 * t3 - 0.21196 * t2 + 0.06052 * ts + 0.25886);
}
double zenithYy(double T, double ts)
{
    const double t2 = ts * ts, t3 = t2 * ts;
    return T * T * (0.00275 * t3 - 0.00610 * t2 + 0.00317 * ts) + T * (-0.04214 * t3 + 0.08970 * t2 - 0.04153 * ts + 0.00516) +
           (0.15346 * t3 - 0.26756 * t2 + 0.06670 * ts + 0.26688);
}

glm::dvec3 dirFrom(double elevDeg, double azDeg)
{
    const double e = elevDeg * kPI / 180.0, a = azDeg * kPI / 180.0;
    return glm::dvec3(std::cos(e) * std::sin(a), std::sin(e), std::cos(e) * std::cos(a));
}

double lumOf(glm::dvec3 c) { return 0.2126 * c.x + 0.7152 * c.y + 0.0722 * c.z; }

bool finiteNonNegative(glm::vec3 c) { return std::isfinite(c.x) && std::isfinite(c.y) && std::isfinite(c.z) && c.x >= 0 && c.y >= 0 && c.z >= 0; }

// A test map: smooth sky brighter toward the zenith, darker ground, plus an optional blob.
EnvMap testMap(int w, double blobElev = 30.0, double blobAz = 40.0, float blob = 0.0f, double blobRadiusDeg = 6.0)
{
    EnvMap m;
    m.width = w;
    m.height = w / 2;
    m.rgb.resize(size_t(w) * size_t(w / 2) * 3);
    const glm::dvec3 b = dirFrom(blobElev, blobAz);
    for (int y = 0; y < m.height; ++y)
        for (int x = 0; x < m.width; ++x) {
            const glm::dvec3 d(envMapPixelDirection(m.width, m.height, x, y));
            const double up = d.y > 0 ? 0.5 + 1.5 * d.y : 0.2 + 0.05 * std::sin(3.0 * std::atan2(d.x, d.z));
            double add = 0.0;
            if (std::acos(std::clamp(glm::dot(d, b), -1.0, 1.0)) < blobRadiusDeg * kPI / 180.0) add = blob;
            float* p = m.ptr(x, y);
            p[0] = float(up * 0.8 + add);
            p[1] = float(up * 0.9 + add);
            p[2] = float(up * 1.2 + add * 0.9);
        }
    return m;
}

// Direct sums over the pixels, written independently of env_map.cpp.
glm::dvec3 directIntegral(const EnvMap& m, bool cosineUpper)
{
    glm::dvec3 s(0.0);
    for (int y = 0; y < m.height; ++y) {
        const double t0 = kPI * y / m.height, t1 = kPI * (y + 1) / m.height, tc = kPI * (y + 0.5) / m.height;
        const double omega = (2.0 * kPI / m.width) * (std::cos(t0) - std::cos(t1));
        const double w = cosineUpper ? std::max(std::cos(tc), 0.0) : 1.0;
        for (int x = 0; x < m.width; ++x) s += glm::dvec3(m.at(x, y)) * omega * w;
    }
    return s;
}

} // namespace

class TestSky : public QObject {
    Q_OBJECT
private:
    CieTable m_cie;

private Q_SLOTS:
    void initTestCase() { m_cie = loadCieCsv(kCiePath); }

    void conventions()
    {
        // Centre column toward +Z, a quarter in toward +X, row 0 at the zenith; sunDirection agrees.
        const glm::vec3 z = equirectDirection(0.5f, 0.5f), xdir = equirectDirection(0.25f, 0.5f), up = equirectDirection(0.3f, 0.0f);
        QVERIFY(glm::length(z - glm::vec3(0, 0, 1)) < 1e-6f);
        QVERIFY(glm::length(xdir - glm::vec3(1, 0, 0)) < 1e-6f);
        QVERIFY(glm::length(up - glm::vec3(0, 1, 0)) < 1e-6f);
        for (double el : {-80.0, -10.0, 0.0, 25.0, 70.0})
            for (double az : {0.0, 45.0, 90.0, 200.0, 359.0}) {
                const glm::vec3 a = sunDirection(el, az), b = directionFromAngles(float(el), float(az));
                QVERIFY(glm::length(a - b) < 1e-5f);
                const glm::vec2 uv = equirectUv(a);
                QVERIFY(glm::length(equirectDirection(uv.x, uv.y) - a) < 1e-5f);
                // Rotating by R adds R to the azimuth.
                const float r = 33.0f * float(kPI) / 180.0f;
                QVERIFY(glm::length(rotateAzimuth(a, std::cos(r), std::sin(r)) - sunDirection(el, az + 33.0)) < 1e-5f);
            }
        // The float XYZ -> Rec. 709 matrix is the colour module's.
        for (glm::dvec3 xyz : {glm::dvec3(0.95047, 1.0, 1.08883), glm::dvec3(0.2, 0.5, 0.1), glm::dvec3(1.0, 0.3, 2.0)}) {
            const glm::dvec3 a = xyzToLinearSrgb(xyz);
            const glm::vec3 b = xyzToRec709(glm::vec3(xyz));
            QVERIFY(glm::length(glm::dvec3(b) - a) < 1e-5);
        }
    }

    void perezCoefficientsAndFunction()
    {
        for (double T : {2.0, 3.0, 5.5, 10.0})
            for (double elev : {5.0, 30.0, 60.0, 89.0}) {
                const PreethamSky s = makePreetham({.turbidity = T, .sunDirection = glm::vec3(dirFrom(elev, 120.0))});
                const Perez ref[3] = {perezOf(kY, T), perezOf(kX, T), perezOf(kYy, T)};
                for (int q = 0; q < 3; ++q)
                    for (int k = 0; k < 5; ++k) QVERIFY2(std::abs(s.perez[q][k] - ref[q].c[k]) < 1e-6, qPrintable(QString::number(T)));
                for (double th : {0.0, 0.3, 1.0, 1.4, 1.55})
                    for (double g : {0.0, 0.1, 0.8, 2.0, 3.1}) {
                        for (int q = 0; q < 3; ++q) {
                            const double want = F(ref[q], th, g);
                            const double got = perezF(s.perez[q], float(std::cos(th)), float(g), float(std::cos(g)));
                            QVERIFY2(std::abs(got - want) <= 1e-5 * std::abs(want) + 1e-6, qPrintable(QString("T %1 theta %2 gamma %3").arg(T).arg(th).arg(g)));
                        }
                    }
            }
    }

    void zenithValues()
    {
        for (double T : {2.0, 3.0, 4.5, 7.0, 10.0})
            for (double elev : {2.0, 10.0, 30.0, 45.0, 75.0, 90.0}) {
                const double ts = (90.0 - elev) * kPI / 180.0;
                const PreethamSky s = makePreetham({.turbidity = T, .sunDirection = glm::vec3(dirFrom(elev, 10.0))});
                const QString where = QString("T %1 elevation %2").arg(T).arg(elev);
                QVERIFY2(std::abs(s.zenith[0] - zenithY(T, ts)) < 1e-5 * zenithY(T, ts) + 1e-6, qPrintable(where));
                QVERIFY2(std::abs(s.zenith[1] - zenithX(T, ts)) < 1e-6, qPrintable(where));
                QVERIFY2(std::abs(s.zenith[2] - zenithYy(T, ts)) < 1e-6, qPrintable(where));
                QVERIFY(std::abs(zenithLuminancePaper(T, ts) - zenithY(T, ts)) < 1e-12);
                // The zenith direction itself reads the zenith values.
                const glm::vec3 yxy = preethamYxy(s, glm::vec3(0, 1, 0));
                QVERIFY2(std::abs(yxy.x - zenithY(T, ts)) < 2e-5 * zenithY(T, ts), qPrintable(where));
                QVERIFY(std::abs(yxy.y - zenithX(T, ts)) < 1e-5);
                QVERIFY(std::abs(yxy.z - zenithYy(T, ts)) < 1e-5);
            }
        // A plausible clear sky: zenith 2..20 kcd/m^2 by day, chromaticity near white.
        const PreethamSky s = makePreetham({.turbidity = 3.0, .sunDirection = glm::vec3(dirFrom(45.0, 0.0))});
        QVERIFY(s.zenith[0] > 2.0f && s.zenith[0] < 20.0f);
        QVERIFY(s.zenith[1] > 0.2f && s.zenith[1] < 0.35f && s.zenith[2] > 0.2f && s.zenith[2] < 0.4f);
    }

    void luminanceRelativeToZenith()
    {
        for (double T : {2.0, 4.0, 8.0})
            for (double elev : {8.0, 35.0, 70.0}) {
                const double ts = (90.0 - elev) * kPI / 180.0;
                const glm::dvec3 sun = dirFrom(elev, 200.0);
                const PreethamSky s = makePreetham({.turbidity = T, .sunDirection = glm::vec3(sun)});
                const Perez pY = perezOf(kY, T);
                for (double ve = 1.0; ve <= 90.0; ve += 11.0)
                    for (double va = 0.0; va < 360.0; va += 30.0) {
                        const glm::dvec3 d = dirFrom(ve, va);
                        const double theta = std::acos(d.y), gamma = std::acos(std::clamp(glm::dot(d, sun), -1.0, 1.0));
                        const double want = F(pY, theta, gamma) / F(pY, 0.0, ts);
                        const double got = preethamYxy(s, glm::vec3(d)).x / s.zenith[0];
                        QVERIFY2(std::abs(got - want) < 2e-4 * want, qPrintable(QString("T %1 sun %2 view %3/%4: %5 vs %6").arg(T).arg(elev).arg(ve).arg(va).arg(got).arg(want)));
                        // RGB is Yxy -> XYZ -> the colour module's Rec. 709, clamped at 0.
                        const glm::vec3 yxy = preethamYxy(s, glm::vec3(d));
                        const glm::dvec3 xyz(yxy.y / yxy.z * yxy.x, yxy.x, (1.0 - yxy.y - yxy.z) / yxy.z * yxy.x);
                        const glm::dvec3 rgb = glm::max(xyzToLinearSrgb(xyz), glm::dvec3(0.0));
                        QVERIFY(glm::length(glm::dvec3(preethamRadiance(s, glm::vec3(d))) - rgb) < 1e-4 * (1.0 + glm::length(rgb)));
                    }
                // The sky brightens toward the sun (circumsolar) and is brighter near it than opposite.
                const double toward = preethamYxy(s, glm::vec3(dirFrom(elev + 3.0 > 89 ? elev - 3.0 : elev + 3.0, 200.0))).x;
                const double away = preethamYxy(s, glm::vec3(dirFrom(std::max(elev, 20.0), 20.0))).x;
                QVERIFY(toward > away);
            }
    }

    void continuityInSunElevation()
    {
        const std::vector<glm::vec3> views = {glm::vec3(0, 1, 0), glm::vec3(dirFrom(10.0, 0.0)), glm::vec3(dirFrom(40.0, 90.0)),
                                              glm::vec3(dirFrom(1.0, 180.0)), glm::vec3(dirFrom(-20.0, 30.0))};
        auto skyAt = [&](double T, double elev, size_t view) {
            return glm::dvec3(preethamRadiance(makePreetham({.turbidity = T, .sunDirection = glm::vec3(dirFrom(elev, 0.0))}), views[view]));
        };
        auto sunAt = [&](double T, double elev) {
            return double(preethamSun({.turbidity = T, .sunDirection = glm::vec3(dirFrom(elev, 0.0))}, m_cie).illuminance);
        };
        for (double T : {2.0, 6.0, 10.0}) {
            // No jumps over the whole range: a 0.01-degree step changes nothing by more than 5%.
            for (double elev = -10.0 + 0.01; elev <= 90.0 + 1e-9; elev += 0.01)
                for (size_t i = 0; i < views.size(); ++i) {
                    const glm::dvec3 a = skyAt(T, elev - 0.01, i), b = skyAt(T, elev, i);
                    QVERIFY2(glm::length(b - a) <= 0.05 * std::max(glm::length(a), 1e-3) + 1e-5,
                             qPrintable(QString("T %1 elevation %2 view %3: %4 -> %5").arg(T).arg(elev).arg(i).arg(glm::length(a)).arg(glm::length(b))));
                }
            // Continuity at the joins (the horizon, where the twilight continuation starts, and the sun's
            // disc crossing it): the difference across the join shrinks with the distance from it.
            for (double e0 : {0.0, kSunRadiusDeg, -kSunRadiusDeg}) {
                double prevSky = 1e30, prevSun = 1e30;
                for (double h : {0.1, 0.01, 0.001}) {
                    double dSky = 0.0;
                    for (size_t i = 0; i < views.size(); ++i) dSky = std::max(dSky, glm::length(skyAt(T, e0 + h, i) - skyAt(T, e0 - h, i)));
                    const double dSun = std::abs(sunAt(T, e0 + h) - sunAt(T, e0 - h));
                    QVERIFY2(dSky < 0.2 * prevSky + 1e-6 && dSun < 0.2 * prevSun + 1e-4,
                             qPrintable(QString("T %1 at %2, h %3: sky %4 sun %5").arg(T).arg(e0).arg(h).arg(dSky).arg(dSun)));
                    prevSky = dSky, prevSun = dSun;
                }
            }
        }
    }

    void noNanOrNegative()
    {
        for (double T = 2.0; T <= 10.0 + 1e-9; T += 0.5)
            for (double elev = -10.0; elev <= 90.0 + 1e-9; elev += 2.5) {
                const PreethamParams p{.turbidity = T, .sunDirection = glm::vec3(dirFrom(elev, 77.0))};
                const PreethamSky s = makePreetham(p);
                for (double ve = -90.0; ve <= 90.0; ve += 7.5)
                    for (double va = 0.0; va < 360.0; va += 45.0)
                        QVERIFY2(finiteNonNegative(preethamRadiance(s, glm::vec3(dirFrom(ve, va)))),
                                 qPrintable(QString("T %1 sun %2 view %3/%4").arg(T).arg(elev).arg(ve).arg(va)));
                QVERIFY(finiteNonNegative(preethamRadiance(s, p.sunDirection)));
                const SkySun sun = preethamSun(p, m_cie);
                QVERIFY(std::isfinite(sun.illuminance) && sun.illuminance >= 0.0f && finiteNonNegative(sun.color));
                QCOMPARE(sun.present, elev > -kSunRadiusDeg);
            }
        QVERIFY_THROWS_EXCEPTION(Error, makePreetham({.turbidity = 1.5}));
        QVERIFY_THROWS_EXCEPTION(Error, makePreetham({.turbidity = 11.0}));
        QVERIFY_THROWS_EXCEPTION(Error, makePreetham({.turbidity = 3.0, .sunDirection = glm::vec3(0.0f)}));
        QVERIFY_THROWS_EXCEPTION(Error, makePreetham({.turbidity = 3.0, .sunDirection = glm::vec3(dirFrom(-10.5, 0.0))}));
    }

    void sunThroughTheAtmosphere()
    {
        // Transmittance: the paper's Rayleigh and aerosol terms with Kasten's air mass, computed here.
        for (double T : {2.0, 5.0, 9.0})
            for (double thetaDeg : {0.0, 45.0, 80.0, 89.0})
                for (double lambda : {400.0, 550.0, 700.0}) {
                    const double um = lambda / 1000.0;
                    const double m = 1.0 / (std::cos(thetaDeg * kPI / 180.0) + 0.15 * std::pow(93.885 - thetaDeg, -1.253));
                    const double want = std::exp(-0.008735 * std::pow(um, -4.08) * m) * std::exp(-(0.04608 * T - 0.04586) * std::pow(um, -1.3) * m);
                    QVERIFY(std::abs(sunTransmittance(lambda, T, thetaDeg) - want) < 1e-12 + 1e-9 * want);
                }
        // Illuminance: 127.5 klux x the attenuated over the free luminance of a 5778 K spectrum (rectangle
        // rule here; the model uses the trapezoid rule), and the colour reddens as the sun sinks.
        double prevRedOverBlue = 0.0;
        for (double elev : {90.0, 60.0, 30.0, 10.0, 3.0}) {
            const PreethamParams p{.turbidity = 3.0, .sunDirection = glm::vec3(dirFrom(elev, 0.0))};
            const SkySun sun = preethamSun(p, m_cie);
            double att = 0.0, free = 0.0;
            for (size_t i = 0; i < m_cie.xyzBar.size(); ++i) {
                const double l = (m_cie.lambda0 + double(i) * m_cie.step) * 1e-9;
                const double planck = 1.0 / (std::pow(l, 5) * (std::exp(1.438776877e-2 / (l * 5778.0)) - 1.0));
                free += planck * m_cie.xyzBar[i].y;
                att += planck * m_cie.xyzBar[i].y * sunTransmittance(l * 1e9, 3.0, 90.0 - elev);
            }
            QVERIFY2(std::abs(sun.illuminance - 127.5 * att / free) < 2e-3 * sun.illuminance, qPrintable(QString::number(elev)));
            QVERIFY(std::abs(luminance(sun.color) - 1.0f) < 1e-4f);
            const double rb = sun.color.x / std::max(sun.color.z, 1e-6f);
            QVERIFY(rb > prevRedOverBlue);
            prevRedOverBlue = rb;
        }
        // Clear-sky sun at the zenith: 80..110 klux (measured direct normal illuminance is about 100 klux).
        const SkySun high = preethamSun({.turbidity = 2.0, .sunDirection = glm::vec3(0, 1, 0)}, m_cie);
        QVERIFY(high.illuminance > 80.0f && high.illuminance < 110.0f);
        // Blackbody colour when asked, same illuminance.
        const PreethamParams bb{.turbidity = 3.0, .sunDirection = glm::vec3(dirFrom(30.0, 0.0)), .sunColor = SunColorModel::Blackbody,
                                .blackbodyKelvin = 4000.0};
        const SkySun b = preethamSun(bb, m_cie), a = preethamSun({.turbidity = 3.0, .sunDirection = bb.sunDirection}, m_cie);
        QVERIFY(glm::length(b.color - sunColor(4000.0, m_cie)) < 1e-6f);
        QCOMPARE(b.illuminance, a.illuminance);
    }

    void mapShapeErrors()
    {
        for (auto [w, h] : {std::pair{0, 0}, std::pair{1, 8}, std::pair{8, 1}, std::pair{3, 2}, std::pair{100, 100}, std::pair{-2, -1}}) {
            bool threw = false;
            try {
                checkEnvMapShape(w, h, "m.exr");
            } catch (const Error& e) {
                threw = true;
                const std::string msg = e.what();
                QVERIFY2(msg.find("m.exr") == 0 && msg.find(std::to_string(w) + " x " + std::to_string(h)) != std::string::npos, e.what());
            }
            QVERIFY(threw);
        }
        checkEnvMapShape(2, 1, "m");   // the smallest 2:1 map
        EnvMap bad;
        bad.width = 4, bad.height = 2;
        bad.rgb.resize(5);
        QVERIFY_THROWS_EXCEPTION(Error, envMapIntegral(bad));
    }

    void cleaning()
    {
        EnvMap m = testMap(64);
        const float nan = std::numeric_limits<float>::quiet_NaN(), inf = std::numeric_limits<float>::infinity();
        m.ptr(3, 3)[0] = -2.0f;
        m.ptr(4, 3)[1] = -0.5f;
        m.ptr(4, 3)[2] = -0.5f;
        m.ptr(10, 5)[2] = nan;
        m.ptr(11, 5)[0] = inf;
        m.ptr(12, 5)[1] = -inf;
        m.ptr(20, 8)[2] = 5000.0f;   // a single-channel spike (lossy compression)
        m.ptr(40, 10)[0] = m.ptr(40, 10)[1] = m.ptr(40, 10)[2] = 3000.0f;   // a tiny bright source: kept
        const EnvMapCleanReport r = cleanEnvMap(m);
        QCOMPARE(r.negative, size_t(2));
        QCOMPARE(r.nonFinite, size_t(3));
        // Two extremes: the blue spike, and (4, 3), red only once its negative green and blue are cleared
        // (made grey at its luminance).
        QCOMPARE(r.spikes, size_t(2));
        QCOMPARE(m.at(4, 3).x, m.at(4, 3).z);
        for (float v : m.rgb) QVERIFY(std::isfinite(v) && v >= 0.0f);
        QVERIFY(m.ptr(20, 8)[2] < 10.0f);
        QCOMPARE(m.ptr(40, 10)[0], 3000.0f);
        QVERIFY(r.spikeEnergy > 0.0);
        // A 2 x 2 block of blue-only extremes (what DWA compression made of park.exr's sun) turns grey at
        // the same luminance; an ordinary saturated sky pixel is kept.
        EnvMap block = testMap(64);
        for (int y = 10; y < 12; ++y)
            for (int x = 30; x < 32; ++x) block.ptr(x, y)[0] = block.ptr(x, y)[1] = 0.0f, block.ptr(x, y)[2] = 8000.0f;
        block.ptr(5, 5)[0] = 0.1f, block.ptr(5, 5)[1] = 0.3f, block.ptr(5, 5)[2] = 2.5f;
        const glm::vec3 keep = block.at(5, 5);
        const EnvMapCleanReport rb = cleanEnvMap(block);
        QCOMPARE(rb.spikes, size_t(4));
        QVERIFY(glm::length(block.at(30, 10) - glm::vec3(0.0722f * 8000.0f)) < 1e-2f);
        QCOMPARE(block.at(5, 5), keep);
    }

    void sunExtraction()
    {
        // A 2-degree sun of radiance 2e4 at elevation 35, azimuth 130 over a smooth sky.
        EnvMap m = testMap(512, 35.0, 130.0, 2.0e4f, 2.0);
        const EnvMap sky = testMap(512);
        const glm::dvec3 before = directIntegral(m, false), skyOnly = directIntegral(sky, false);
        const FoundSun f = extractSun(m);
        QVERIFY(f.sun.present);
        const double angle = std::acos(std::clamp(glm::dot(glm::dvec3(f.sun.direction), dirFrom(35.0, 130.0)), -1.0, 1.0)) * 180.0 / kPI;
        QVERIFY2(angle < 0.3, qPrintable(QString::number(angle)));
        // Conservation: what the map lost is the sun's power; and the sun's power is the disc's excess.
        const glm::dvec3 after = directIntegral(m, false);
        const glm::dvec3 sunPower(f.sun.radiance());
        QVERIFY(glm::length(after + sunPower - before) < 1e-5 * glm::length(before));
        QVERIFY(std::abs(lumOf(after) - lumOf(skyOnly)) < 0.01 * lumOf(skyOnly));
        QVERIFY(f.sun.solidAngle > 0.0f && f.sun.solidAngle < 0.01f);
        // No compact peak: no sun, map unchanged.
        EnvMap cloudy = testMap(256);
        const std::vector<float> copy = cloudy.rgb;
        QVERIFY(!extractSun(cloudy).sun.present);
        QVERIFY(cloudy.rgb == copy);
        // A broad bright patch (20 degrees) is not a sun either.
        EnvMap broad = testMap(256, 40.0, 0.0, 500.0f, 20.0);
        QVERIFY(!extractSun(broad).sun.present);
        // A map sky rotates its sun and scales it.
        EnvMap m2 = testMap(512, 35.0, 130.0, 2.0e4f, 2.0);
        const Sky s = mapSky(std::move(m2), 50.0f, 2.0f);
        QVERIFY(s.sun.present);
        QVERIFY(glm::length(glm::dvec3(s.sun.direction) - dirFrom(35.0, 180.0)) < 0.01);
        QVERIFY(std::abs(s.sun.illuminance - 2.0f * f.sun.illuminance) < 1e-3f * s.sun.illuminance);
    }

    void mapLookup()
    {
        const EnvMap m = testMap(128);
        const int shift = 8;   // 8 columns = 22.5 degrees
        const EnvMapView v0 = envMapView(m, 0.0f, 1.0f), vr = envMapView(m, 360.0f * shift / 128.0f, 3.0f);
        for (int y = 0; y < m.height; y += 5)
            for (int x = 0; x < m.width; x += 7) {
                const glm::vec3 d = envMapPixelDirection(m.width, m.height, x, y);
                QCOMPARE(envMapRadiance(v0, d), m.at(x, y));
                // Rotation by R adds R to the azimuth, and azimuth falls with the column: the map's pixel
                // (x, y) is now seen at column x - shift.
                const glm::vec3 dr = envMapPixelDirection(m.width, m.height, (x - shift + m.width) % m.width, y);
                QVERIFY(glm::length(envMapRadiance(vr, dr) - 3.0f * m.at(x, y)) < 1e-5f);
            }
    }

    void virtualLightsPower()
    {
        const PreethamParams p{.turbidity = 4.0, .sunDirection = glm::vec3(dirFrom(25.0, 60.0))};
        const EnvMap pre = renderSkyToMap(preethamView(p, m_cie), 256);
        for (const EnvMap* m : {&pre}) {
            const glm::dvec3 total = directIntegral(*m, false);
            for (int n : {16, 100, 256, 1024}) {
                const std::vector<VirtualLight> lights = virtualLights(*m, n);
                QCOMPARE(int(lights.size()), n);
                glm::dvec3 sum(0.0);
                double lo = 1e30, hi = 0.0;
                for (const VirtualLight& l : lights) {
                    sum += glm::dvec3(l.power);
                    lo = std::min(lo, lumOf(glm::dvec3(l.power)));
                    hi = std::max(hi, lumOf(glm::dvec3(l.power)));
                    QVERIFY(std::abs(glm::length(l.direction) - 1.0f) < 1e-5f);
                }
                QVERIFY2(glm::length(sum - total) < 1e-6 * glm::length(total), qPrintable(QString::number(n)));
                // Roughly equal power: within 4x of each other (cuts fall between pixel rows and columns;
                // 1024 regions of a 256 x 128 map hold 32 pixels each).
                qInfo("N %4d: light power %.4g .. %.4g (mean %.4g)", n, lo, hi, lumOf(total) / n);
                QVERIFY2(hi < 4.0 * lo, qPrintable(QString("N %1: %2 .. %3").arg(n).arg(lo).arg(hi)));
            }
        }
        QVERIFY_THROWS_EXCEPTION(Error, virtualLights(pre, 0));
        QVERIFY_THROWS_EXCEPTION(Error, virtualLights(pre, 70000));
    }

    void virtualLightsIrradianceConverges()
    {
        for (int which = 0; which < 2; ++which) {
            EnvMap m = which == 0 ? testMap(256, 50.0, 300.0, 40.0f, 10.0)
                                  : renderSkyToMap(preethamView({.turbidity = 2.5, .sunDirection = glm::vec3(dirFrom(15.0, 200.0))}, m_cie), 256);
            const double want = lumOf(directIntegral(m, true));
            double prevErr = 1e30;
            for (int n : {16, 64, 256, 1024}) {
                glm::dvec3 e(0.0);
                for (const VirtualLight& l : virtualLights(m, n)) e += glm::dvec3(l.power) * std::max(0.0, double(l.direction.y));
                const double err = std::abs(lumOf(e) - want) / want;
                qInfo("map %d, N %4d: irradiance %.6g vs %.6g, relative error %.2e", which, n, lumOf(e), want, err);
                QVERIFY(err < prevErr * 1.05 || err < 1e-3);
                prevErr = err;
                if (n == 1024) QVERIFY2(err < 0.005, qPrintable(QString::number(err)));
            }
        }
    }

    void rotatedMapRotatesLights()
    {
        // The blob at azimuth 40: the brightest light points there; rotated by 70, at azimuth 110.
        const EnvMap m = testMap(256, 30.0, 40.0, 200.0, 5.0);
        for (float rot : {0.0f, 70.0f, -135.0f}) {
            const std::vector<VirtualLight> lights = virtualLights(m, 64, rot);
            const VirtualLight* best = &lights[0];
            for (const VirtualLight& l : lights)
                if (lumOf(glm::dvec3(l.power)) / l.solidAngle > lumOf(glm::dvec3(best->power)) / best->solidAngle) best = &l;
            const double angle = std::acos(std::clamp(glm::dot(glm::dvec3(best->direction), dirFrom(30.0, 40.0 + rot)), -1.0, 1.0)) * 180.0 / kPI;
            QVERIFY2(angle < 5.0, qPrintable(QString("rotation %1: %2 degrees off").arg(rot).arg(angle)));
        }
        // Rotating by R is the unrotated lights turned by R, power unchanged.
        const std::vector<VirtualLight> a = virtualLights(m, 128, 0.0f), b = virtualLights(m, 128, 37.0f);
        QCOMPARE(a.size(), b.size());
        const float r = 37.0f * float(kPI) / 180.0f;
        for (size_t i = 0; i < a.size(); ++i) {
            QVERIFY(glm::length(rotateAzimuth(a[i].direction, std::cos(r), std::sin(r)) - b[i].direction) < 1e-5f);
            QCOMPARE(a[i].power, b[i].power);
        }
        // A map whose columns are shifted left by a quarter is the map turned by +90 degrees: a plane facing n
        // receives from its lights what a plane facing n turned by -90 receives from the original's.
        EnvMap shifted = m;
        for (int y = 0; y < m.height; ++y)
            for (int x = 0; x < m.width; ++x) {
                const glm::vec3 c = m.at(x, y);
                float* p = shifted.ptr((x - m.width / 4 + m.width) % m.width, y);
                p[0] = c.x, p[1] = c.y, p[2] = c.z;
            }
        for (glm::dvec3 n : {glm::dvec3(1, 0, 0), glm::dvec3(0, 0, 1), glm::dvec3(0.6, 0.8, 0)}) {
            const glm::dvec3 back(glm::vec3(rotateAzimuth(glm::vec3(n), 0.0f, -1.0f)));
            double e1 = 0.0, e0 = 0.0;
            for (const VirtualLight& l : virtualLights(shifted, 1024)) e1 += lumOf(glm::dvec3(l.power)) * std::max(0.0, glm::dot(glm::dvec3(l.direction), n));
            for (const VirtualLight& l : virtualLights(m, 1024)) e0 += lumOf(glm::dvec3(l.power)) * std::max(0.0, glm::dot(glm::dvec3(l.direction), back));
            QVERIFY2(std::abs(e1 - e0) < 0.01 * e0, qPrintable(QString("%1 vs %2").arg(e1).arg(e0)));
        }
    }

    void interleaving()
    {
        for (int n : {16, 64, 100, 1024})
            for (int k : {1, 4, 6, 7, 16}) {
                const Interleave il = makeInterleave(k, n);
                QCOMPARE(il.blockWidth * il.blockHeight, il.subsets);
                QVERIFY(il.blockWidth <= il.blockHeight);
                // Every light in exactly one subset.
                std::vector<int> seen(size_t(n), 0);
                for (int s = 0; s < il.subsets; ++s)
                    for (int j = 0; j < subsetSize(il, s, n); ++j) seen[size_t(subsetLight(il, s, j))] += 1;
                for (int c : seen) QCOMPARE(c, 1);
                // A block uses every subset once per sample, a pixel every subset over K samples.
                for (int s = 0; s < 3; ++s) {
                    std::set<int> used;
                    for (int y = 5; y < 5 + il.blockHeight; ++y)
                        for (int x = 9; x < 9 + il.blockWidth; ++x) used.insert(interleavedSubset(il, x, y, s));
                    QCOMPARE(int(used.size()), il.subsets);
                }
                std::set<int> overSamples;
                for (int s = 0; s < il.subsets; ++s) overSamples.insert(interleavedSubset(il, 13, 2, s));
                QCOMPARE(int(overSamples.size()), il.subsets);
                // Unbiased: the mean over subsets of K x (subset sum) is the total.
                double total = 0.0, mean = 0.0;
                for (int j = 0; j < n; ++j) total += 1.0 + 0.01 * j * j;
                for (int s = 0; s < il.subsets; ++s) {
                    double sum = 0.0;
                    for (int j = 0; j < subsetSize(il, s, n); ++j) {
                        const int idx = subsetLight(il, s, j);
                        sum += 1.0 + 0.01 * idx * idx;
                    }
                    mean += interleaveWeight(il) * sum / il.subsets;
                }
                QVERIFY(std::abs(mean - total) < 1e-9 * total);
            }
        QCOMPARE(makeInterleave(16, 4).subsets, 4);   // no more subsets than lights
        QCOMPARE(makeInterleave(12, 100).blockWidth, 3);
    }

    void sunPositionNoaa()
    {
        // NREL SPA's example (Reda & Andreas, "Solar Position Algorithm for Solar Radiation Applications",
        // NREL/TP-560-34302, 2004/2008, Table A4-1): 2003-10-17 12:30:30 at UTC-7, latitude 39.742476,
        // longitude -105.1786: topocentric zenith 50.11162 degrees (refracted, 820 mbar, 11 C), azimuth
        // 194.34024 degrees east of north.
        const SunPosition spa = noaaSunPosition({.year = 2003, .month = 10, .day = 17, .hour = 12.0 + 30.5 / 60.0, .timeZoneHours = -7.0,
                                                 .latitudeDeg = 39.742476, .longitudeDeg = -105.1786});
        qInfo("SPA example: elevation %.5f (SPA %.5f), compass azimuth %.5f (SPA 194.34024)", spa.elevationDeg, 90.0 - 50.11162, spa.compassAzimuthDeg);
        QVERIFY(std::abs(spa.elevationDeg - (90.0 - 50.11162)) < 0.02);
        QVERIFY(std::abs(spa.compassAzimuthDeg - 194.34024) < 0.02);
        QVERIFY(std::abs(spa.azimuthDeg - (180.0 - 194.34024 + 360.0)) < 0.02);
        QVERIFY(glm::length(spa.direction - sunDirection(spa.elevationDeg, spa.azimuthDeg)) < 1e-5f);
        // Meeus, "Astronomical Algorithms" (2nd ed.), examples 25.a and 28.b: 1992 October 13, 0h TD (UT
        // 59 s earlier): apparent declination -7.78507 degrees, equation of time +13m 42.6s.
        const SunPosition meeus = noaaSunPosition({.year = 1992, .month = 10, .day = 13, .hour = 0.0, .latitudeDeg = 0.0, .longitudeDeg = 0.0});
        QVERIFY(std::abs(meeus.julianDay - 2448908.5) < 1e-9);   // Meeus example 25.a's JDE (UT here)
        qInfo("Meeus 25.a/28.b: declination %.5f (-7.78507), equation of time %.3f min (13.710)", meeus.declinationDeg, meeus.equationOfTimeMin);
        QVERIFY(std::abs(meeus.declinationDeg - (-7.78507)) < 0.01);
        QVERIFY(std::abs(meeus.equationOfTimeMin - (13.0 + 42.6 / 60.0)) < 0.1);
        // Julian day of Meeus example 7.a: 1957 October 4.81 = JD 2436116.31.
        QVERIFY(std::abs(julianDay(1957, 10, 4, 0.81 * 24.0) - 2436116.31) < 1e-6);
        // Geography: a northern morning sun stands in the east (+X), the noon sun in the south (+Z).
        const SunPosition morning = noaaSunPosition({.year = 2024, .month = 6, .day = 21, .hour = 8.0, .timeZoneHours = 2.0, .latitudeDeg = 48.1, .longitudeDeg = 11.6});
        QVERIFY(morning.direction.x > 0.5f && morning.elevationDeg > 10.0);
        const SunPosition noon = noaaSunPosition({.year = 2024, .month = 3, .day = 20, .hour = 12.0, .timeZoneHours = 0.0, .latitudeDeg = 45.0, .longitudeDeg = 0.0});
        QVERIFY(noon.direction.z > 0.7f && std::abs(noon.direction.x) < 0.05f);
        QVERIFY(std::abs(noon.elevationDeg - 45.0) < 1.0);   // equinox: 90 - latitude (declination ~0, refraction)
        // The almanac's June solstice of 2024 (USNO: June 20, 20:51 UT): the sun's apparent longitude is 90
        // degrees, so its apparent declination is the true obliquity of the ecliptic, computed here by Meeus
        // (22.2: mean obliquity; chapter 22's nutation in obliquity, its four leading terms); a day either
        // side it is lower by the second-order fall (under 0.01 degrees).
        const SunPosition solstice = noaaSunPosition({.year = 2024, .month = 6, .day = 20, .hour = 20.0 + 51.0 / 60.0});
        const double tc = (solstice.julianDay - 2451545.0) / 36525.0, rad = kPiD / 180.0;
        const double omega = (125.04452 - 1934.136261 * tc) * rad, lSun = (280.4665 + 36000.7698 * tc) * rad,
                     lMoon = (218.3165 + 481267.8813 * tc) * rad;
        const double obliquity = 23.0 + 26.0 / 60.0 + (21.448 - tc * (46.8150 + tc * (0.00059 - tc * 0.001813))) / 3600.0 +
                                 (9.20 * std::cos(omega) + 0.57 * std::cos(2.0 * lSun) + 0.10 * std::cos(2.0 * lMoon) - 0.09 * std::cos(2.0 * omega)) / 3600.0;
        qInfo("June solstice 2024: declination %.5f (true obliquity %.5f)", solstice.declinationDeg, obliquity);
        QVERIFY(std::abs(solstice.declinationDeg - obliquity) < 0.002);
        for (int day : {19, 21}) {
            const double d = noaaSunPosition({.year = 2024, .month = 6, .day = day, .hour = 20.0 + 51.0 / 60.0}).declinationDeg;
            QVERIFY(d < solstice.declinationDeg && d > solstice.declinationDeg - 0.01);
        }
        // The text forms read back.
        int y = 0, mo = 0, d = 0;
        double h = 0.0;
        QVERIFY(parseSunDate("2024-02-29", &y, &mo, &d) && y == 2024 && mo == 2 && d == 29);
        QVERIFY(parseSunTime("08:30", &h) && h == 8.5);
        QVERIFY(parseSunTime("12:30:30", &h) && std::abs(h - (12.0 + 30.5 / 60.0)) < 1e-12);
        QCOMPARE(formatSunTime(12.0 + 30.5 / 60.0), std::string("12:30:30"));
        QCOMPARE(formatSunTime(8.5), std::string("08:30"));
        QVERIFY(parseSunTime(formatSunTime(7.123456), &h) && std::abs(h - 7.123456) < 1e-6);
        QCOMPARE(formatSunDate({.year = 987 + 1000, .month = 3, .day = 4}), std::string("1987-03-04"));
        for (const char* bad : {"2024-6-1x", "24-06-21", "2024/06/21", ""}) QVERIFY(!parseSunDate(bad, &y, &mo, &d));
        for (const char* bad : {"8:30", "08:60", "08:30:60", "08h30", "08:30x", ""}) QVERIFY(!parseSunTime(bad, &h));
        // Bad input names the field.
        for (SunPlace bad : {SunPlace{.month = 13}, SunPlace{.year = 2023, .month = 2, .day = 29}, SunPlace{.hour = 25.0},
                             SunPlace{.timeZoneHours = 15.0}, SunPlace{.latitudeDeg = 91.0}, SunPlace{.longitudeDeg = std::nan("")}})
            QVERIFY_THROWS_EXCEPTION(Error, noaaSunPosition(bad));
        noaaSunPosition({.year = 2024, .month = 2, .day = 29});   // a leap day exists
    }

    void latticeShares()
    {
        // A constant sky over the six axes: each gets 4 pi / 6 x L (to pixel-assignment rounding).
        SkySun none;
        const Sky c = constantSky(glm::vec3(1.0f, 2.0f, 3.0f), none);
        const std::vector<glm::vec3> axes = {{1, 0, 0}, {-1, 0, 0}, {0, 2, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
        const std::vector<glm::dvec3> shares = skyDirectionShares(c, axes, 512);
        glm::dvec3 sum(0.0);
        for (const glm::dvec3& s : shares) {
            QVERIFY(glm::length(s - glm::dvec3(1, 2, 3) * (4.0 * kPI / 6.0)) < 0.01 * glm::length(glm::dvec3(1, 2, 3)) * 4.0 * kPI / 6.0);
            sum += s;
        }
        QVERIFY(glm::length(sum - skyTotal(c)) < 1e-9 * glm::length(sum));
        QVERIFY(glm::length(skyTotal(c) - glm::dvec3(1, 2, 3) * 4.0 * kPI) < 1e-6 * 4.0 * kPI * 3.75);
        // A map sky: shares sum to the rotated map's integral; rotation moves them.
        EnvMap m = testMap(128, 30.0, 90.0, 50.0f, 10.0);   // blob toward +X
        const Sky ms = mapSky(m, 90.0f, 1.0f, false), m0 = mapSky(m, 0.0f, 1.0f, false);
        const std::vector<glm::dvec3> rs = skyDirectionShares(ms, axes), s0 = skyDirectionShares(m0, axes);
        QVERIFY(lumOf(s0[0]) > lumOf(s0[4]));       // unrotated: the blob is nearest +X
        QVERIFY(lumOf(rs[5]) > lumOf(rs[0]));       // rotated by 90: toward azimuth 180, -Z
        glm::dvec3 rsum(0.0);
        for (const glm::dvec3& s : rs) rsum += s;
        QVERIFY(glm::length(rsum - directIntegral(m, false)) < 1e-6 * glm::length(rsum));
        QVERIFY_THROWS_EXCEPTION(Error, skyDirectionShares(c, {glm::vec3(0.0f)}));
        // The LB's D3Q19 moving directions: a constant sky gives the 6 axial directions equal shares and the
        // 12 diagonal ones equal shares (the lattice's symmetry), summing to 4 pi L.
        std::vector<glm::vec3> d3q19;
        for (int q = 1; q < lb::kDirections; ++q) d3q19.emplace_back(float(lb::kC[q][0]), float(lb::kC[q][1]), float(lb::kC[q][2]));
        const std::vector<glm::dvec3> lat = skyDirectionShares(constantSky(glm::vec3(1.0f), none), d3q19, 1024);
        double total = 0.0;
        for (int q = 1; q < lb::kDirections; ++q) {
            const double ref = lb::isAxial(q) ? lat[0].x : lat[6].x;
            QVERIFY2(std::abs(lat[size_t(q - 1)].x - ref) < 0.01 * ref, qPrintable(QString("direction %1: %2 vs %3").arg(q).arg(lat[size_t(q - 1)].x).arg(ref)));
            total += lat[size_t(q - 1)].x;
        }
        QVERIFY(std::abs(total - 4.0 * kPI) < 1e-6);
    }
};

QTEST_APPLESS_MAIN(TestSky)
#include "tst_sky.moc"
