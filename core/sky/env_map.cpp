// Environment maps: shape checks, cleaning, integrals and the sun's extraction.
#include "core/sky/env_map.h"

#include <algorithm>
#include <cmath>
#include <cstdint>

#include "core/base/error.h"

namespace sylva::sky {

namespace {

float lum(glm::vec3 c) { return 0.2126f * c.x + 0.7152f * c.y + 0.0722f * c.z; }
double lumD(glm::dvec3 c) { return 0.2126 * c.x + 0.7152 * c.y + 0.0722 * c.z; }

constexpr float kChromaSpikeRatio = 32.0f, kChromaSpikeFloor = 1.0f;

size_t pixelCount(const EnvMap& m) { return size_t(m.width) * size_t(m.height); }

void checkStorage(const EnvMap& m)
{
    checkEnvMapShape(m.width, m.height, "environment map");
    if (m.rgb.size() != pixelCount(m) * 3) throw Error("environment map: pixel storage does not match its size");
}

} // namespace

void checkEnvMapShape(int width, int height, const std::string& what)
{
    const std::string size = std::to_string(width) + " x " + std::to_string(height);
    if (width <= 0 || height <= 0) throw Error(what + ": the map is empty (" + size + " pixels)");
    if (width < 2 || height < 1 || size_t(width) * size_t(height) < 2)
        throw Error(what + ": a " + size + " map is too small for an equirectangular sky (at least 2 x 1)");
    if (width != 2 * height)
        throw Error(what + ": an equirectangular map is twice as wide as high; this one is " + size);
    if (size_t(width) * size_t(height) > (size_t(1) << 28)) throw Error(what + ": " + size + " pixels is too large");
}

EnvMapCleanReport cleanEnvMap(EnvMap& map, float spikeRatio)
{
    checkStorage(map);
    EnvMapCleanReport r;
    for (size_t p = 0; p < pixelCount(map); ++p) {
        bool neg = false, bad = false;
        for (int c = 0; c < 3; ++c) {
            float& v = map.rgb[p * 3 + size_t(c)];
            if (!std::isfinite(v)) {
                v = 0.0f;
                bad = true;
            } else if (v < 0.0f) {
                v = 0.0f;
                neg = true;
            }
        }
        r.negative += neg ? 1 : 0;
        r.nonFinite += bad ? 1 : 0;
    }
    if (!(spikeRatio > 0.0f)) return r;
    // Neighbourhood maxima from the cleaned map (wrapping in azimuth, clamped at the poles).
    const int w = map.width, h = map.height;
    const std::vector<float> src = map.rgb;
    auto value = [&](int x, int y, int c) {
        x = (x % w + w) % w;
        y = std::clamp(y, 0, h - 1);
        return src[(size_t(y) * size_t(w) + size_t(x)) * 3 + size_t(c)];
    };
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            float nmax[3] = {0.0f, 0.0f, 0.0f};
            for (int dy = -1; dy <= 1; ++dy)
                for (int dx = -1; dx <= 1; ++dx) {
                    if (dx == 0 && dy == 0) continue;
                    if (y + dy < 0 || y + dy >= h) continue;
                    for (int c = 0; c < 3; ++c) nmax[c] = std::max(nmax[c], value(x + dx, y + dy, c));
                }
            bool spike[3], any = false, all = true;
            for (int c = 0; c < 3; ++c) {
                const float v = value(x, y, c);
                spike[c] = v > 1e-6f && v > spikeRatio * nmax[c];
                any = any || spike[c];
                all = all && spike[c];
            }
            if (!any || all) continue;   // nothing, or bright in every channel (a small sun, a lamp)
            float* d = map.ptr(x, y);
            const glm::vec3 before(d[0], d[1], d[2]);
            for (int c = 0; c < 3; ++c)
                if (spike[c]) d[c] = nmax[c];
            r.spikes += 1;
            r.spikeEnergy += double(lum(before) - lum(glm::vec3(d[0], d[1], d[2]))) * envMapPixelSolidAngle(w, h, y);
        }
    // Single-channel extremes (a block of lossy compression gone wrong, e.g. around a clipped sun: blue in
    // the thousands, red and green 0): grey of the same luminance.
    for (int y = 0; y < map.height; ++y)
        for (int x = 0; x < map.width; ++x) {
            float* d = map.ptr(x, y);
            for (int c = 0; c < 3; ++c) {
                const float o1 = d[(c + 1) % 3], o2 = d[(c + 2) % 3];
                if (d[c] > kChromaSpikeFloor && d[c] > kChromaSpikeRatio * std::max(o1, o2)) {
                    const float l = lum(glm::vec3(d[0], d[1], d[2]));
                    d[0] = d[1] = d[2] = l;
                    r.spikes += 1;
                    break;
                }
            }
        }
    return r;
}

double envMapPixelSolidAngle(int width, int height, int y)
{
    const double t0 = kPiD * double(y) / double(height), t1 = kPiD * double(y + 1) / double(height);
    return 2.0 * kPiD / double(width) * (std::cos(t0) - std::cos(t1));
}

glm::vec3 envMapPixelDirection(int width, int height, int x, int y)
{
    return equirectDirection((float(x) + 0.5f) / float(width), (float(y) + 0.5f) / float(height));
}

glm::dvec3 envMapIntegral(const EnvMap& map)
{
    checkStorage(map);
    glm::dvec3 sum(0.0);
    for (int y = 0; y < map.height; ++y) {
        glm::dvec3 row(0.0);
        for (int x = 0; x < map.width; ++x) row += glm::dvec3(map.at(x, y));
        sum += row * envMapPixelSolidAngle(map.width, map.height, y);
    }
    return sum;
}

glm::dvec3 envMapUpperIrradiance(const EnvMap& map)
{
    checkStorage(map);
    glm::dvec3 sum(0.0);
    for (int y = 0; y < map.height; ++y) {
        const double cosT = std::cos(kPiD * (double(y) + 0.5) / double(map.height));
        if (cosT <= 0.0) continue;
        glm::dvec3 row(0.0);
        for (int x = 0; x < map.width; ++x) row += glm::dvec3(map.at(x, y));
        sum += row * envMapPixelSolidAngle(map.width, map.height, y) * cosT;
    }
    return sum;
}

FoundSun extractSun(EnvMap& map, const SunFindSettings& settings)
{
    checkStorage(map);
    const int w = map.width, h = map.height;
    FoundSun f;
    // The peak (largest luminance) and the median of the upper half.
    std::vector<float> upper;
    upper.reserve(size_t(w) * size_t(h / 2 + 1));
    int px = 0, py = 0;
    float peak = -1.0f;
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            const float l = lum(map.at(x, y));
            if (y < (h + 1) / 2) upper.push_back(l);
            if (l > peak) peak = l, px = x, py = y;
        }
    std::nth_element(upper.begin(), upper.begin() + std::ptrdiff_t(upper.size() / 2), upper.end());
    f.medianLuminance = upper[upper.size() / 2];
    f.peakLuminance = peak;
    if (!(peak > 0.0f) || peak < settings.minContrast * f.medianLuminance) return f;
    const float threshold = std::max(settings.regionFraction * peak, settings.minContrast * f.medianLuminance);
    // Flood fill (8-connected, wrapping in azimuth) of the pixels above the threshold.
    std::vector<uint8_t> in(size_t(w) * size_t(h), 0);
    std::vector<std::pair<int, int>> stack{{px, py}}, region;
    in[size_t(py) * size_t(w) + size_t(px)] = 1;
    double solidAngle = 0.0;
    while (!stack.empty()) {
        const auto [x, y] = stack.back();
        stack.pop_back();
        region.emplace_back(x, y);
        solidAngle += envMapPixelSolidAngle(w, h, y);
        if (solidAngle > settings.maxSolidAngle) return f;   // not compact
        for (int dy = -1; dy <= 1; ++dy)
            for (int dx = -1; dx <= 1; ++dx) {
                const int nx = ((x + dx) % w + w) % w, ny = y + dy;
                if (ny < 0 || ny >= h) continue;
                uint8_t& seen = in[size_t(ny) * size_t(w) + size_t(nx)];
                if (seen || lum(map.at(nx, ny)) <= threshold) continue;
                seen = 1;
                stack.emplace_back(nx, ny);
            }
    }
    // The fill: mean of the pixels bordering the region (8-neighbours not in it).
    glm::dvec3 fill(0.0);
    size_t border = 0;
    std::vector<uint8_t> counted(in.size(), 0);
    for (const auto& [x, y] : region)
        for (int dy = -1; dy <= 1; ++dy)
            for (int dx = -1; dx <= 1; ++dx) {
                const int nx = ((x + dx) % w + w) % w, ny = y + dy;
                if (ny < 0 || ny >= h) continue;
                const size_t i = size_t(ny) * size_t(w) + size_t(nx);
                if (in[i] || counted[i]) continue;
                counted[i] = 1;
                fill += glm::dvec3(map.at(nx, ny));
                ++border;
            }
    if (border > 0) fill /= double(border);
    glm::dvec3 power(0.0), centre(0.0);
    for (const auto& [x, y] : region) {
        const glm::dvec3 excess = glm::max(glm::dvec3(map.at(x, y)) - fill, glm::dvec3(0.0));
        const double omega = envMapPixelSolidAngle(w, h, y);
        power += excess * omega;
        centre += lumD(excess) * omega * glm::dvec3(envMapPixelDirection(w, h, x, y));
    }
    const glm::dvec3 total = envMapIntegral(map);
    if (!(lumD(power) > 0.0) || lumD(power) < settings.minPowerFraction * lumD(total) || !(glm::length(centre) > 0.0)) return f;
    for (const auto& [x, y] : region) {
        float* p = map.ptr(x, y);
        for (int c = 0; c < 3; ++c) p[c] = std::min(p[c], float(fill[c]));   // what the sun took: excess only
    }
    f.pixels = int(region.size());
    f.sun.present = true;
    f.sun.direction = glm::vec3(glm::normalize(centre));
    f.sun.solidAngle = float(solidAngle);
    const double l = lumD(power);
    f.sun.illuminance = float(l);
    f.sun.color = glm::vec3(power / l);
    return f;
}

EnvMapView envMapView(const EnvMap& map, float rotationDeg, float intensity)
{
    EnvMapView v;
    v.rgb = map.rgb.data();
    v.width = map.width;
    v.height = map.height;
    const double r = double(rotationDeg) * kPiD / 180.0;
    v.cosRot = float(std::cos(r));
    v.sinRot = float(std::sin(r));
    v.intensity = intensity;
    return v;
}

std::vector<float> envMapMipChain(const EnvMap& map, int& levels)
{
    checkEnvMapShape(map.width, map.height, "sky map");
    std::vector<float> out(map.rgb.begin(), map.rgb.end());
    levels = 1;
    size_t at = 0;   // the level being halved
    int w = map.width, h = map.height;
    while (h % 2 == 0) {
        const int w2 = w / 2, h2 = h / 2;
        std::vector<float> next(size_t(w2) * size_t(h2) * 3);
        for (int y = 0; y < h2; ++y) {
            // the two fine rows' solid angles (per pixel; the columns of a row have the same)
            const double a0 = envMapPixelSolidAngle(w, h, 2 * y), a1 = envMapPixelSolidAngle(w, h, 2 * y + 1);
            const double norm = 1.0 / (2.0 * (a0 + a1));
            for (int x = 0; x < w2; ++x)
                for (int c = 0; c < 3; ++c) {
                    auto fine = [&](int fx, int fy) { return double(out[at + (size_t(fy) * size_t(w) + size_t(fx)) * 3 + size_t(c)]); };
                    const double sum = a0 * (fine(2 * x, 2 * y) + fine(2 * x + 1, 2 * y)) + a1 * (fine(2 * x, 2 * y + 1) + fine(2 * x + 1, 2 * y + 1));
                    next[(size_t(y) * size_t(w2) + size_t(x)) * 3 + size_t(c)] = float(sum * norm);
                }
        }
        at = out.size();
        out.insert(out.end(), next.begin(), next.end());
        w = w2;
        h = h2;
        ++levels;
    }
    return out;
}

EnvMap renderSkyToMap(const SkyView& sky, int width)
{
    if (width < 2 || width % 2 != 0) throw Error("sky map: the width must be even and at least 2, got " + std::to_string(width));
    EnvMap m;
    m.width = width;
    m.height = width / 2;
    checkEnvMapShape(m.width, m.height, "sky map");
    m.rgb.resize(pixelCount(m) * 3);
    for (int y = 0; y < m.height; ++y)
        for (int x = 0; x < m.width; ++x) {
            const glm::vec3 c = skyRadiance(sky, envMapPixelDirection(m.width, m.height, x, y));
            float* p = m.ptr(x, y);
            p[0] = c.x, p[1] = c.y, p[2] = c.z;
        }
    return m;
}

} // namespace sylva::sky
