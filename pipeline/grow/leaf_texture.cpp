// Generated textures for grown trees: leaf cut-outs drawn from analytic shapes, bark from periodic noise.
#include "pipeline/grow/leaf_texture.h"

#include <algorithm>
#include <cmath>
#include <cstdint>

#include <tbb/parallel_for.h>

#include "core/base/error.h"
#include "core/base/hash.h"

namespace sylva {

namespace {

constexpr float kPi = 3.14159265358979f;

uint32_t hash32(uint32_t x) { return hashFinalize(x); }

// Lattice value in [0,1) for integer cell (x, y), wrapped to a px x py period.
float latticeValue(int x, int y, int px, int py, uint32_t salt)
{
    x = ((x % px) + px) % px;
    y = ((y % py) + py) % py;
    return float(hash32(uint32_t(x) * 0x9E3779B1U ^ hash32(uint32_t(y) + salt * 0x85EBCA77U)) >> 8) * (1.0f / 16777216.0f);
}

// Smooth value noise in [0,1); x, y in lattice units, period px x py cells.
float periodicNoise(float x, float y, int px, int py, uint32_t salt)
{
    const float fx0 = std::floor(x), fy0 = std::floor(y);
    const int x0 = int(fx0), y0 = int(fy0);
    float fx = x - fx0, fy = y - fy0;
    fx = fx * fx * (3.0f - 2.0f * fx);
    fy = fy * fy * (3.0f - 2.0f * fy);
    const float a = latticeValue(x0, y0, px, py, salt), b = latticeValue(x0 + 1, y0, px, py, salt);
    const float c = latticeValue(x0, y0 + 1, px, py, salt), d = latticeValue(x0 + 1, y0 + 1, px, py, salt);
    return (a + (b - a) * fx) + ((c + (d - c) * fx) - (a + (b - a) * fx)) * fy;
}

// Fractal noise in about [0,1) over texture coordinates u, v in [0,1), tileable; base cells bx x by.
float fbm(float u, float v, int bx, int by, int octaves, uint32_t salt)
{
    float sum = 0, amp = 0.5f, norm = 0;
    for (int o = 0; o < octaves; ++o) {
        const int fx = bx << o, fy = by << o;
        sum += amp * periodicNoise(u * float(fx), v * float(fy), fx, fy, salt + uint32_t(o) * 101U);
        norm += amp;
        amp *= 0.5f;
    }
    return sum / norm;
}

float fract(float x) { return x - std::floor(x); }

float smoothstepf(float e0, float e1, float x)
{
    const float t = std::clamp((x - e0) / (e1 - e0), 0.0f, 1.0f);
    return t * t * (3.0f - 2.0f * t);
}

glm::vec3 mix3(const glm::vec3& a, const glm::vec3& b, float t) { return a + (b - a) * t; }

// Distance from p to segment ab, and the segment parameter of the closest point.
float segmentDistance(glm::vec2 p, glm::vec2 a, glm::vec2 b, float* t)
{
    const glm::vec2 ab = b - a;
    const float s = std::clamp(glm::dot(p - a, ab) / glm::dot(ab, ab), 0.0f, 1.0f);
    *t = s;
    return glm::length(p - (a + ab * s));
}

// One sample of a leaf card: X in [-1,1] across, Y in [0,1] from stem to tip.
struct LeafSample {
    bool inside = false;
    float vein = 0;   // 0 blade, 1 vein or stem
    float edge = 1;   // distance-like measure to the outline, small near the edge
};

// Distance of (t) to the nearest line of a family t = k / count, in units of t.
float lineDistance(float t, float count) { return std::fabs(fract(t * count + 0.5f) - 0.5f) / count; }

LeafSample broadleafLeaf(float x, float y)
{
    LeafSample s;
    const float ax = std::fabs(x);
    if (y < 0.14f && ax < 0.02f) {
        s.inside = true;
        s.vein = 1;
        return s;
    }
    const float yb = (y - 0.11f) / 0.87f;
    if (yb <= 0 || yb >= 1) return s;
    float hw = 0.58f * std::pow(std::sin(kPi * std::pow(yb, 0.8f)), 0.8f);
    hw *= 1.0f - 0.05f * fract(yb * 26.0f);  // fine teeth
    if (ax >= hw) return s;
    s.inside = true;
    s.edge = hw - ax;
    const float mid = 0.016f * (1.0f - yb) + 0.005f;
    if (ax < mid) s.vein = 1;
    else if (yb > 0.04f && ax < 0.92f * hw && lineDistance(yb - 0.75f * ax, 7.0f) < 0.0045f + 0.004f * (1.0f - ax / hw))
        s.vein = 0.75f;
    return s;
}

LeafSample birchLeaf(float x, float y)
{
    LeafSample s;
    const float ax = std::fabs(x);
    if (y < 0.12f && ax < 0.016f) {
        s.inside = true;
        s.vein = 1;
        return s;
    }
    const float yb = (y - 0.09f) / 0.89f;
    if (yb <= 0 || yb >= 1) return s;
    float hw = yb < 0.3f ? 0.66f * std::pow(std::sin(yb / 0.3f * 0.5f * kPi), 0.5f)
                         : 0.66f * std::pow(1.0f - (yb - 0.3f) / 0.7f, 1.2f);
    hw *= 1.0f - 0.09f * fract(yb * 16.0f) - 0.04f * fract(yb * 48.0f);  // double serration
    if (ax >= hw) return s;
    s.inside = true;
    s.edge = hw - ax;
    if (ax < 0.012f * (1.0f - yb) + 0.004f) s.vein = 1;
    else if (yb > 0.05f && ax < 0.9f * hw && lineDistance(yb - 0.55f * ax, 9.0f) < 0.0045f)
        s.vein = 0.75f;
    return s;
}

LeafSample coniferSpray(float x, float y)
{
    LeafSample s;
    const glm::vec2 p(x, y);
    float t = 0;
    // the twig
    if (y < 0.97f && std::fabs(x) < 0.028f * (1.0f - 0.6f * y)) {
        s.inside = true;
        s.vein = 1;
        return s;
    }
    // needles, alternating sides, shorter toward the tip
    constexpr int kPerSide = 20;
    const float angle = 52.0f * kPi / 180.0f;
    for (int side = 0; side < 2; ++side) {
        const float sx = side == 0 ? -1.0f : 1.0f;
        const glm::vec2 dir(sx * std::sin(angle), std::cos(angle));
        for (int k = 0; k < kPerSide; ++k) {
            const float ya = 0.03f + 0.9f * (float(k) + 0.5f * float(side)) / float(kPerSide);
            const float len = 0.66f * (1.0f - 0.6f * ya) + 0.06f;
            const glm::vec2 a(0.0f, ya);
            if (p.y < ya - 0.03f || p.y > ya + len) continue;
            const float d = segmentDistance(p, a, a + dir * len, &t);
            const float halfWidth = 0.017f * (1.0f - 0.7f * t);
            if (d < halfWidth) {
                s.inside = true;
                s.edge = std::min(s.edge, halfWidth - d);
                s.vein = std::max(s.vein, d < 0.3f * halfWidth ? 0.5f : 0.0f);  // the pale stomatal band
            }
        }
    }
    return s;
}

LeafSample shrubSprig(float x, float y)
{
    LeafSample s;
    if (y < 0.64f && std::fabs(x) < 0.016f) {
        s.inside = true;
        s.vein = 1;
        return s;
    }
    struct Leaflet { float attachY, angleDeg, halfLen, halfWidth; };
    static constexpr Leaflet kLeaflets[] = {
        {0.62f, 0.0f, 0.18f, 0.14f},
        {0.46f, 52.0f, 0.21f, 0.15f}, {0.46f, -52.0f, 0.21f, 0.15f},
        {0.22f, 64.0f, 0.19f, 0.13f}, {0.22f, -64.0f, 0.19f, 0.13f},
    };
    const glm::vec2 p(x, y);
    for (const Leaflet& l : kLeaflets) {
        const float a = l.angleDeg * kPi / 180.0f;
        const glm::vec2 axis(std::sin(a), std::cos(a));
        const glm::vec2 across(axis.y, -axis.x);
        const glm::vec2 base(0.0f, l.attachY);
        const glm::vec2 center = base + axis * (l.halfLen + 0.035f);
        const glm::vec2 d = p - center;
        const float along = glm::dot(d, axis), side = glm::dot(d, across);
        // the stalk from the rachis to the leaflet
        float t = 0;
        if (segmentDistance(p, base, center - axis * l.halfLen, &t) < 0.011f) {
            s.inside = true;
            s.vein = 1;
            return s;
        }
        const float phi = std::atan2(side, along);
        const float r = 1.0f - 0.06f * std::fabs(std::sin(phi * 9.0f));  // serrated rim
        const float e = (side / l.halfWidth) * (side / l.halfWidth) + (along / l.halfLen) * (along / l.halfLen);
        if (e < r * r) {
            s.inside = true;
            s.edge = (r - std::sqrt(e)) * l.halfWidth;
            const float as = std::fabs(side);
            if (as < 0.008f) s.vein = 1;
            else if (lineDistance((along + l.halfLen) / (2.0f * l.halfLen) - 0.6f * as / l.halfWidth, 6.0f) < 0.012f)
                s.vein = 0.7f;
            return s;
        }
    }
    return s;
}

struct LeafColours {
    glm::vec3 blade, vein, edge;
};

} // namespace

ImageRgba makeLeafTexture(TreeSpecies species, int size)
{
    if (size < 8 || size > 8192) throw Error("leaf texture: size " + std::to_string(size) + " is outside [8, 8192]");
    LeafColours colours;
    LeafSample (*shape)(float, float) = nullptr;
    switch (species) {
    case TreeSpecies::Broadleaf:
        colours = {{0.20f, 0.42f, 0.10f}, {0.50f, 0.64f, 0.26f}, {0.16f, 0.33f, 0.08f}};
        shape = broadleafLeaf;
        break;
    case TreeSpecies::Birch:
        colours = {{0.34f, 0.54f, 0.14f}, {0.60f, 0.72f, 0.32f}, {0.27f, 0.44f, 0.11f}};
        shape = birchLeaf;
        break;
    case TreeSpecies::Conifer:
        colours = {{0.10f, 0.28f, 0.13f}, {0.40f, 0.50f, 0.30f}, {0.07f, 0.20f, 0.10f}};
        shape = coniferSpray;
        break;
    case TreeSpecies::Shrub:
        colours = {{0.22f, 0.40f, 0.12f}, {0.46f, 0.58f, 0.26f}, {0.17f, 0.31f, 0.10f}};
        shape = shrubSprig;
        break;
    default:
        throw Error("leaf texture: unknown species");
    }
    const uint32_t salt = 1000U + uint32_t(species);
    ImageRgba img(size, size);
    tbb::parallel_for(0, size, [&](int py) {  // rows are independent: the same pixels at any thread count
        const float y = 1.0f - (float(py) + 0.5f) / float(size);  // bottom row is the stem end
        for (int px = 0; px < size; ++px) {
            const float x = (float(px) + 0.5f) / float(size) * 2.0f - 1.0f;
            const LeafSample s = shape(x, y);
            float* out = img.at(px, py);
            if (!s.inside) {
                // colour of the background bleeds the blade colour so filtering does not darken the rim
                out[0] = colours.blade.x;
                out[1] = colours.blade.y;
                out[2] = colours.blade.z;
                out[3] = 0.0f;
                continue;
            }
            const float n = fbm(x * 0.5f + 0.5f, y, 8, 8, 3, salt);
            glm::vec3 c = colours.blade * (0.82f + 0.36f * n);
            c = mix3(colours.edge, c, smoothstepf(0.0f, 0.05f, s.edge));
            c = mix3(c, colours.vein, s.vein);
            out[0] = std::clamp(c.x, 0.0f, 1.0f);
            out[1] = std::clamp(c.y, 0.0f, 1.0f);
            out[2] = std::clamp(c.z, 0.0f, 1.0f);
            out[3] = 1.0f;
        }
    });
    return img;
}

ImageRgba makeBarkTexture(TreeSpecies species, int size)
{
    if (size < 8 || size > 8192) throw Error("bark texture: size " + std::to_string(size) + " is outside [8, 8192]");
    if (species != TreeSpecies::Broadleaf && species != TreeSpecies::Birch && species != TreeSpecies::Conifer &&
        species != TreeSpecies::Shrub)
        throw Error("bark texture: unknown species");
    ImageRgba img(size, size);
    const uint32_t salt = 2000U + uint32_t(species) * 17U;
    tbb::parallel_for(0, size, [&](int py) {
        const float v = (float(py) + 0.5f) / float(size);
        for (int px = 0; px < size; ++px) {
            const float u = (float(px) + 0.5f) / float(size);
            glm::vec3 c(0.0f);
            switch (species) {
            case TreeSpecies::Broadleaf: {
                // long vertical ridges and furrows
                const float ridge = fbm(u, v, 12, 2, 4, salt);
                const float fine = fbm(u, v, 32, 16, 3, salt + 7);
                const float f = smoothstepf(0.35f, 0.65f, ridge);
                c = mix3(glm::vec3(0.16f, 0.13f, 0.10f), glm::vec3(0.42f, 0.39f, 0.34f), f) * (0.85f + 0.3f * fine);
                break;
            }
            case TreeSpecies::Birch: {
                // white bark, dark horizontal lenticels, a few dark patches
                const float fine = fbm(u, v, 16, 16, 3, salt);
                c = glm::vec3(0.86f, 0.85f, 0.80f) * (0.9f + 0.15f * fine);
                constexpr int kCu = 6, kCv = 36;
                const int cu = int(u * kCu), cv = int(v * kCv);
                for (int du = -1; du <= 1; ++du) {
                    const int cell = (cu + du + kCu) % kCu;
                    const float h0 = latticeValue(cell, cv, kCu, kCv, salt + 1);
                    if (h0 < 0.45f) continue;
                    const float centerU = (float(cu + du) + latticeValue(cell, cv, kCu, kCv, salt + 2)) / kCu;
                    const float halfLen = (0.25f + 0.6f * latticeValue(cell, cv, kCu, kCv, salt + 3)) / kCu;
                    const float centerV = (float(cv) + 0.5f) / kCv;
                    const float du2 = std::fabs(u - centerU) / halfLen, dv2 = std::fabs(v - centerV) / (0.18f / kCv);
                    if (du2 * du2 + dv2 * dv2 < 1.0f) c = glm::vec3(0.14f, 0.12f, 0.11f);
                }
                const float patch = fbm(u, v, 3, 6, 4, salt + 9);
                if (patch > 0.68f) c = mix3(c, glm::vec3(0.10f, 0.09f, 0.09f), smoothstepf(0.68f, 0.74f, patch));
                break;
            }
            case TreeSpecies::Conifer: {
                // reddish plates separated by dark cracks (periodic cellular pattern)
                constexpr int kGu = 5, kGv = 8;
                const float gu = u * kGu, gv = v * kGv;
                const int iu = int(gu), iv = int(gv);
                float f1 = 1e9f, f2 = 1e9f;
                for (int dy = -1; dy <= 1; ++dy)
                    for (int dx = -1; dx <= 1; ++dx) {
                        const int cx = iu + dx, cy = iv + dy;
                        const float fx = float(cx) + latticeValue(cx, cy, kGu, kGv, salt + 4);
                        const float fy = float(cy) + latticeValue(cx, cy, kGu, kGv, salt + 5);
                        const float ddx = (gu - fx) * 1.6f, ddy = gv - fy;  // plates taller than wide
                        const float d = std::sqrt(ddx * ddx + ddy * ddy);
                        if (d < f1) {
                            f2 = f1;
                            f1 = d;
                        } else if (d < f2) {
                            f2 = d;
                        }
                    }
                const float fine = fbm(u, v, 16, 16, 3, salt);
                c = glm::vec3(0.46f, 0.26f, 0.16f) * (0.8f + 0.35f * fine);
                c = mix3(glm::vec3(0.12f, 0.08f, 0.06f), c, smoothstepf(0.04f, 0.14f, f2 - f1));
                break;
            }
            case TreeSpecies::Shrub: {
                const float fine = fbm(u, v, 8, 24, 4, salt);
                c = glm::vec3(0.36f, 0.30f, 0.24f) * (0.8f + 0.4f * fine);
                break;
            }
            }
            float* out = img.at(px, py);
            out[0] = std::clamp(c.x, 0.0f, 1.0f);
            out[1] = std::clamp(c.y, 0.0f, 1.0f);
            out[2] = std::clamp(c.z, 0.0f, 1.0f);
            out[3] = 1.0f;
        }
    });
    return img;
}

} // namespace sylva
