// Equal-power partition of an environment map into virtual directional lights; interleaving blocks.
#include "core/sky/virtual_lights.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "core/base/error.h"

namespace sylva::sky {

namespace {

struct Partition {
    const EnvMap& map;
    std::vector<double> power;   // luminance x solid angle per pixel
    std::vector<double> omega;   // per row
    float cosR, sinR, intensity;
    std::vector<VirtualLight>* out;

    void leaf(int x0, int x1, int y0, int y1)
    {
        glm::dvec3 rgb(0.0), centre(0.0), plain(0.0);
        double sa = 0.0;
        for (int y = y0; y < y1; ++y)
            for (int x = x0; x < x1; ++x) {
                const glm::dvec3 d(envMapPixelDirection(map.width, map.height, x, y));
                rgb += glm::dvec3(map.at(x, y)) * omega[size_t(y)];
                centre += power[size_t(y) * size_t(map.width) + size_t(x)] * d;
                plain += omega[size_t(y)] * d;
                sa += omega[size_t(y)];
            }
        const glm::dvec3 c = glm::length(centre) > 0.0 ? centre : plain;
        const glm::dvec3 dir = glm::length(c) > 0.0 ? glm::normalize(c) : glm::dvec3(envMapPixelDirection(map.width, map.height, x0, y0));
        VirtualLight l;
        l.direction = glm::normalize(rotateAzimuth(glm::vec3(dir), cosR, sinR));
        l.power = glm::vec3(rgb * double(intensity));
        l.solidAngle = float(sa);
        out->push_back(l);
    }

    void split(int x0, int x1, int y0, int y1, int n)
    {
        const int nx = x1 - x0, ny = y1 - y0;
        if (n <= 1 || (nx == 1 && ny == 1)) {
            leaf(x0, x1, y0, y1);
            return;
        }
        const int nl = n / 2;
        const double frac = double(nl) / double(n);
        // Angular sides: columns span 2 pi / width x sin(middle latitude's polar angle), rows pi / height.
        const double thetaMid = kPiD * (0.5 * (y0 + y1)) / double(map.height);
        const double widthAngle = double(nx) * 2.0 * kPiD / double(map.width) * std::sin(thetaMid);
        const double heightAngle = double(ny) * kPiD / double(map.height);
        const bool alongX = ny == 1 || (nx > 1 && widthAngle >= heightAngle);
        const int len = alongX ? nx : ny;
        std::vector<double> line(size_t(len), 0.0);
        for (int y = y0; y < y1; ++y)
            for (int x = x0; x < x1; ++x) line[size_t(alongX ? x - x0 : y - y0)] += power[size_t(y) * size_t(map.width) + size_t(x)];
        double total = 0.0;
        for (double v : line) total += v;
        int cut = len / 2;
        if (total > 0.0) {
            // The first cut where the cumulative power reaches frac x total, or the one just before it
            // when that is closer.
            double acc = 0.0;
            cut = len - 1;
            for (int i = 0; i < len - 1; ++i) {
                const double next = acc + line[size_t(i)];
                if (next >= frac * total) {
                    cut = (frac * total - acc < next - frac * total && i > 0) ? i : i + 1;
                    break;
                }
                acc = next;
            }
        }
        cut = std::clamp(cut, 1, len - 1);
        if (alongX) {
            split(x0, x0 + cut, y0, y1, nl);
            split(x0 + cut, x1, y0, y1, n - nl);
        } else {
            split(x0, x1, y0, y0 + cut, nl);
            split(x0, x1, y0 + cut, y1, n - nl);
        }
    }
};

} // namespace

std::vector<VirtualLight> virtualLights(const EnvMap& map, int count, float rotationDeg, float intensity, bool upperOnly)
{
    if (count < kMinVirtualLights || count > kMaxVirtualLights)
        throw Error("virtual lights: the count must be in 1 .. 65536, got " + std::to_string(count));
    checkEnvMapShape(map.width, map.height, "virtual lights");
    if (map.rgb.size() != size_t(map.width) * size_t(map.height) * 3) throw Error("virtual lights: pixel storage does not match the map's size");
    if (!std::isfinite(intensity) || intensity < 0.0f) throw Error("virtual lights: the intensity must be finite and >= 0");
    const double r = double(rotationDeg) * kPiD / 180.0;
    std::vector<VirtualLight> lights;
    lights.reserve(size_t(count));
    Partition p{map, {}, {}, float(std::cos(r)), float(std::sin(r)), intensity, &lights};
    p.omega.resize(size_t(map.height));
    for (int y = 0; y < map.height; ++y) p.omega[size_t(y)] = envMapPixelSolidAngle(map.width, map.height, y);
    p.power.resize(size_t(map.width) * size_t(map.height));
    for (int y = 0; y < map.height; ++y)
        for (int x = 0; x < map.width; ++x) {
            const glm::vec3 c = map.at(x, y);
            const double l = 0.2126 * double(c.x) + 0.7152 * double(c.y) + 0.0722 * double(c.z);
            p.power[size_t(y) * size_t(map.width) + size_t(x)] = std::max(l, 0.0) * p.omega[size_t(y)];
        }
    // Row y's centre lies at polar angle pi (y + 0.5) / height: above the horizon for the first height / 2 rows.
    const int rows = upperOnly && map.height / 2 > 0 ? map.height / 2 : map.height;
    p.split(0, map.width, 0, rows, count);
    return lights;
}

Interleave makeInterleave(int subsets, int lightCount)
{
    Interleave il;
    il.subsets = std::clamp(subsets, 1, std::max(lightCount, 1));
    int bw = 1;
    for (int d = 1; d * d <= il.subsets; ++d)
        if (il.subsets % d == 0) bw = d;
    il.blockWidth = bw;
    il.blockHeight = il.subsets / bw;
    return il;
}

} // namespace sylva::sky
