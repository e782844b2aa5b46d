// An equirectangular HDR environment map in memory (conventions in core/sky/sky.h): checked, cleaned,
// integrated, its sun found and taken out. Reading files is the pipeline's (pipeline/io/env_map_io.h).
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "core/sky/sky.h"

namespace sylva::sky {

// width = 2 x height, row 0 at the zenith, 3 floats (linear Rec. 709 radiance) per pixel, 12 bytes each.
struct EnvMap {
    int width = 0, height = 0;
    std::vector<float> rgb;
    glm::vec3 at(int x, int y) const
    {
        const float* p = &rgb[(size_t(y) * size_t(width) + size_t(x)) * 3];
        return glm::vec3(p[0], p[1], p[2]);
    }
    float* ptr(int x, int y) { return &rgb[(size_t(y) * size_t(width) + size_t(x)) * 3]; }
};

// Throws sylva::Error (prefixed with `what`, e.g. the file name) unless the map is usable: at least
// 2 x 1 pixels, width exactly 2 x height, rgb holding width x height x 3 values.
void checkEnvMapShape(int width, int height, const std::string& what);

// What cleanEnvMap changed. Counts are of pixels (a pixel with several bad channels counts once).
struct EnvMapCleanReport {
    size_t negative = 0;     // some channel < 0: those channels set to 0
    size_t nonFinite = 0;    // some channel NaN or +-Inf: those channels set to 0
    size_t spikes = 0;       // single-channel extremes made grey + isolated extreme channels replaced
    double spikeEnergy = 0;  // luminance x sr removed by the isolated-spike filter (compare with the integral)
};

// Cleans a map read from a file so no negative, NaN or infinite radiance reaches the renderer: negative
// and non-finite channels -> 0. Then, unless spikeRatio <= 0, two filters for lossy-compression outliers
// (counted in `spikes`): first a channel more than spikeRatio x the largest of the same channel in its 8
// neighbours (and above 1e-6) while the pixel's other channels are not is set to that maximum (a real sun
// is bright in all three channels and is kept); then a pixel with one channel above 1 and above 32 x both
// others (no sky or sun has such a colour; DWA-compressed suns do: park.exr's is blue 11800 with red and
// green 0, in a 2 x 2 cluster the first filter cannot see) becomes grey of the same luminance, so its
// luminance power is kept but not its false colour.
EnvMapCleanReport cleanEnvMap(EnvMap& map, float spikeRatio = 16.0f);

// Solid angle of a pixel of row y: (2 pi / width) (cos theta_top - cos theta_bottom), sr. The rows sum to 4 pi.
double envMapPixelSolidAngle(int width, int height, int y);
// Centre direction of pixel (x, y) of a width x height map (unrotated).
glm::vec3 envMapPixelDirection(int width, int height, int x, int y);

// Sum over the pixels of radiance x solid angle, RGB (double): the map's integral over the sphere, and the
// cosine-weighted integral over the upper hemisphere (the irradiance of an upward-facing plane, with the
// pixel-centre cosine, pixels below the horizon skipped).
glm::dvec3 envMapIntegral(const EnvMap& map);
glm::dvec3 envMapUpperIrradiance(const EnvMap& map);

struct SunFindSettings {
    float minContrast = 50.0f;      // the peak's luminance over the map's median luminance (upper half)
    float regionFraction = 0.02f;   // the region: pixels 8-connected to the peak above this x peak luminance
                                    // (and above minContrast x median)
    double maxSolidAngle = 0.01;    // sr: a larger region is not a compact sun (0.01 sr: a 3.2 degree radius)
    double minPowerFraction = 0.005; // the region's power (above the fill) over the map's: smaller is no sun
};

// The map's sun: the brightest compact region, as a directional sun. Its pixels are set to the mean of the
// pixels bordering the region (the sky behind the sun), and the sun gets what that took out: power =
// sum (L - fill) x solid angle per channel (>= 0), at the power-weighted centre of the region. So
// envMapIntegral(after) + sun.radiance() == envMapIntegral(before) up to float rounding. present = false
// (map unchanged) when no region passes the settings. Directions are of the unrotated map.
struct FoundSun {
    SkySun sun;
    int pixels = 0;              // in the region
    float peakLuminance = 0.0f;  // of the brightest pixel
    float medianLuminance = 0.0f;
};
FoundSun extractSun(EnvMap& map, const SunFindSettings& settings = {});

// The per-ray view of a map (pointer into `map`, which must outlive it), rotated about +Y and scaled.
EnvMapView envMapView(const EnvMap& map, float rotationDeg, float intensity);

// The map and its coarser levels for filtered lookups (envMapFiltered, core/sky/sky.h), one after another:
// level k + 1 is half of level k each way, each texel the solid-angle-weighted mean of the 2 x 2 below it, so
// every level keeps the map's integral over the sphere; the chain stops at a level of odd height (a 2 x 1
// level at the end for power-of-two maps). Sets `levels` to their number (>= 1).
std::vector<float> envMapMipChain(const EnvMap& map, int& levels);

// An analytic sky sampled at pixel centres (without its sun), as a width x width/2 map. width >= 2, even.
EnvMap renderSkyToMap(const SkyView& sky, int width);

} // namespace sylva::sky
