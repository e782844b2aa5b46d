// Preetham, Shirley & Smits, "A Practical Analytic Model for Daylight" (SIGGRAPH 1999): the host side that
// turns a turbidity and a sun direction into the per-ray PreethamSky (core/sky/sky.h) and its sun.
#pragma once

#include <glm/glm.hpp>

#include "core/sky/sky.h"

namespace sylva {
struct CieTable;
}

namespace sylva::sky {

inline constexpr double kMinTurbidity = 2.0, kMaxTurbidity = 10.0;
inline constexpr double kMinSunElevationDeg = -10.0;   // below: refused (the model is continued only to -10)

// The paper's tables (Appendix A.2), linear in turbidity T: coefficient k of quantity q (0 = Y, 1 = x,
// 2 = y) is perezTable[q][k][0] * T + perezTable[q][k][1].
extern const double kPerezTable[3][5][2];

// The paper's zenith formulas (Appendix A.2); thetaSun in radians from the zenith (0 .. pi/2).
// Luminance in kcd/m^2: (4.0453 T - 4.9710) tan(chi) - 0.2155 T + 2.4192, chi = (4/9 - T/120)(pi - 2 theta_s).
double zenithLuminancePaper(double turbidity, double thetaSun);
// Chromaticity x (which = 0) or y (which = 1): [T^2 T 1] M [theta^3 theta^2 theta 1]^T.
double zenithChromaticityPaper(double turbidity, double thetaSun, int which);

enum class SunColorModel {
    Atmosphere,   // the paper's attenuation along the sun's path (Rayleigh + Angstrom aerosol, Appendix A.2)
    Blackbody     // the seed-000 blackbody at blackbodyKelvin (sylva::sunColor), same illuminance
};

struct PreethamParams {
    double turbidity = 3.0;                    // 2 .. 10
    glm::vec3 sunDirection{0.4f, 0.8f, 0.3f};  // toward the sun, any length; elevation >= -10 degrees
    float scale = 1.0f;                        // multiplies sky and sun (kcd/m^2 -> the renderer's unit)
    SunColorModel sunColor = SunColorModel::Atmosphere;
    double blackbodyKelvin = 6500.0;
};

// The sky of the parameters. Above the horizon: the paper's model. Sun below the horizon (elevation 0 ..
// -10 degrees): the paper does not cover it; the Perez distribution is evaluated with the true sun angle,
// the zenith chromaticity is held at its horizon value (theta_s = 90 degrees) and the zenith luminance is
// its horizon value x 10^(elevation / 2.5 degrees) (a twilight fall of about 250x by -6 degrees; our
// continuation, continuous at 0, never negative). Throws sylva::Error for a turbidity outside 2 .. 10, a
// zero or non-finite direction, or an elevation below -10 degrees (by more than 0.001: float directions).
PreethamSky makePreetham(const PreethamParams& params);

// Atmospheric transmittance toward the sun at wavelength lambda (nanometres), the paper's Appendix A.2:
// Rayleigh exp(-0.008735 lambda_um^-4.08 m) x aerosol exp(-beta lambda_um^-1.3 m), beta = 0.04608 T -
// 0.04586, relative optical mass m = 1 / (cos theta_s + 0.15 (93.885 - theta_s_deg)^-1.253) (Kasten). The
// ozone, mixed-gas and water-vapour terms (tabulated absorption bands) are left out.
double sunTransmittance(double lambdaNm, double turbidity, double thetaSunDeg);

// The vertical optical depths of the whole atmosphere at sea level (relative optical mass 1) that
// sunTransmittance scales by the optical mass: Rayleigh 0.008735 lambda_um^-4.08 and aerosol
// beta lambda_um^-1.3 (beta = 0.04608 T - 0.04586). The aerial perspective's extinction is built from them
// (core/render/surfaces/atmosphere.h), so distant slopes fade with the same air the sun's colour comes through.
double rayleighOpticalDepth(double lambdaNm);
double aerosolOpticalDepth(double lambdaNm, double turbidity);

// Extraterrestrial solar illuminance at normal incidence, klux (the IES solar illuminance constant).
inline constexpr double kSolarIlluminanceKlux = 127.5;
// Angular radius of the sun's disc, degrees (solid angle 6.8e-5 sr).
inline constexpr double kSunRadiusDeg = 0.2666;

// The model's sun: extraterrestrial spectrum taken as a 5778 K blackbody, attenuated by sunTransmittance
// and integrated against the CIE table: colour (luminance 1; or the blackbody's at blackbodyKelvin) and
// illuminance kSolarIlluminanceKlux x (attenuated Y / unattenuated Y) x scale. The disc sets below the
// horizon linearly over its diameter (elevation +r .. -r), then present = false.
SkySun preethamSun(const PreethamParams& params, const CieTable& cie);

// The sky view of a Preetham sky with its sun.
SkyView preethamView(const PreethamParams& params, const CieTable& cie);

} // namespace sylva::sky
