// Colour science on the host: the CIE 1931 observer table, blackbody (Planck) colours, XYZ -> linear sRGB.
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include <glm/glm.hpp>

namespace sylva {

// CIE colour matching functions sampled on a uniform wavelength grid: sample i is at
// lambda0 + i * step nanometres; xyzBar[i] = (xbar, ybar, zbar), dimensionless. 24 bytes per sample.
struct CieTable {
    double lambda0 = 0.0;   // nm, first sample
    double step = 0.0;      // nm, > 0
    std::vector<glm::dvec3> xyzBar;
};

// Parses "lambda_nm,xbar,ybar,zbar" CSV text: '#' comment lines, one optional header line, blank lines
// and CRLF are accepted; the wavelengths must be finite, strictly increasing and uniformly spaced.
// Throws sylva::Error naming the line and the problem otherwise.
CieTable parseCieCsv(std::string_view text);

// Reads and parses a CMF table file (e.g. resources/color/cie1931_2deg_xyz_cmf_360-830_1nm.csv).
// Throws sylva::Error naming the file when it cannot be read or is malformed.
CieTable loadCieCsv(const std::string& path);

// Limits of the blackbody temperature accepted by blackbodyXyz and sunColor, in kelvin.
inline constexpr double kMinBlackbodyKelvin = 1000.0;
inline constexpr double kMaxBlackbodyKelvin = 40000.0;

// Tristimulus values of a blackbody at `kelvin`: Planck's spectral radiance
// B(lambda, T) = 2 h c^2 / lambda^5 / (exp(h c / (lambda k_B T)) - 1) in W sr^-1 m^-2 m^-1 (SI 2019 exact
// h, c, k_B), integrated against the CMFs over the table's range (trapezoid rule, lambda in metres).
// The result is CMF-weighted radiance in W sr^-1 m^-2 (no 683 lm/W factor); Y is proportional to luminance.
// Throws sylva::Error unless kelvin is finite and in [1000, 40000], or when the table is empty.
glm::dvec3 blackbodyXyz(double kelvin, const CieTable& cie);

// CIE xy chromaticity: (X, Y) / (X + Y + Z); (0, 0) when X + Y + Z is 0.
glm::dvec2 chromaticity(glm::dvec3 xyz);

// CIE XYZ -> linear sRGB (Rec. 709 primaries, D65 white), the IEC 61966-2-1 matrix. No clamping.
glm::dvec3 xyzToLinearSrgb(glm::dvec3 xyz);

// The linear-sRGB colour of a blackbody sun at `kelvin`: out-of-gamut (negative) components clamped to 0,
// then scaled so that its Rec. 709 luminance (sylva::luminance) is 1. Same validation as blackbodyXyz.
glm::vec3 sunColor(double kelvin, const CieTable& cie);

} // namespace sylva
