// Sky models behind one plain-data view: a constant colour, Preetham's analytic daylight (1999) and an
// equirectangular HDR map. Each gives radiance for a direction (SYLVA_HD, per ray), its sun (direction,
// colour, radiance) and, through sky_light.h, the totals the LB boundary and the virtual lights take.
//
// Conventions (the same as SunDesc and sunDirection in core/scene/scene.h):
//   * world +Y is up; a direction is a unit vector pointing AWAY from the viewer (toward the sky).
//   * elevation: degrees above the horizon; azimuth: degrees, 0 = +Z, 90 = +X (x = cos(el) sin(az),
//     y = sin(el), z = cos(el) cos(az)).
//   * geography (core/sky/sun_position.h): +X is east, -Z is north, +Z is south, so the sylva azimuth is
//     180 - the compass bearing (0 = south: the northern hemisphere's noon sun).
//   * equirectangular maps: width = 2 x height, row 0 at the zenith, row centres at polar angle
//     theta = pi (row + 0.5) / height; column u = (col + 0.5) / width looks at azimuth pi (1 - 2 u), i.e.
//     the centre column looks toward +Z (south), a quarter in toward +X (east), the left and right edges
//     toward -Z (north). Azimuth falls left to right, so the map reads unmirrored from inside the sphere
//     (with +Y up and a right-handed frame, the viewer's right of +Z is -X).
//   * a map rotation of R degrees about +Y adds R to every azimuth of the map (its sun moves with it).
//   * radiance is linear Rec. 709 RGB. The Preetham model's unit is kcd/m^2 (the paper's zenith
//     luminance), scaled by PreethamSky::scale; a map's unit is its pixels' x its intensity.
//   * a sun's radiance (SkySun::radiance) is what the renderer's directional sun is given today: the
//     irradiance it delivers on a surface facing it (radiance integrated over its disc), colour x
//     illuminance, in the sky's unit x sr (klux for Preetham at scale 1).
#pragma once

#include <cmath>

#include <glm/glm.hpp>

#include "core/base/defines.h"

namespace sylva::sky {

inline constexpr float kPi = 3.14159265358979323846f;
inline constexpr double kPiD = 3.14159265358979323846;

// Direction from elevation and azimuth in degrees (sunDirection's formula, here for per-ray code).
SYLVA_HD inline glm::vec3 directionFromAngles(float elevationDeg, float azimuthDeg)
{
    const float el = elevationDeg * (kPi / 180.0f), az = azimuthDeg * (kPi / 180.0f);
    return glm::vec3(cosf(el) * sinf(az), sinf(el), cosf(el) * cosf(az));
}

// Direction at map coordinates u, v in [0, 1] (v = 0: zenith, v = 1: nadir).
SYLVA_HD inline glm::vec3 equirectDirection(float u, float v)
{
    const float az = kPi * (1.0f - 2.0f * u), theta = kPi * v;
    const float s = sinf(theta);
    return glm::vec3(s * sinf(az), cosf(theta), s * cosf(az));
}

// Map coordinates of a direction (any length > 0): u in [0, 1), v in [0, 1].
SYLVA_HD inline glm::vec2 equirectUv(glm::vec3 d)
{
    const float len = sqrtf(d.x * d.x + d.y * d.y + d.z * d.z);
    const float y = len > 0.0f ? fminf(fmaxf(d.y / len, -1.0f), 1.0f) : 1.0f;
    const float az = atan2f(d.x, d.z);   // -pi .. pi, 0 = +Z
    float u = 0.5f * (1.0f - az / kPi);
    u = u - floorf(u);
    if (!(u < 1.0f)) u = 0.0f;           // rounding up to 1, or NaN
    return glm::vec2(u, acosf(y) / kPi);
}

// Rotates a direction about +Y so that its azimuth grows by the angle whose cosine and sine are given.
SYLVA_HD inline glm::vec3 rotateAzimuth(glm::vec3 d, float c, float s)
{
    return glm::vec3(d.x * c + d.z * s, d.y, d.z * c - d.x * s);
}

// A sky's sun: a directional light. present = false: the sky has none (a cloudy map, the sun below the
// horizon); radiance is then 0.
struct SkySun {
    bool present = false;
    glm::vec3 direction{0.0f, 1.0f, 0.0f};   // unit, toward the sun
    glm::vec3 color{1.0f};                   // linear Rec. 709, Rec. 709 luminance 1
    float illuminance = 0.0f;                // luminance of radiance: irradiance facing the sun
    float solidAngle = 0.0f;                 // sr, of the disc (or of the map region it was taken from)
    SYLVA_HD glm::vec3 radiance() const { return color * illuminance; }
};

// Preetham, Shirley & Smits 1999: the Perez coefficients (A..E) of Y, x and y for one turbidity, the
// zenith values, the Perez normalization F(0, theta_sun) and the sun direction. Built on the host by
// makePreetham (core/sky/preetham.h); evaluated per ray by preethamRadiance.
struct PreethamSky {
    float perez[3][5] = {};                  // [Y, x, y][A, B, C, D, E]
    float zenith[3] = {};                    // Yz (kcd/m^2), xz, yz
    float norm[3] = {1.0f, 1.0f, 1.0f};      // F(0, theta_sun) for Y, x, y
    glm::vec3 sunDirection{0.0f, 1.0f, 0.0f};
    float scale = 1.0f;                      // multiplies the radiance (and the model's sun)
};

// The Perez et al. (1993) sky distribution F(theta, gamma) = (1 + A exp(B / cos theta)) (1 + C exp(D gamma)
// + E cos^2 gamma) with cos theta clamped to >= 1e-4 (the horizon value for directions below it).
SYLVA_HD inline float perezF(const float* c, float cosTheta, float gamma, float cosGamma)
{
    const float ct = fmaxf(cosTheta, 1e-4f);
    return (1.0f + c[0] * expf(c[1] / ct)) * (1.0f + c[2] * expf(c[3] * gamma) + c[4] * cosGamma * cosGamma);
}

// CIE XYZ -> linear Rec. 709, the IEC 61966-2-1 matrix (sylva::xyzToLinearSrgb's, in float).
SYLVA_HD inline glm::vec3 xyzToRec709(glm::vec3 v)
{
    return glm::vec3(3.2406f * v.x - 1.5372f * v.y - 0.4986f * v.z, -0.9689f * v.x + 1.8758f * v.y + 0.0415f * v.z,
                     0.0557f * v.x - 0.2040f * v.y + 1.0570f * v.z);
}

// Luminance Y (kcd/m^2 x scale) and chromaticity x, y of the sky toward a unit direction. Directions below
// the horizon get the horizon's value (theta clamped at 90 degrees: the ground is the renderer's).
SYLVA_HD inline glm::vec3 preethamYxy(const PreethamSky& p, glm::vec3 d)
{
    const float cosGamma = fminf(fmaxf(d.x * p.sunDirection.x + d.y * p.sunDirection.y + d.z * p.sunDirection.z, -1.0f), 1.0f);
    const float gamma = acosf(cosGamma);
    glm::vec3 out;
    for (int i = 0; i < 3; ++i) out[i] = p.zenith[i] * perezF(p.perez[i], d.y, gamma, cosGamma) / p.norm[i];
    return out;
}

// Linear Rec. 709 radiance of the Preetham sky toward a unit direction (kcd/m^2 x scale), >= 0: the
// out-of-gamut (negative) components of very saturated colours are clamped to 0.
SYLVA_HD inline glm::vec3 preethamRadiance(const PreethamSky& p, glm::vec3 d)
{
    const glm::vec3 yxy = preethamYxy(p, d);
    const float Y = fmaxf(yxy.x, 0.0f), x = yxy.y, y = fmaxf(yxy.z, 1e-4f);
    const glm::vec3 rgb = xyzToRec709(glm::vec3(x / y * Y, Y, (1.0f - x - y) / y * Y)) * p.scale;
    return glm::max(rgb, glm::vec3(0.0f));
}

// An equirectangular map as the per-ray code reads it: RGB floats, row 0 at the zenith (conventions above),
// the rotation's cosine and sine, and an intensity. Piecewise constant: a direction reads the pixel it
// falls in (the same function the map's integrals and virtual lights use).
struct EnvMapView {
    const float* rgb = nullptr;              // width x height x 3, row-major; then the coarser levels, if any
    int width = 0, height = 0;
    float cosRot = 1.0f, sinRot = 0.0f;      // of the rotation about +Y
    float intensity = 1.0f;
    int levels = 1;                          // mip levels in rgb (envMapMipChain, core/sky/env_map.h): level k is
                                             // (width >> k) x (height >> k), stored after level k - 1
};

SYLVA_HD inline glm::vec3 envMapRadiance(const EnvMapView& m, glm::vec3 d)
{
    if (!m.rgb || m.width <= 0 || m.height <= 0) return glm::vec3(0.0f);
    const glm::vec2 uv = equirectUv(rotateAzimuth(d, m.cosRot, -m.sinRot));   // world -> map: azimuth - R
    const int x = glm::min(int(uv.x * float(m.width)), m.width - 1);
    const int y = glm::min(glm::max(int(uv.y * float(m.height)), 0), m.height - 1);
    const float* p = m.rgb + (size_t(y) * size_t(m.width) + size_t(x)) * 3;
    return glm::vec3(p[0], p[1], p[2]) * m.intensity;
}

// Texel (x, y) of level `level` of a map's mip chain (level 0: the map).
SYLVA_HD inline glm::vec3 envMapTexel(const EnvMapView& m, int level, int x, int y)
{
    const float* p = m.rgb;
    int w = m.width, h = m.height;
    for (int k = 0; k < level; ++k) {
        p += size_t(w) * size_t(h) * 3;
        w >>= 1;
        h >>= 1;
    }
    p += (size_t(y) * size_t(w) + size_t(x)) * 3;
    return glm::vec3(p[0], p[1], p[2]);
}

// Level `level` of the chain at map coordinates uv, interpolated bilinearly between texel centres (u wraps
// around the azimuth, v holds the first and last rows' values toward the poles); without the intensity.
SYLVA_HD inline glm::vec3 envMapBilinear(const EnvMapView& m, int level, glm::vec2 uv)
{
    const int w = m.width >> level, h = m.height >> level;
    const float fx = uv.x * float(w) - 0.5f, fy = uv.y * float(h) - 0.5f;
    const float x0f = floorf(fx), y0f = floorf(fy);
    const float ax = fx - x0f, ay = fy - y0f;
    int x0 = int(x0f) % w;
    if (x0 < 0) x0 += w;
    const int x1 = x0 + 1 == w ? 0 : x0 + 1;
    const int y0 = glm::min(glm::max(int(y0f), 0), h - 1), y1 = glm::min(glm::max(int(y0f) + 1, 0), h - 1);
    const glm::vec3 top = envMapTexel(m, level, x0, y0) * (1.0f - ax) + envMapTexel(m, level, x1, y0) * ax;
    const glm::vec3 bottom = envMapTexel(m, level, x0, y1) * (1.0f - ax) + envMapTexel(m, level, x1, y1) * ax;
    return top * (1.0f - ay) + bottom * ay;
}

// The map as a camera sees it behind everything: the bilinear map of the mip level whose texels (pi / height
// x 2^level radians) match `footprint`, the angle one camera sample covers, blended linearly between the two
// nearest levels (trilinear filtering); below one texel the full map, bilinear. envMapRadiance (piecewise
// constant) stays the sky's light: its integrals, virtual lights and sampling table are of that function.
SYLVA_HD inline glm::vec3 envMapFiltered(const EnvMapView& m, glm::vec3 d, float footprint)
{
    if (!m.rgb || m.width <= 0 || m.height <= 0) return glm::vec3(0.0f);
    const glm::vec2 uv = equirectUv(rotateAzimuth(d, m.cosRot, -m.sinRot));
    const float texel = kPi / float(m.height);
    const float lod = footprint > texel ? fminf(log2f(footprint / texel), float(m.levels - 1)) : 0.0f;
    const int l0 = int(lod);
    const float f = lod - float(l0);
    glm::vec3 c = envMapBilinear(m, l0, uv);
    if (f > 0.0f && l0 + 1 < m.levels) c = c * (1.0f - f) + envMapBilinear(m, l0 + 1, uv) * f;
    return c * m.intensity;
}

// Uniform: the scene level only (SkyDesc), the constant colour lighting like a map: loadSceneSky builds it as a
// uniform Map sky, so no SkyView holds it.
enum class SkyKind : int { Constant = 0, Preetham = 1, Map = 2, Uniform = 3 };

// Everything per-ray code needs about the sky: plain data (the map's pixels by pointer, owned by Sky).
struct SkyView {
    SkyKind kind = SkyKind::Constant;
    glm::vec3 constant{0.55f, 0.70f, 0.95f};   // SkyKind::Constant: radiance in every direction
    PreethamSky preetham;
    EnvMapView map;
    SkySun sun;                                // kept apart from radiance(): the sky's radiance excludes it
};

// Radiance of the sky (without its sun) toward a unit direction.
SYLVA_HD inline glm::vec3 skyRadiance(const SkyView& s, glm::vec3 d)
{
    switch (s.kind) {
    case SkyKind::Preetham: return preethamRadiance(s.preetham, d);
    case SkyKind::Map: return envMapRadiance(s.map, d);
    default: return s.constant;
    }
}

} // namespace sylva::sky
