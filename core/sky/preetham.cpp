// Preetham, Shirley & Smits 1999, host side. Source of every constant: A. J. Preetham, P. Shirley,
// B. Smits, "A Practical Analytic Model for Daylight", SIGGRAPH 99, Appendix A.2 (the Perez coefficient
// tables, the zenith luminance and chromaticity formulas, the sun's attenuation).
#include "core/sky/preetham.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "core/base/error.h"
#include "core/color/color.h"

namespace sylva::sky {

// [Y, x, y][A..E][slope in T, intercept]
const double kPerezTable[3][5][2] = {
    {{0.1787, -1.4630}, {-0.3554, 0.4275}, {-0.0227, 5.3251}, {0.1206, -2.5771}, {-0.0670, 0.3703}},
    {{-0.0193, -0.2592}, {-0.0665, 0.0008}, {-0.0004, 0.2125}, {-0.0641, -0.8989}, {-0.0033, 0.0452}},
    {{-0.0167, -0.2608}, {-0.0950, 0.0092}, {-0.0079, 0.2102}, {-0.0441, -1.6537}, {-0.0109, 0.0529}},
};

namespace {

// Zenith chromaticity matrices: rows T^2, T, 1; columns theta^3, theta^2, theta, 1.
const double kZenithX[3][4] = {
    {0.00166, -0.00375, 0.00209, 0.0}, {-0.02903, 0.06377, -0.03202, 0.00394}, {0.11693, -0.21196, 0.06052, 0.25886}};
const double kZenithY[3][4] = {
    {0.00275, -0.00610, 0.00317, 0.0}, {-0.04214, 0.08970, -0.04153, 0.00516}, {0.15346, -0.26756, 0.06670, 0.26688}};

constexpr double kHalfPi = kPiD / 2.0;
constexpr double kTwilightDegPerDecade = 2.5;
constexpr double kSolarKelvin = 5778.0;   // the extraterrestrial sun's spectrum, as a blackbody

double perezD(const double c[5], double cosTheta, double gamma)
{
    const double ct = std::max(cosTheta, 1e-4);
    const double cg = std::cos(gamma);
    return (1.0 + c[0] * std::exp(c[1] / ct)) * (1.0 + c[2] * std::exp(c[3] * gamma) + c[4] * cg * cg);
}

struct SunAngles {
    glm::dvec3 dir;
    double elevationDeg, thetaSun;
};

SunAngles checkParams(const PreethamParams& p)
{
    if (!std::isfinite(p.turbidity) || p.turbidity < kMinTurbidity || p.turbidity > kMaxTurbidity)
        throw Error("Preetham sky: turbidity must be in 2 .. 10, got " + std::to_string(p.turbidity));
    if (!std::isfinite(p.scale) || p.scale < 0.0f) throw Error("Preetham sky: scale must be finite and >= 0");
    const glm::dvec3 d(p.sunDirection);
    const double len = glm::length(d);
    if (!std::isfinite(len) || len <= 0.0) throw Error("Preetham sky: the sun direction must be finite and non-zero");
    SunAngles a;
    a.dir = d / len;
    a.elevationDeg = std::asin(std::clamp(a.dir.y, -1.0, 1.0)) * 180.0 / kPiD;
    if (a.elevationDeg < kMinSunElevationDeg - 1e-3)
        throw Error("Preetham sky: sun elevation " + std::to_string(a.elevationDeg) + " degrees is below the model's -10");
    a.thetaSun = kHalfPi - a.elevationDeg * kPiD / 180.0;
    return a;
}

} // namespace

double zenithLuminancePaper(double T, double thetaSun)
{
    const double chi = (4.0 / 9.0 - T / 120.0) * (kPiD - 2.0 * thetaSun);
    return (4.0453 * T - 4.9710) * std::tan(chi) - 0.2155 * T + 2.4192;
}

double zenithChromaticityPaper(double T, double thetaSun, int which)
{
    const double(&m)[3][4] = which == 0 ? kZenithX : kZenithY;
    const double th[4] = {thetaSun * thetaSun * thetaSun, thetaSun * thetaSun, thetaSun, 1.0};
    const double tt[3] = {T * T, T, 1.0};
    double v = 0.0;
    for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 4; ++c) v += tt[r] * m[r][c] * th[c];
    return v;
}

PreethamSky makePreetham(const PreethamParams& params)
{
    const SunAngles a = checkParams(params);
    const double T = params.turbidity;
    PreethamSky s;
    s.sunDirection = glm::vec3(a.dir);
    s.scale = params.scale;
    double coef[3][5];
    for (int q = 0; q < 3; ++q)
        for (int k = 0; k < 5; ++k) {
            coef[q][k] = kPerezTable[q][k][0] * T + kPerezTable[q][k][1];
            s.perez[q][k] = float(coef[q][k]);
        }
    const double thetaAbove = std::min(a.thetaSun, kHalfPi);
    double Yz = zenithLuminancePaper(T, thetaAbove);
    if (a.elevationDeg < 0.0) Yz *= std::pow(10.0, a.elevationDeg / kTwilightDegPerDecade);
    s.zenith[0] = float(std::max(Yz, 0.0));
    s.zenith[1] = float(zenithChromaticityPaper(T, thetaAbove, 0));
    s.zenith[2] = float(zenithChromaticityPaper(T, thetaAbove, 1));
    // F(0, theta_s): the zenith's own Perez value (view zenith angle 0, angle to the sun theta_s).
    for (int q = 0; q < 3; ++q) s.norm[q] = float(perezD(coef[q], 1.0, a.thetaSun));
    return s;
}

double sunTransmittance(double lambdaNm, double turbidity, double thetaSunDeg)
{
    const double cosT = std::cos(thetaSunDeg * kPiD / 180.0);
    const double base = std::max(93.885 - thetaSunDeg, 1e-6);   // the formula's pole lies past the horizon
    const double m = 1.0 / (std::max(cosT, 0.0) + 0.15 * std::pow(base, -1.253));
    return std::exp(-rayleighOpticalDepth(lambdaNm) * m) * std::exp(-aerosolOpticalDepth(lambdaNm, turbidity) * m);
}

double rayleighOpticalDepth(double lambdaNm) { return 0.008735 * std::pow(lambdaNm / 1000.0, -4.08); }

double aerosolOpticalDepth(double lambdaNm, double turbidity)
{
    const double beta = 0.04608 * turbidity - 0.04586;
    return beta * std::pow(lambdaNm / 1000.0, -1.3);
}

SkySun preethamSun(const PreethamParams& params, const CieTable& cie)
{
    const SunAngles a = checkParams(params);
    if (cie.xyzBar.empty() || !(cie.step > 0.0)) throw Error("Preetham sun: empty CIE table");
    SkySun sun;
    sun.direction = glm::vec3(a.dir);
    sun.solidAngle = float(2.0 * kPiD * (1.0 - std::cos(kSunRadiusDeg * kPiD / 180.0)));
    const double setFraction = std::clamp((a.elevationDeg + kSunRadiusDeg) / (2.0 * kSunRadiusDeg), 0.0, 1.0);
    // Spectral integration (the blackbody's own Planck formula through blackbodyXyz would lose the
    // per-wavelength attenuation, so the CMFs are integrated here with the same trapezoid rule).
    const double thetaDeg = std::min(a.thetaSun * 180.0 / kPiD, 90.0 + kSunRadiusDeg);
    glm::dvec3 att(0.0), free(0.0);
    const size_t n = cie.xyzBar.size();
    for (size_t i = 0; i < n; ++i) {
        const double lambda = cie.lambda0 + double(i) * cie.step;
        const double lm = lambda * 1e-9;
        const double planck = 1.0 / (std::pow(lm, 5.0) * (std::exp(0.014387768775039337 / (lm * kSolarKelvin)) - 1.0));
        const double w = (i == 0 || i + 1 == n) ? 0.5 : 1.0;
        free += w * planck * cie.xyzBar[i];
        att += w * planck * sunTransmittance(lambda, params.turbidity, thetaDeg) * cie.xyzBar[i];
    }
    if (!(free.y > 0.0)) throw Error("Preetham sun: the CIE table gives no luminance");
    const double ratio = att.y / free.y;
    if (params.sunColor == SunColorModel::Blackbody) {
        sun.color = sunColor(params.blackbodyKelvin, cie);
    } else if (att.y > 0.0) {
        const glm::vec3 rgb(glm::max(xyzToLinearSrgb(att / att.y), glm::dvec3(0.0)));
        const float lum = 0.2126f * rgb.x + 0.7152f * rgb.y + 0.0722f * rgb.z;
        sun.color = lum > 0.0f ? rgb / lum : glm::vec3(1.0f);
    }
    sun.illuminance = float(kSolarIlluminanceKlux * ratio * setFraction * double(params.scale));
    sun.present = sun.illuminance > 0.0f;
    if (!sun.present) sun.illuminance = 0.0f;
    return sun;
}

SkyView preethamView(const PreethamParams& params, const CieTable& cie)
{
    SkyView v;
    v.kind = SkyKind::Preetham;
    v.preetham = makePreetham(params);
    v.sun = preethamSun(params, cie);
    return v;
}

} // namespace sylva::sky
