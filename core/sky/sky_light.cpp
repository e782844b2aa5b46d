// Host skies: construction, their maps, lights and integrals.
#include "core/sky/sky_light.h"

#include <cmath>
#include <string>

#include "core/base/error.h"

namespace sylva::sky {

namespace {

const EnvMap& mapOf(const Sky& sky)
{
    if (!sky.map) throw Error("map sky without a map");
    return *sky.map;
}

} // namespace

SkyView Sky::view() const
{
    SkyView v;
    v.kind = kind;
    v.constant = constant;
    v.preetham = preetham;
    if (kind == SkyKind::Map && map) v.map = envMapView(*map, rotationDeg, intensity);
    v.sun = sun;
    return v;
}

Sky constantSky(glm::vec3 radiance, const SkySun& sun)
{
    if (!std::isfinite(radiance.x + radiance.y + radiance.z) || glm::any(glm::lessThan(radiance, glm::vec3(0.0f))))
        throw Error("constant sky: the radiance must be finite and >= 0");
    Sky s;
    s.kind = SkyKind::Constant;
    s.constant = radiance;
    s.sun = sun;
    return s;
}

Sky preethamSky(const PreethamParams& params, const CieTable& cie)
{
    Sky s;
    s.kind = SkyKind::Preetham;
    s.preetham = makePreetham(params);
    s.sun = preethamSun(params, cie);
    return s;
}

Sky mapSky(EnvMap map, float rotationDeg, float intensity, bool findSun, FoundSun* found)
{
    if (!std::isfinite(rotationDeg)) throw Error("map sky: the rotation must be finite");
    if (!std::isfinite(intensity) || intensity < 0.0f) throw Error("map sky: the intensity must be finite and >= 0");
    checkEnvMapShape(map.width, map.height, "map sky");
    Sky s;
    s.kind = SkyKind::Map;
    s.rotationDeg = rotationDeg;
    s.intensity = intensity;
    FoundSun f;
    if (findSun) f = extractSun(map);
    if (f.sun.present) {
        const double r = double(rotationDeg) * kPiD / 180.0;
        s.sun = f.sun;
        s.sun.direction = glm::normalize(rotateAzimuth(f.sun.direction, float(std::cos(r)), float(std::sin(r))));
        s.sun.illuminance *= intensity;
        s.sun.present = s.sun.illuminance > 0.0f;
    }
    if (found) *found = f;
    s.map = std::make_shared<const EnvMap>(std::move(map));
    return s;
}

EnvMap skyToMap(const Sky& sky, int width)
{
    if (sky.kind == SkyKind::Map && std::fmod(double(sky.rotationDeg), 360.0) == 0.0) {
        EnvMap m = mapOf(sky);
        for (float& v : m.rgb) v *= sky.intensity;
        return m;
    }
    const int w = sky.kind == SkyKind::Map ? mapOf(sky).width : width;
    return renderSkyToMap(sky.view(), w);
}

std::vector<VirtualLight> skyLights(const Sky& sky, int count, int width, bool upperOnly)
{
    if (sky.kind == SkyKind::Map) return virtualLights(mapOf(sky), count, sky.rotationDeg, sky.intensity, upperOnly);
    return virtualLights(skyToMap(sky, width), count, 0.0f, 1.0f, upperOnly);
}

glm::dvec3 skyTotal(const Sky& sky, int width)
{
    if (sky.kind == SkyKind::Map) return envMapIntegral(mapOf(sky)) * double(sky.intensity);
    return envMapIntegral(skyToMap(sky, width));
}

std::vector<glm::dvec3> skyDirectionShares(const Sky& sky, const std::vector<glm::vec3>& directions, int width, bool upperOnly)
{
    std::vector<glm::vec3> dirs;
    for (const glm::vec3& d : directions) {
        const float len = glm::length(d);
        if (!(len > 0.0f) || !std::isfinite(len)) throw Error("sky shares: a lattice direction is zero or not finite");
        dirs.push_back(d / len);
    }
    std::vector<glm::dvec3> shares(dirs.size(), glm::dvec3(0.0));
    if (dirs.empty()) return shares;
    const EnvMap rendered = sky.kind == SkyKind::Map ? EnvMap() : skyToMap(sky, width);
    const EnvMap& m = sky.kind == SkyKind::Map ? mapOf(sky) : rendered;
    const double scale = sky.kind == SkyKind::Map ? double(sky.intensity) : 1.0;
    const double r = sky.kind == SkyKind::Map ? double(sky.rotationDeg) * kPiD / 180.0 : 0.0;
    const float c = float(std::cos(r)), s = float(std::sin(r));
    for (int y = 0; y < m.height; ++y) {
        const double omega = envMapPixelSolidAngle(m.width, m.height, y) * scale;
        for (int x = 0; x < m.width; ++x) {
            const glm::vec3 d = rotateAzimuth(envMapPixelDirection(m.width, m.height, x, y), c, s);
            if (upperOnly && !(d.y > 0.0f)) continue;
            size_t best = 0;
            float bestDot = -2.0f;
            for (size_t i = 0; i < dirs.size(); ++i) {
                const float dd = glm::dot(d, dirs[i]);
                if (dd > bestDot) bestDot = dd, best = i;
            }
            shares[best] += glm::dvec3(m.at(x, y)) * omega;
        }
    }
    return shares;
}

} // namespace sylva::sky
