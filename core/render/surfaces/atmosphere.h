// The atmosphere kind's record: aerial perspective, the air between the camera and what it sees. A medium of the
// list (core/render/surfaces/surface_list.h): camera rays that end on a surface cross it (atmosphere_trace.h);
// rays that reach the sky do not, since the sky model already holds the air in front of it.
//
// The air is Rayleigh molecules and aerosol, each with a density falling exponentially with height (scale
// heights kRayleighScaleHeight and kAerosolScaleHeight above world y = 0, sea level) and the sea-level
// extinction of Preetham, Shirley & Smits, "A Practical Analytic Model for Daylight" (1999), Appendix A.2, the
// same columns the sky's sun comes through (core/sky/preetham.h: the vertical optical depth over the scale
// height), so a turbidity hazes the distance as it reddens the sun. Along a straight ray from height y0 in
// direction d (d.y its vertical part) the optical depth to distance t has the closed form
//   tau = sum_k sigma_k * integral_0^t exp(-(y0 + s d.y) / H_k) ds
//       = sum_k sigma_k * H_k / d.y * (exp(-y0 / H_k) - exp(-(y0 + t d.y) / H_k))     (d.y != 0),
// and the surface's light reaches the camera times T = exp(-tau) per channel. The air's own light along the
// ray is (1 - T) x the sky's radiance toward the horizon under that direction (a map's a little above it):
// the exact single-scattering result where the in-scattered radiance per unit extinction is the same along the
// ray, equal to what a ray that never ends sees at the horizon; so a distant slope fades into the sky behind it
// and takes the sky's colour and its glow around the sun. docs/RENDERING.md "Aerial perspective".
#pragma once

#include <cstdint>
#include <math.h>

#include <glm/glm.hpp>

#include "core/base/defines.h"

namespace sylva {

inline constexpr float kRayleighScaleHeight = 8000.0f;   // metres
inline constexpr float kAerosolScaleHeight = 1200.0f;    // metres
// The lowest direction (its y) the air's in-scattered light is taken from a map sky: about 2 degrees above the
// horizon, where a photograph shows sky rather than the ground it was taken over (analytic skies: the horizon).
inline constexpr float kHorizonMinY = 0.035f;
// The angle (radians) a map sky is filtered over where the air's light is read from it.
inline constexpr float kHorizonFootprint = 0.1f;
// Hits at or beyond this distance are the sky (the camera ray's tmax): no air is added in front of them.
inline constexpr float kAtmosphereSkyDistance = 1e29f;

// 32 bytes.
struct AtmosphereRecord {
    uint32_t enabled = 0;                // 0: no aerial perspective
    float cameraY = 0.0f;                // world height of the camera (metres above sea level, world y = 0)
    glm::vec3 rayleigh{0.0f};            // extinction at sea level, per metre, linear Rec. 709 channels
    glm::vec3 aerosol{0.0f};             // the same for the aerosol (turbidity)
};

// The effective wavelengths (nanometres) of the linear Rec. 709 channels the extinction is evaluated at (the
// primaries' dominant wavelengths).
inline constexpr double kAtmosphereWavelengthsNm[3] = {611.0, 549.0, 464.0};

// The air of a turbidity (2 .. 10, as the Preetham sky's) for a camera at world height cameraY: each channel's
// sea-level extinction is Preetham's vertical optical depth (core/sky/preetham.h) over its scale height, so
// the vertical column from sea level gives the sun's transmittance at the zenith. Host only
// (atmosphere_build.cpp); throws Error outside 2 .. 10.
AtmosphereRecord makeAtmosphere(double turbidity, double cameraY);

// integral_0^t exp(-(y0 + s dy) / H) ds: the air a ray of length t from height y0 with vertical direction dy
// passes, in metres of sea-level air. Near-horizontal rays take the midpoint rule, exact to (t dy / H)^2 / 24.
SYLVA_HD SYLVA_INLINE float airColumn(float y0, float dy, float t, float H)
{
    const float x = t * dy / H;
    if (fabsf(x) < 1e-3f) return t * expf(-(y0 + 0.5f * t * dy) / H);
    return H / dy * (expf(-y0 / H) - expf(-(y0 + t * dy) / H));
}

// Transmittance per channel along a camera-relative ray of length t with unit direction dir.
SYLVA_HD SYLVA_INLINE glm::vec3 atmosphereTransmittance(const AtmosphereRecord& a, float y0, const glm::vec3& dir, float t)
{
    const float r = airColumn(y0, dir.y, t, kRayleighScaleHeight), m = airColumn(y0, dir.y, t, kAerosolScaleHeight);
    const glm::vec3 tau = a.rayleigh * r + a.aerosol * m;
    return glm::vec3(expf(-tau.x), expf(-tau.y), expf(-tau.z));
}

// The direction the air's in-scattered light is read from: unit dir raised to height minY (0 .. 1) when below it.
SYLVA_HD SYLVA_INLINE glm::vec3 horizonDirection(const glm::vec3& dir, float minY)
{
    if (dir.y >= minY) return dir;
    const float h = sqrtf(dir.x * dir.x + dir.z * dir.z);
    const float c = sqrtf(1.0f - minY * minY);
    if (!(h > 0.0f)) return glm::vec3(c, minY, 0.0f);
    return glm::vec3(dir.x / h * c, minY, dir.z / h * c);
}

} // namespace sylva
