// The volumes kind, the list's medium (host and device): density grids with LB lighting, marched along
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
#include "core/render/render_view.h"
#include "core/render/surface_point.h"

namespace sylva {

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

// The volumes' arrays of a view.
SYLVA_HD SYLVA_INLINE VolumeArrays volumeViewOf(const RenderView& v)
{
    return VolumeArrays{v.volumeGrids, v.volumeInstances, v.volumeDensity, v.volumeBricks, v.volumeLight, v.volumeTemperature,
                        v.volumeBlackbody, v.volumes.count};
}

// The volumes kind's segment of a camera ray, [ray.tmin, tEnd]: the volumes it crosses composed back to
// front (each one's entry point orders them; the nearest kMaxRayVolumes kept): what lies behind is multiplied
// by a volume's transmittance (the constant sky through skyCover x its mean, the colour difference into
// background) and the volume's own light is added (marchVolume: sun single scattering and emission into
// local, LB into indirect, the scattered share of a uniform ambient into albedo, so every render mode keeps
// its meaning).
SYLVA_HD inline void crossVolumes(const RenderView& v, const Ray& ray, float tEnd, SampleParts& parts)
{
    if (v.volumes.count == 0) return;
    const VolumeArrays vv = volumeViewOf(v);
    uint32_t order[kMaxRayVolumes];
    float entry[kMaxRayVolumes];
    int n = 0;
    for (uint32_t i = 0; i < v.volumes.count; ++i) {
        const VolumeInstanceRecord& in = v.volumeInstances[i];
        float t0 = ray.tmin, t1 = tEnd;
        if (!volumeClip(v.volumeGrids[in.grid].dims, volumeToGrid(in, ray.org), volumeDirToGrid(in, ray.dir), t0, t1)) continue;
        if (n == kMaxRayVolumes && !(t0 < entry[n - 1])) continue;   // full: keep the nearest
        int k = n < kMaxRayVolumes ? n++ : n - 1;
        while (k > 0 && entry[k - 1] > t0) {        // nearest entry first
            order[k] = order[k - 1];
            entry[k] = entry[k - 1];
            --k;
        }
        order[k] = i;
        entry[k] = t0;
    }
    for (int k = n - 1; k >= 0; --k) {
        const VolumeSegment s = marchVolume(vv, v.volumeInstances[order[k]], ray.org, ray.dir, ray.tmin, tEnd, lbLight(v), v.lbRadiance,
                                            v.indirectScale);
        const glm::vec3& T = s.transmittance;
        const float mean = (T.x + T.y + T.z) * (1.0f / 3.0f);
        parts.local = parts.local * T + s.local;
        parts.indirect = parts.indirect * T + s.indirect;
        parts.albedo = parts.albedo * T + s.albedo;
        parts.background = parts.background * T + parts.skyCover * (T - mean) * v.sky.constant;
        parts.skyCover *= mean;
    }
}

// The volumes kind's transmittance along a shadow ray (cloud shadows).
SYLVA_HD SYLVA_INLINE glm::vec3 transmittanceVolumes(const RenderView& v, const glm::vec3& org, const glm::vec3& dir, float tmax)
{
    if (v.volumes.count == 0) return glm::vec3(1.0f);
    return volumeTransmittance(volumeViewOf(v), org, dir, tmax);
}

} // namespace sylva
