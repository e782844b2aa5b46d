// NOAA's solar position algorithm (the formulas of NOAA GML's solar calculator spreadsheet, NOAA_Solar_
// Calculations_day.xls, after Meeus 1991).
#include "core/sky/sun_position.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include "core/base/error.h"
#include "core/sky/sky.h"

namespace sylva::sky {

namespace {

constexpr double kDeg = kPiD / 180.0;

double sinD(double d) { return std::sin(d * kDeg); }
double cosD(double d) { return std::cos(d * kDeg); }
double tanD(double d) { return std::tan(d * kDeg); }
double positiveMod(double v, double m) { return v - m * std::floor(v / m); }

bool leapYear(int y) { return (y % 4 == 0 && y % 100 != 0) || y % 400 == 0; }

void check(bool ok, const char* field, const std::string& expected, double got)
{
    if (!ok) throw Error(std::string("sun position: ") + field + " must be " + expected + ", got " + std::to_string(got));
}

// NOAA's refraction correction in degrees for a true elevation e (degrees).
double refractionDeg(double e)
{
    double arcsec;
    if (e > 85.0) {
        arcsec = 0.0;
    } else if (e > 5.0) {
        const double t = tanD(e);
        arcsec = 58.1 / t - 0.07 / (t * t * t) + 0.000086 / std::pow(t, 5.0);
    } else if (e > -0.575) {
        arcsec = 1735.0 + e * (-518.2 + e * (103.4 + e * (-12.79 + e * 0.711)));
    } else {
        arcsec = -20.772 / tanD(e);
    }
    return arcsec / 3600.0;
}

} // namespace

double julianDay(int year, int month, int day, double utHour)
{
    int y = year, m = month;
    if (m <= 2) {
        y -= 1;
        m += 12;
    }
    const int a = y / 100;
    const int b = 2 - a + a / 4;
    return std::floor(365.25 * (y + 4716)) + std::floor(30.6001 * (m + 1)) + day + b - 1524.5 + utHour / 24.0;
}

bool parseSunDate(const std::string& text, int* year, int* month, int* day)
{
    int y = 0, m = 0, d = 0, used = 0;
    if (std::sscanf(text.c_str(), "%4d-%2d-%2d%n", &y, &m, &d, &used) != 3 || size_t(used) != text.size() || text.size() != 10) return false;
    *year = y, *month = m, *day = d;
    return true;
}

bool parseSunTime(const std::string& text, double* hour)
{
    int h = 0, mi = 0, used = 0;
    double sec = 0.0;
    const bool hms = std::sscanf(text.c_str(), "%2d:%2d:%lf%n", &h, &mi, &sec, &used) == 3 && size_t(used) == text.size();
    if (!hms && !(std::sscanf(text.c_str(), "%2d:%2d%n", &h, &mi, &used) == 2 && size_t(used) == text.size())) return false;
    if (text.size() < 5 || text[2] != ':' || h < 0 || mi < 0 || mi > 59 || !(sec >= 0.0 && sec < 60.0)) return false;
    *hour = h + mi / 60.0 + sec / 3600.0;
    return true;
}

std::string formatSunDate(const SunPlace& p)
{
    char buf[32];
    std::snprintf(buf, sizeof buf, "%04d-%02d-%02d", p.year, p.month, p.day);
    return buf;
}

std::string formatSunTime(double hour)
{
    const long long totalMs = std::llround(std::clamp(hour, 0.0, 24.0) * 3600000.0);
    const int h = int(totalMs / 3600000), mi = int(totalMs / 60000 % 60);
    const double sec = double(totalMs % 60000) / 1000.0;
    char buf[32];
    if (totalMs % 60000 == 0) std::snprintf(buf, sizeof buf, "%02d:%02d", h, mi);
    else if (totalMs % 1000 == 0) std::snprintf(buf, sizeof buf, "%02d:%02d:%02d", h, mi, int(sec));
    else std::snprintf(buf, sizeof buf, "%02d:%02d:%06.3f", h, mi, sec);
    return buf;
}

SunPosition noaaSunPosition(const SunPlace& p)
{
    check(p.year >= 1583 && p.year <= 3000, "year", "in 1583 .. 3000", p.year);
    check(p.month >= 1 && p.month <= 12, "month", "in 1 .. 12", p.month);
    static const int kDays[12] = {31, 28, 31, 30, 31, 30, 31, 31, 30, 31, 30, 31};
    const int days = kDays[p.month - 1] + (p.month == 2 && leapYear(p.year) ? 1 : 0);
    check(p.day >= 1 && p.day <= days, "day", "in 1 .. " + std::to_string(days) + " for that month", p.day);
    check(std::isfinite(p.hour) && p.hour >= 0.0 && p.hour <= 24.0, "hour", "in 0 .. 24", p.hour);
    check(std::isfinite(p.timeZoneHours) && std::abs(p.timeZoneHours) <= 14.0, "time zone", "in -14 .. 14 hours", p.timeZoneHours);
    check(std::isfinite(p.latitudeDeg) && std::abs(p.latitudeDeg) <= 90.0, "latitude", "in -90 .. 90 degrees", p.latitudeDeg);
    check(std::isfinite(p.longitudeDeg) && std::abs(p.longitudeDeg) <= 180.0, "longitude", "in -180 .. 180 degrees", p.longitudeDeg);

    SunPosition out;
    out.julianDay = julianDay(p.year, p.month, p.day, p.hour - p.timeZoneHours);
    const double jc = (out.julianDay - 2451545.0) / 36525.0;
    const double l0 = positiveMod(280.46646 + jc * (36000.76983 + jc * 0.0003032), 360.0);
    const double m = 357.52911 + jc * (35999.05029 - 0.0001537 * jc);
    const double e = 0.016708634 - jc * (0.000042037 + 0.0000001267 * jc);
    const double c = sinD(m) * (1.914602 - jc * (0.004817 + 0.000014 * jc)) + sinD(2.0 * m) * (0.019993 - 0.000101 * jc) +
                     sinD(3.0 * m) * 0.000289;
    const double trueLong = l0 + c;
    const double omega = 125.04 - 1934.136 * jc;
    const double appLong = trueLong - 0.00569 - 0.00478 * sinD(omega);
    const double meanObliq = 23.0 + (26.0 + (21.448 - jc * (46.815 + jc * (0.00059 - jc * 0.001813))) / 60.0) / 60.0;
    const double obliq = meanObliq + 0.00256 * cosD(omega);
    const double decl = std::asin(sinD(obliq) * sinD(appLong)) / kDeg;
    const double yv = tanD(obliq / 2.0) * tanD(obliq / 2.0);
    const double eqTime = 4.0 / kDeg *
                          (yv * sinD(2.0 * l0) - 2.0 * e * sinD(m) + 4.0 * e * yv * sinD(m) * cosD(2.0 * l0) -
                           0.5 * yv * yv * sinD(4.0 * l0) - 1.25 * e * e * sinD(2.0 * m));
    const double trueSolarMin = positiveMod(p.hour * 60.0 + eqTime + 4.0 * p.longitudeDeg - 60.0 * p.timeZoneHours, 1440.0);
    const double hourAngle = trueSolarMin / 4.0 < 0.0 ? trueSolarMin / 4.0 + 180.0 : trueSolarMin / 4.0 - 180.0;
    const double cosZen = std::clamp(sinD(p.latitudeDeg) * sinD(decl) + cosD(p.latitudeDeg) * cosD(decl) * cosD(hourAngle), -1.0, 1.0);
    const double zenith = std::acos(cosZen) / kDeg;
    double azimuth;
    const double denom = cosD(p.latitudeDeg) * sinD(zenith);
    if (std::abs(denom) < 1e-12) {
        azimuth = p.latitudeDeg >= 0.0 ? 180.0 : 0.0;   // sun at the zenith or observer at a pole
    } else {
        const double a = std::acos(std::clamp((sinD(p.latitudeDeg) * cosZen - sinD(decl)) / denom, -1.0, 1.0)) / kDeg;
        azimuth = hourAngle > 0.0 ? positiveMod(a + 180.0, 360.0) : positiveMod(540.0 - a, 360.0);
    }
    const double trueElevation = 90.0 - zenith;
    out.elevationDeg = trueElevation + (p.refraction ? refractionDeg(trueElevation) : 0.0);
    out.elevationDeg = std::min(out.elevationDeg, 90.0);
    out.compassAzimuthDeg = azimuth;
    out.azimuthDeg = positiveMod(180.0 - azimuth, 360.0);
    out.declinationDeg = decl;
    out.equationOfTimeMin = eqTime;
    const double el = out.elevationDeg * kDeg, az = out.azimuthDeg * kDeg;
    out.direction = glm::vec3(float(std::cos(el) * std::sin(az)), float(std::sin(el)), float(std::cos(el) * std::cos(az)));
    return out;
}

} // namespace sylva::sky
