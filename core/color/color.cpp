// CIE table parsing, Planck's law against the CMFs, XYZ -> linear sRGB, sun colours.
#include "core/color/color.h"

#include <charconv>
#include <cmath>
#include <fstream>
#include <sstream>

#include "core/base/error.h"
#include "core/render/tonemap.h"

namespace sylva {

namespace {

std::string fmt(double v)
{
    std::ostringstream s;
    s.precision(10);
    s << v;
    return s.str();
}

std::string_view trim(std::string_view s)
{
    const auto isSpace = [](char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\f' || c == '\v'; };
    while (!s.empty() && isSpace(s.front())) s.remove_prefix(1);
    while (!s.empty() && isSpace(s.back())) s.remove_suffix(1);
    return s;
}

[[noreturn]] void failAt(size_t line, const std::string& what)
{
    throw Error("CIE table line " + std::to_string(line) + ": " + what);
}

double parseField(std::string_view field, size_t line, const char* name)
{
    field = trim(field);
    double v = 0.0;
    const auto [end, ec] = std::from_chars(field.data(), field.data() + field.size(), v);
    if (field.empty() || ec != std::errc() || end != field.data() + field.size())
        failAt(line, std::string(name) + " '" + std::string(field) + "' is not a number");
    if (!std::isfinite(v)) failAt(line, std::string(name) + " '" + std::string(field) + "' is not finite");
    return v;
}

void validateKelvin(double kelvin)
{
    if (!std::isfinite(kelvin))
        throw Error("blackbody temperature " + fmt(kelvin) + " K is not finite (must be in [" +
                    fmt(kMinBlackbodyKelvin) + ", " + fmt(kMaxBlackbodyKelvin) + "] K)");
    if (kelvin < kMinBlackbodyKelvin)
        throw Error("blackbody temperature " + fmt(kelvin) + " K is below the minimum " + fmt(kMinBlackbodyKelvin) + " K");
    if (kelvin > kMaxBlackbodyKelvin)
        throw Error("blackbody temperature " + fmt(kelvin) + " K is above the maximum " + fmt(kMaxBlackbodyKelvin) + " K");
}

} // namespace

CieTable parseCieCsv(std::string_view text)
{
    CieTable table;
    std::vector<double> lambdas;
    bool headerSeen = false;
    size_t lineNo = 0;
    while (!text.empty()) {
        const size_t nl = text.find('\n');
        std::string_view line = trim(text.substr(0, nl));
        text = nl == std::string_view::npos ? std::string_view() : text.substr(nl + 1);
        ++lineNo;
        if (line.empty() || line.front() == '#') continue;
        const char c0 = line.front();
        const bool numeric = (c0 >= '0' && c0 <= '9') || c0 == '-' || c0 == '+' || c0 == '.';
        if (!numeric) {
            if (headerSeen || !lambdas.empty())
                failAt(lineNo, "unexpected text '" + std::string(line) + "' (only one header line, before the data, is allowed)");
            headerSeen = true;
            continue;
        }
        std::string_view fields[4];
        size_t count = 0;
        for (std::string_view rest = line;;) {
            const size_t comma = rest.find(',');
            if (count < 4) fields[count] = rest.substr(0, comma);
            ++count;
            if (comma == std::string_view::npos) break;
            rest = rest.substr(comma + 1);
        }
        if (count != 4) failAt(lineNo, "expected 4 comma-separated fields (lambda_nm,xbar,ybar,zbar), found " + std::to_string(count));
        const double lambda = parseField(fields[0], lineNo, "wavelength");
        const glm::dvec3 bar(parseField(fields[1], lineNo, "xbar"), parseField(fields[2], lineNo, "ybar"),
                             parseField(fields[3], lineNo, "zbar"));
        if (lambda <= 0.0) failAt(lineNo, "wavelength " + fmt(lambda) + " nm must be > 0");
        if (bar.x < 0.0 || bar.y < 0.0 || bar.z < 0.0) failAt(lineNo, "colour matching values must be >= 0");
        if (!lambdas.empty() && lambda <= lambdas.back())
            failAt(lineNo, "wavelength " + fmt(lambda) + " nm does not increase (previous " + fmt(lambdas.back()) + " nm)");
        if (lambdas.size() >= 2) {
            const double step = lambdas[1] - lambdas[0];
            const double expected = lambdas[0] + double(lambdas.size()) * step;
            if (std::fabs(lambda - expected) > 1e-6 * step)
                failAt(lineNo, "wavelength " + fmt(lambda) + " nm breaks the uniform spacing of " + fmt(step) +
                                   " nm (expected " + fmt(expected) + " nm)");
        }
        lambdas.push_back(lambda);
        table.xyzBar.push_back(bar);
    }
    if (lambdas.size() < 2)
        throw Error("CIE table has " + std::to_string(lambdas.size()) + " data rows; at least 2 are needed");
    table.lambda0 = lambdas.front();
    table.step = lambdas[1] - lambdas[0];
    return table;
}

CieTable loadCieCsv(const std::string& path)
{
    std::ifstream in(path, std::ios::binary);
    if (!in) throw Error("cannot open CIE table '" + path + "'");
    std::ostringstream content;
    content << in.rdbuf();
    if (in.bad()) throw Error("cannot read CIE table '" + path + "'");
    try {
        return parseCieCsv(content.str());
    } catch (const Error& e) {
        throw Error(path + ": " + e.what());
    }
}

glm::dvec3 blackbodyXyz(double kelvin, const CieTable& cie)
{
    validateKelvin(kelvin);
    if (cie.xyzBar.size() < 2 || !(cie.step > 0.0) || !(cie.lambda0 > 0.0))
        throw Error("CIE table is empty or has no positive wavelength step");
    constexpr double h = 6.62607015e-34;   // Planck constant, J s (exact, SI 2019)
    constexpr double c = 299792458.0;      // speed of light, m/s (exact)
    constexpr double kB = 1.380649e-23;    // Boltzmann constant, J/K (exact, SI 2019)
    constexpr double c1 = 2.0 * h * c * c; // W m^2 sr^-1
    constexpr double c2 = h * c / kB;      // m K
    const size_t n = cie.xyzBar.size();
    const double dLambda = cie.step * 1e-9;   // m
    glm::dvec3 sum(0.0);
    for (size_t i = 0; i < n; ++i) {
        const double lambda = (cie.lambda0 + double(i) * cie.step) * 1e-9;   // m
        const double l2 = lambda * lambda;
        const double radiance = c1 / (l2 * l2 * lambda) / std::expm1(c2 / (lambda * kelvin));
        const double weight = (i == 0 || i + 1 == n) ? 0.5 * dLambda : dLambda;
        sum += cie.xyzBar[i] * (radiance * weight);
    }
    return sum;
}

glm::dvec2 chromaticity(glm::dvec3 xyz)
{
    const double s = xyz.x + xyz.y + xyz.z;
    if (s == 0.0) return glm::dvec2(0.0);
    return glm::dvec2(xyz.x / s, xyz.y / s);
}

glm::dvec3 xyzToLinearSrgb(glm::dvec3 v)
{
    // IEC 61966-2-1:1999, XYZ (D65, Y = 1 for white) -> linear RGB.
    return glm::dvec3(3.2406 * v.x - 1.5372 * v.y - 0.4986 * v.z,
                      -0.9689 * v.x + 1.8758 * v.y + 0.0415 * v.z,
                      0.0557 * v.x - 0.2040 * v.y + 1.0570 * v.z);
}

glm::vec3 sunColor(double kelvin, const CieTable& cie)
{
    const glm::dvec3 xyz = blackbodyXyz(kelvin, cie);
    if (!(xyz.y > 0.0)) throw Error("CIE table gives a blackbody at " + fmt(kelvin) + " K no luminance (ybar is zero)");
    const glm::vec3 rgb(glm::max(xyzToLinearSrgb(xyz / xyz.y), glm::dvec3(0.0)));
    return rgb / luminance(rgb);
}

} // namespace sylva
