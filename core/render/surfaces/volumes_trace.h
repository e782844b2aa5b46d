// Participating media in the renderer (host and device): density grids with LB lighting, marched along
// camera rays (Geist & Westall, "Lattice-Boltzmann Lighting Models", section 3.2.1: "a standard, path
// integrating volume tracer that samples the medium density and the LB lighting solution along each ray"),
// beside single scattering (as in the graphics-blog posts "Faster Fog" and "In-Scattering Demo"), with
// empty-space skipping over a max-density brick grid, blackbody emission and shadow transmittance.
#pragma once

#include <cstdint>
#include <math.h>

#include <glm/glm.hpp>

#include "core/accel/ray.h"
#include "core/base/defines.h"
#include "core/render/lights/light_list.h"

namespace sylva {

// How a volume's in-scattered light is computed (docs/RENDERING.md "Volumes").
//   Lb:       sigma_s x the LB photon density (isotropic), Geist & Westall: no shadow rays, all of it indirect;
//   Single:   as in those posts: sun single scattering with the Henyey-Greenstein phase and a shadow march
//             toward the sun at every step (direct, `local`), no multiple scattering;
//   Combined: Single's sun term plus the LB solution less its uncollided part (multiple scattering,
//             indirect).
enum class VolumeTracer : uint32_t { Lb = 0, Single = 1, Combined = 2 };

// Nodes per side of a brick of the empty-space grid.
inline constexpr int kVolumeBrick = 8;
// Blackbody table: kVolumeBlackbodySize entries from kVolumeBlackbodyLo to kVolumeBlackbodyHi kelvin.
inline constexpr int kVolumeBlackbodySize = 256;
inline constexpr float kVolumeBlackbodyLo = 1000.0f, kVolumeBlackbodyHi = 40000.0f;
// A ray's march stops where every channel's transmittance is below this (the rest adds < 1e-4).
inline constexpr float kVolumeMinTransmittance = 1e-4f;
// The adaptive step keeps the optical depth of one step below this (down to step / 8).
inline constexpr float kVolumeTauPerStep = 0.25f;
// Volumes one camera ray composes (the nearest entries beyond are dropped; shadows take them all).
inline constexpr int kMaxRayVolumes = 8;

// One volume grid (asset), its optics per node spacing at density 1. 96 bytes.
struct VolumeGridRecord {
    glm::ivec3 dims;            // density nodes per axis (z fastest)
    uint32_t densityOffset;     // into RenderView::volumeDensity
    glm::ivec3 bricks;          // brick grid dims (ceil(dims / kVolumeBrick))
    uint32_t brickOffset;       // into volumeBricks: max density over a brick's trilinear support
    glm::vec3 sigmaT;           // extinction per node spacing at density 1, per channel
    uint32_t lightOffset;       // into volumeLight (3 floats per node, normalized: 1 = unobstructed); kNoHit = none
    glm::vec3 sigmaS;           // scattering per node spacing at density 1
    uint32_t temperatureOffset; // into volumeTemperature (kelvin per node); kNoHit = no emission
    glm::vec3 g;                // Henyey-Greenstein asymmetry per channel
    uint32_t tracer;            // VolumeTracer
    float step;                 // largest camera-ray step, nodes
    float shadowStep;           // shadow-march step, nodes
    float emission;             // 2^exposure: multiplies sigma_a rho B(T) / Y(B(6500 K))
    float maxSigmaT;            // max over channels of sigmaT
};

// A placed volume: camera-relative world -> grid node coordinates (node (i,j,k) at (i,j,k); the medium
// fills the node-centred cells, [-0.5, N - 0.5] per axis). 64 bytes.
struct VolumeInstanceRecord {
    glm::vec4 row[3];
    uint32_t grid;              // into RenderView::volumeGrids
    float nodesPerMetre;        // 1 / (spacing x instance scale)
    uint32_t pad[2];
};

// What a volume view needs of RenderView (filled from it by volumeViewOf in shade.h).
struct VolumeArrays {
    const VolumeGridRecord* grids;
    const VolumeInstanceRecord* instances;
    const float* density;
    const float* bricks;
    const float* light;
    const float* temperature;
    const glm::vec3* blackbody;
    uint32_t count;             // instances
};

SYLVA_HD SYLVA_INLINE glm::vec3 volumeToGrid(const VolumeInstanceRecord& in, const glm::vec3& p)
{
    return glm::vec3(glm::dot(glm::vec3(in.row[0]), p) + in.row[0].w, glm::dot(glm::vec3(in.row[1]), p) + in.row[1].w,
                     glm::dot(glm::vec3(in.row[2]), p) + in.row[2].w);
}
SYLVA_HD SYLVA_INLINE glm::vec3 volumeDirToGrid(const VolumeInstanceRecord& in, const glm::vec3& d)
{
    return glm::vec3(glm::dot(glm::vec3(in.row[0]), d), glm::dot(glm::vec3(in.row[1]), d), glm::dot(glm::vec3(in.row[2]), d));
}

// Trilinear weights and base node of grid point c (clamped into the nodes, as sampleLighting does).
struct TrilinearAt {
    int base;                   // linear index of the lower corner
    int sx, sy;                 // strides of x and y (z is 1)
    glm::vec3 f;
};
SYLVA_HD SYLVA_INLINE TrilinearAt trilinearAt(const glm::ivec3& dims, const glm::vec3& c)
{
    const glm::vec3 hi = glm::vec3(dims - 1) - 1e-4f;
    const glm::vec3 q = glm::clamp(c, glm::vec3(0.0f), hi);
    const glm::ivec3 i = glm::ivec3(q);
    TrilinearAt t;
    t.sy = dims.z;
    t.sx = dims.y * dims.z;
    t.base = i.x * t.sx + i.y * t.sy + i.z;
    t.f = q - glm::vec3(i);
    return t;
}

SYLVA_HD SYLVA_INLINE float trilinear1(const float* a, const TrilinearAt& t)
{
    const float* p = a + t.base;
    const float c00 = p[0] + t.f.z * (p[1] - p[0]);
    const float c01 = p[t.sy] + t.f.z * (p[t.sy + 1] - p[t.sy]);
    const float c10 = p[t.sx] + t.f.z * (p[t.sx + 1] - p[t.sx]);
    const float c11 = p[t.sx + t.sy] + t.f.z * (p[t.sx + t.sy + 1] - p[t.sx + t.sy]);
    const float c0 = c00 + t.f.y * (c01 - c00), c1 = c10 + t.f.y * (c11 - c10);
    return c0 + t.f.x * (c1 - c0);
}

SYLVA_HD SYLVA_INLINE glm::vec3 trilinear3(const float* a, const TrilinearAt& t)
{
    glm::vec3 out(0.0f);
    for (int corner = 0; corner < 8; ++corner) {
        const int dx = corner >> 2, dy = (corner >> 1) & 1, dz = corner & 1;
        const float w = (dx ? t.f.x : 1.0f - t.f.x) * (dy ? t.f.y : 1.0f - t.f.y) * (dz ? t.f.z : 1.0f - t.f.z);
        const int node = t.base + dx * t.sx + dy * t.sy + dz;
        out += w * glm::vec3(a[node * 3], a[node * 3 + 1], a[node * 3 + 2]);
    }
    return out;
}

// Henyey-Greenstein phase (normalized over the sphere) at cosine mu between propagation directions.
SYLVA_HD SYLVA_INLINE float henyeyGreenstein(float g, float mu)
{
    const float d = fmaxf(1.0f + g * g - 2.0f * g * mu, 1e-6f);
    return (1.0f - g * g) / (4.0f * 3.14159265358979f * d * sqrtf(d));
}

// The part [t0, t1] of ray (o + t d, grid coordinates) inside the medium box [-0.5, N - 0.5]; false when empty.
SYLVA_HD SYLVA_INLINE bool volumeClip(const glm::ivec3& dims, const glm::vec3& o, const glm::vec3& d, float& t0, float& t1)
{
    const glm::vec3 inv = safeReciprocal(d);
    const glm::vec3 lo(-0.5f), hi = glm::vec3(dims) - 0.5f;
    for (int a = 0; a < 3; ++a) {
        float ta = (lo[a] - o[a]) * inv[a], tb = (hi[a] - o[a]) * inv[a];
        if (d[a] == 0.0f) {
            if (o[a] < lo[a] || o[a] > hi[a]) return false;
            continue;
        }
        if (ta > tb) {
            const float s = ta;
            ta = tb;
            tb = s;
        }
        t0 = fmaxf(t0, ta);
        t1 = fminf(t1, tb);
    }
    return t0 < t1;
}

// Walks the bricks that ray o + t d (grid coordinates) crosses in [t0, t1], nearest first (3D DDA),
// calling f(brickMax, ta, tb) for each; f returns false to stop.
template <class F>
SYLVA_HD inline void walkBricks(const VolumeArrays& vv, const VolumeGridRecord& g, const glm::vec3& o, const glm::vec3& d, float t0, float t1,
                                F&& f)
{
    const float B = float(kVolumeBrick);
    // Brick coordinates: brick b covers grid coordinates [b B - 0.5, (b + 1) B - 0.5).
    const glm::vec3 ob = (o + 0.5f) / B, db = d / B;
    const glm::vec3 start = ob + t0 * db;
    glm::ivec3 cell = glm::clamp(glm::ivec3(glm::floor(start)), glm::ivec3(0), g.bricks - 1);
    glm::ivec3 stepI;
    glm::vec3 tNext, tDelta;
    for (int a = 0; a < 3; ++a) {
        if (db[a] > 0.0f) {
            stepI[a] = 1;
            tNext[a] = (float(cell[a] + 1) - ob[a]) / db[a];
            tDelta[a] = 1.0f / db[a];
        } else if (db[a] < 0.0f) {
            stepI[a] = -1;
            tNext[a] = (float(cell[a]) - ob[a]) / db[a];
            tDelta[a] = -1.0f / db[a];
        } else {
            stepI[a] = 0;
            tNext[a] = 3e38f;
            tDelta[a] = 3e38f;
        }
    }
    float t = t0;
    const float* bricks = vv.bricks + g.brickOffset;
    for (int guard = 0; guard < 4 * (g.bricks.x + g.bricks.y + g.bricks.z) + 8 && t < t1; ++guard) {
        const int axis = tNext.x < tNext.y ? (tNext.x < tNext.z ? 0 : 2) : (tNext.y < tNext.z ? 1 : 2);
        const float te = fminf(tNext[axis], t1);
        if (te > t) {
            const float m = bricks[(cell.x * g.bricks.y + cell.y) * g.bricks.z + cell.z];
            if (!f(m, t, te)) return;
        }
        t = fmaxf(t, te);
        cell[axis] += stepI[axis];
        if (cell[axis] < 0 || cell[axis] >= g.bricks[axis]) return;
        tNext[axis] += tDelta[axis];
    }
}

// Optical depth per channel of volume instance `in` along camera-relative ray org + t dir, t in [tmin, tmax]
// (shadow-march step; bricks without medium skipped).
SYLVA_HD inline glm::vec3 volumeOpticalDepth(const VolumeArrays& vv, const VolumeInstanceRecord& in, const glm::vec3& org, const glm::vec3& dir,
                                             float tmin, float tmax)
{
    const VolumeGridRecord g = vv.grids[in.grid];
    const glm::vec3 o = volumeToGrid(in, org), d = volumeDirToGrid(in, dir);
    float t0 = tmin, t1 = tmax;
    if (!volumeClip(g.dims, o, d, t0, t1)) return glm::vec3(0.0f);
    const float speed = glm::length(d);   // nodes per unit t
    const float* rho = vv.density + g.densityOffset;
    float tauNodes = 0.0f;                // integral of rho over node length
    walkBricks(vv, g, o, d, t0, t1, [&](float m, float ta, float tb) {
        if (m <= 0.0f) return true;
        const float len = (tb - ta) * speed;
        const int n = int(ceilf(len / g.shadowStep));
        const float dt = (tb - ta) / float(n > 0 ? n : 1);
        float sum = 0.0f;
        for (int k = 0; k < n; ++k) sum += trilinear1(rho, trilinearAt(g.dims, o + (ta + (float(k) + 0.5f) * dt) * d));
        tauNodes += sum * dt * speed;
        return tauNodes * g.maxSigmaT < 30.0f;   // exp(-30): opaque
    });
    return g.sigmaT * tauNodes;
}

// Transmittance of every volume along camera-relative ray org + t dir for t in [0, tmax] (shadow rays).
SYLVA_HD inline glm::vec3 volumeTransmittance(const VolumeArrays& vv, const glm::vec3& org, const glm::vec3& dir, float tmax = 1e30f)
{
    glm::vec3 tau(0.0f);
    for (uint32_t i = 0; i < vv.count; ++i) tau += volumeOpticalDepth(vv, vv.instances[i], org, dir, 0.0f, tmax);
    return glm::exp(-tau);
}

// Linear RGB of a blackbody at `kelvin` from the table (luminance 1 at 6500 K); 0 below the table.
SYLVA_HD SYLVA_INLINE glm::vec3 blackbodyRadiance(const VolumeArrays& vv, float kelvin)
{
    if (!(kelvin >= kVolumeBlackbodyLo)) return glm::vec3(0.0f);
    const float x = fminf((kelvin - kVolumeBlackbodyLo) / (kVolumeBlackbodyHi - kVolumeBlackbodyLo), 1.0f) * float(kVolumeBlackbodySize - 1);
    const int i = int(fminf(x, float(kVolumeBlackbodySize - 2)));
    const float f = x - float(i);
    return vv.blackbody[i] + f * (vv.blackbody[i + 1] - vv.blackbody[i]);
}

// What one volume adds along a camera ray segment and how much of what lies behind it gets through.
struct VolumeSegment {
    glm::vec3 transmittance;    // of the whole segment
    glm::vec3 local;            // sun single scattering and emission
    glm::vec3 indirect;         // LB in-scattering (all of it, or its multiply scattered part)
    glm::vec3 albedo;           // integral of T sigma_s: what a uniform ambient radiance of 1 would scatter in
};

// Marches volume instance `in` along camera-relative ray org + t dir, t in [tmin, tmax]: adaptive steps
// (optical depth per step <= kVolumeTauPerStep, at most g.step nodes, at least g.step / 8) through the
// bricks that hold medium, density and light sampled trilinearly at each step's midpoint, integrated with
// the exact exponential over the step (the source held constant: T (1 - e^-sigma_t dt) S / sigma_t).
// sun: the distant light the LB grids are solved toward (RenderView lbLight: direction toward it, unit;
// radiance: surfaces show albedo x it x cos, so its irradiance is pi x it); lbRadiance: the unit of the normalized LB grids (RenderView::lbRadiance: the sun's
// radiance, or 1 where the sun is dark and the sky is in the boundary); indirectScale: the LB's weight, as
// on surfaces.
SYLVA_HD inline VolumeSegment marchVolume(const VolumeArrays& vv, const VolumeInstanceRecord& in, const glm::vec3& org, const glm::vec3& dir,
                                          float tmin, float tmax, const LightRecord& sunLight, const glm::vec3& lbRadiance,
                                          float indirectScale)
{
    const glm::vec3& sunDir = sunLight.direction;
    const glm::vec3& sunRadiance = sunLight.radiance;
    VolumeSegment s{glm::vec3(1.0f), glm::vec3(0.0f), glm::vec3(0.0f), glm::vec3(0.0f)};
    const VolumeGridRecord g = vv.grids[in.grid];
    const glm::vec3 o = volumeToGrid(in, org), d = volumeDirToGrid(in, dir);
    float t0 = tmin, t1 = tmax;
    if (!volumeClip(g.dims, o, d, t0, t1)) return s;
    const float speed = glm::length(d);
    const float* rho = vv.density + g.densityOffset;
    const VolumeTracer mode = VolumeTracer(g.tracer);
    const bool lb = g.lightOffset != kNoHit && mode != VolumeTracer::Single;
    const bool sun = mode != VolumeTracer::Lb;
    const bool hot = g.temperatureOffset != kNoHit;
    const float mu = glm::dot(sunDir, glm::normalize(dir));   // propagation -sunDir vs. toward the camera -dir
    const glm::vec3 phase(henyeyGreenstein(g.g.x, mu), henyeyGreenstein(g.g.y, mu), henyeyGreenstein(g.g.z, mu));
    const glm::vec3 sunSource = phase * 3.14159265358979f * sunRadiance;   // sigma_s rho T_sun x this
    const glm::vec3 lbSource = 0.25f * indirectScale * lbRadiance;          // sigma_s rho phi x this (phi / 4 pi x pi)
    // The sun's uncollided light in the grid's units (combined tracer): T_sun x sunRadiance / lbRadiance (1 when equal).
    glm::vec3 sunInLb(1.0f);
    for (int ch = 0; ch < 3; ++ch)
        if (lbRadiance[ch] > 0.0f && lbRadiance[ch] != sunRadiance[ch]) sunInLb[ch] = sunRadiance[ch] / lbRadiance[ch];
    const glm::vec3 sigmaA = g.sigmaT - g.sigmaS;
    const bool grey = g.sigmaT.x == g.sigmaT.y && g.sigmaT.y == g.sigmaT.z;
    walkBricks(vv, g, o, d, t0, t1, [&](float m, float ta, float tb) {
        if (m <= 0.0f) return true;
        const float len = (tb - ta) * speed;
        const float h = fminf(g.step, fmaxf(kVolumeTauPerStep / (g.maxSigmaT * m), 0.125f * g.step));
        const int n = int(ceilf(len / h));
        const float dt = (tb - ta) / float(n > 0 ? n : 1);
        const float dl = dt * speed;   // nodes per step
        for (int k = 0; k < n; ++k) {
            const float t = ta + (float(k) + 0.5f) * dt;
            const glm::vec3 c = o + t * d;
            const TrilinearAt at = trilinearAt(g.dims, c);
            const float r = trilinear1(rho, at);
            if (!(r > 0.0f)) continue;
            const glm::vec3 sigT = g.sigmaT * r, sigS = g.sigmaS * r;
            // (1 - e^-x) / sigma_t: the in-step weight of a source per unit length (dl when sigma_t -> 0).
            // One exponential when the channels share sigma_t (cloud, smoke, pmma): the same bits as three.
            glm::vec3 stepT, w;
            if (grey) {
                const float e = expf(-sigT.x * dl);
                stepT = glm::vec3(e);
                w = glm::vec3(sigT.x > 1e-6f ? (1.0f - e) / sigT.x : dl);
            } else {
                stepT = glm::exp(-sigT * dl);
                for (int ch = 0; ch < 3; ++ch) w[ch] = sigT[ch] > 1e-6f ? (1.0f - stepT[ch]) / sigT[ch] : dl;
            }
            const glm::vec3 tw = s.transmittance * w;
            s.albedo += tw * sigS;
            glm::vec3 tSun(1.0f);
            if (sun) {
                const glm::vec3 p = org + t * dir;
                tSun = volumeTransmittance(vv, p, sunDir);
                s.local += tw * sigS * sunSource * tSun;
            }
            if (lb) {
                glm::vec3 phi = trilinear3(vv.light + g.lightOffset, at);
                if (sun) phi = glm::max(phi - tSun * sunInLb, glm::vec3(0.0f));   // multiple scattering only
                s.indirect += tw * sigS * phi * lbSource;
            }
            if (hot) {
                const float kelvin = trilinear1(vv.temperature + g.temperatureOffset, at);
                s.local += tw * sigmaA * r * blackbodyRadiance(vv, kelvin) * g.emission;
            }
            s.transmittance *= stepT;
            if (s.transmittance.x < kVolumeMinTransmittance && s.transmittance.y < kVolumeMinTransmittance &&
                s.transmittance.z < kVolumeMinTransmittance)
                return false;
        }
        return true;
    });
    return s;
}

} // namespace sylva
