// The sun's position by date, time and place: NOAA's solar position algorithm (the NOAA Global Monitoring
// Laboratory's solar calculator and spreadsheet, after Meeus, "Astronomical Algorithms", 1991), in the
// project's conventions (core/sky/sky.h): +X east, -Z north, sylva azimuth = 180 - compass bearing.
//
// Accuracy: NOAA gives its results as theoretically accurate to about a minute of arc for dates between
// 1800 and 2100 (the truncated Meeus series; UT is used for TT, which moves the sun by under 0.001 degree
// today). Measured in tests/core/tst_sky.cpp against NREL's SPA (Reda & Andreas 2004, +-0.0003 degrees):
// within 0.02 degrees in elevation and azimuth. Refraction: NOAA's standard-atmosphere correction (it
// lifts the sun by about 0.5 degrees at the horizon); no parallax, no local pressure or temperature.
#pragma once

#include <string>

#include <glm/glm.hpp>

namespace sylva::sky {

struct SunPlace {
    int year = 2024, month = 6, day = 21;   // Gregorian calendar, 1583 .. 3000
    double hour = 12.0;                      // local clock time in hours, 0 .. 24 (12.5 = 12:30)
    double timeZoneHours = 0.0;              // local time minus UTC (east positive: +1 for CET), -14 .. 14
    double latitudeDeg = 48.0;               // north positive, -90 .. 90
    double longitudeDeg = 11.0;              // east positive, -180 .. 180
    bool refraction = true;                  // apply NOAA's atmospheric refraction to the elevation
};

struct SunPosition {
    double elevationDeg = 0.0;        // above the horizon (refracted when asked)
    double azimuthDeg = 0.0;          // sylva convention: 0 = +Z (south), 90 = +X (east)
    double compassAzimuthDeg = 0.0;   // clockwise from north (NOAA's, 0 .. 360)
    double declinationDeg = 0.0;      // apparent declination of the sun
    double equationOfTimeMin = 0.0;   // apparent minus mean solar time, minutes
    double julianDay = 0.0;           // of the instant (UT)
    glm::vec3 direction{0.0f, 1.0f, 0.0f};   // toward the sun (unit; sunDirection(elevation, azimuth))
};

// Throws sylva::Error naming the field for a date that does not exist or a value outside its range.
SunPosition noaaSunPosition(const SunPlace& place);

// Julian day (UT) of a Gregorian calendar date at a UT hour (Meeus chapter 7).
double julianDay(int year, int month, int day, double utHour);

// The text forms of a place's date and clock time (scene files, the CLI's --sun-at, the studio):
// "YYYY-MM-DD" and "HH:MM" or "HH:MM:SS" (seconds may have a fraction; 24:00 allowed). false: not of that
// form (the ranges of the values are noaaSunPosition's to check, except minutes and seconds 0 .. 59).
bool parseSunDate(const std::string& text, int* year, int* month, int* day);
bool parseSunTime(const std::string& text, double* hour);
std::string formatSunDate(const SunPlace& place);
std::string formatSunTime(double hour);   // "HH:MM", or "HH:MM:SS" when the seconds are not whole minutes

// The direction of noaaSunPosition(place).direction (throws as it does).
inline glm::vec3 placeSunDirection(const SunPlace& place) { return noaaSunPosition(place).direction; }

} // namespace sylva::sky
