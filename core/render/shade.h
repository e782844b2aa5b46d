// Shading of one camera sample: sun light with shadow rays, LB indirect light, sky (host and device).
#pragma once

#include "core/render/render_view.h"
#include "core/render/trace.h"

namespace sylva {

// The three parts a render mode combines (linear RGB): local = sun light only, indirect = LB
// indirect light (ground: sky light), albedo = the surface colour the indirect light multiplies
// (for the constant-ambient comparison), skyCover = share of samples that saw the sky. Beside them,
// for the render passes only (no mode reads them): normal = the unit surface normal facing the
// viewer (world orientation; 0 for the sky), averaged over a pixel's samples like the parts, and
// depth = the distance along the camera's forward axis to the surface, the nearest over the samples
// (kSkyDepth for the sky). background = the radiance of a Preetham or map sky where samples saw it
// (averaged like the parts; 0 for the constant sky, which composes as skyCover x its colour). A
// Preetham or map sky's light on surfaces (its virtual lights) is direct light: it is in `local`.
// 68 bytes.
struct SampleParts {
    glm::vec3 local;
    glm::vec3 indirect;
    glm::vec3 albedo;
    float skyCover;
    glm::vec3 normal;
    float depth;
    glm::vec3 background;
};

// The depth of a sample that saw the sky (Cycles' value for the background of its Z pass).
inline constexpr float kSkyDepth = 1e10f;

// Linear RGB of a render mode from a pixel's parts: full = local + indirect, local = sun light only,
// ambient = local + a constant ambient x albedo, lb = indirect only; plus the sky where samples saw it
// (skyCover x the constant sky `sky`, composeSky(scene), plus the other skies' background).
SYLVA_HD SYLVA_INLINE glm::vec3 composeSample(const SampleParts& p, RenderMode mode, const glm::vec3& sky, float ambient)
{
    glm::vec3 c(0.0f);
    switch (mode) {
    case RenderMode::Full: c = p.local + p.indirect; break;
    case RenderMode::Local: c = p.local; break;
    case RenderMode::Ambient: c = p.local + ambient * p.albedo; break;
    case RenderMode::Lb: c = p.indirect; break;
    }
    const glm::vec3 withSky = c + p.skyCover * sky;
    return withSky + p.background;
}

// Bilinear, wrapped texture lookup (v = 0 is the bottom row, as in OBJ).
SYLVA_HD inline glm::vec4 sampleTexture(const RenderView& v, int32_t index, glm::vec2 uv)
{
    const TextureRecord t = v.textures[index];
    const float x = (uv.x - floorf(uv.x)) * float(t.width) - 0.5f;
    const float y = (1.0f - (uv.y - floorf(uv.y))) * float(t.height) - 0.5f;
    const float fx = floorf(x), fy = floorf(y);
    const float ax = x - fx, ay = y - fy;
    int x0 = int(fx), y0 = int(fy);
    x0 = ((x0 % t.width) + t.width) % t.width;
    y0 = ((y0 % t.height) + t.height) % t.height;
    const int x1 = (x0 + 1) % t.width, y1 = (y0 + 1) % t.height;
    const glm::vec4* p = v.texels + t.offset;
    return (1.0f - ay) * ((1.0f - ax) * p[y0 * t.width + x0] + ax * p[y0 * t.width + x1]) +
           ay * ((1.0f - ax) * p[y1 * t.width + x0] + ax * p[y1 * t.width + x1]);
}

// Trilinear lookup of a species' normalized lighting grid at a species-frame point (clamped to the grid).
SYLVA_HD inline glm::vec3 sampleLighting(const RenderView& v, const SpeciesRecord& sp, const glm::vec3& p)
{
    if (sp.gridInvSpacing == 0.0f) return glm::vec3(1.0f);
    const glm::vec3 g = (p - sp.gridOrigin) * sp.gridInvSpacing;
    const glm::vec3 hi = glm::vec3(sp.gridDims - 1) - 1e-4f;
    const glm::vec3 c = glm::clamp(g, glm::vec3(0.0f), hi);
    const glm::ivec3 i = glm::ivec3(c);
    const glm::vec3 f = c - glm::vec3(i);
    const float* L = v.lighting + sp.gridOffset;
    const int sy = sp.gridDims.z, sx = sp.gridDims.y * sp.gridDims.z;
    glm::vec3 out(0.0f);
    for (int corner = 0; corner < 8; ++corner) {
        const int dx = corner >> 2, dy = (corner >> 1) & 1, dz = corner & 1;
        const float w = (dx ? f.x : 1.0f - f.x) * (dy ? f.y : 1.0f - f.y) * (dz ? f.z : 1.0f - f.z);
        const int node = (i.x + dx) * sx + (i.y + dy) * sy + (i.z + dz);
        out += w * glm::vec3(L[node * 3], L[node * 3 + 1], L[node * 3 + 2]);
    }
    return out;
}

// The forest-level grid's factor on instance `in`'s species lighting at species-frame point lp (1 where the
// instance has none): its per-channel factor at the crown centre, blended towards the mix of its face
// factors along the world direction d from the centre (weights d.x^2, d.y^2, d.z^2, the face of each sign)
// as lp moves out to the crown box's half extent, so the side of a crown facing open ground keeps its light.
// Continuous in lp; per instance, read by every backend (the species grid stays one per species).
SYLVA_HD inline glm::vec3 forestFactor(const RenderView& v, const InstanceRecord& in, const glm::vec3& lp)
{
    if (in.light == 0u) return glm::vec3(1.0f);
    const InstanceLightRecord& r = v.instanceLights[in.light - 1u];
    const glm::vec3 centre(r.factor);
    const glm::vec3 o = lp - r.centre;
    const glm::vec3 w = toWorldNormal(in, o);   // R o / scale: the world direction
    const float wl = glm::length(w);
    if (!(wl > 0.0f)) return centre;
    const glm::vec3 d = w / wl;
    const glm::vec3 d2 = d * d;
    const glm::vec3 cube = d2.x * glm::vec3(r.face[d.x >= 0.0f ? 0 : 1]) + d2.y * glm::vec3(r.face[d.y >= 0.0f ? 2 : 3]) +
                           d2.z * glm::vec3(r.face[d.z >= 0.0f ? 4 : 5]);
    const float t = fminf(glm::length(o) * r.invRadius, 1.0f);
    return centre + t * (cube - centre);
}

// Is the distant light toward unit `dir` visible from camera-relative point p (already offset off its
// surface)? The alpha-tested any-hit query; always with shadows off.
SYLVA_HD inline bool directionVisible(const RenderView& v, const glm::vec3& p, const glm::vec3& dir)
{
    if (!v.shadows) return true;
    Ray r{p, 0.0f, dir, 1e30f};
    Hit h{};
    return !traceScene<true>(v, r, h);
}

// Is the sun visible from camera-relative point p (already offset off its surface)?
SYLVA_HD inline bool sunVisible(const RenderView& v, const glm::vec3& p) { return directionVisible(v, p, v.sunDir); }

// Radiance of the view's Preetham or map sky (without its sun) toward unit direction d; the map's pixels
// are the skyMap array (on the device too).
SYLVA_HD inline glm::vec3 viewSkyRadiance(const RenderView& v, const glm::vec3& d)
{
    if (v.skyModel.kind == sky::SkyKind::Map) {
        sky::EnvMapView m = v.skyModel.map;
        m.rgb = v.skyMap;
        return sky::envMapRadiance(m, d);
    }
    return sky::skyRadiance(v.skyModel, d);
}

// Irradiance / pi at camera-relative point p (offset already) with unit normal n from the virtual sky
// lights of the subset pixel (px, py) uses for its sample s (interleaved sampling, core/sky/
// virtual_lights.h): each light of the subset weighted by K, one shadow ray each. A diffuse surface of
// albedo a shows a x this. 0 without sky lights.
SYLVA_HD inline glm::vec3 skyLightIrradiance(const RenderView& v, const glm::vec3& p, const glm::vec3& n, int px, int py, int s)
{
    glm::vec3 e(0.0f);
    const int count = int(v.skyLightCount);
    if (count == 0) return e;
    const sky::Interleave& il = v.skyInterleave;
    const int subset = sky::interleavedSubset(il, px, py, s);
    const int size = sky::subsetSize(il, subset, count);
    for (int k = 0; k < size; ++k) {
        const sky::VirtualLight& l = v.skyLights[sky::subsetLight(il, subset, k)];
        const float c = glm::dot(n, l.direction);
        if (c > 0.0f && directionVisible(v, p, l.direction)) e += l.power * c;
    }
    return e * (sky::interleaveWeight(il) / sky::kPi);
}

// Offset along the geometric normal, scaled to the magnitude of the coordinates the hit was computed
// from (no self-shadowing acne): camera-relative p and, for a mesh hit, `extent` = its species-frame
// point's largest coordinate in world units. No floor in metres: a 1 m floor lifted the shadow rays of
// a micrometre-sized scene clear of all its geometry (it lost every shadow).
SYLVA_HD SYLVA_INLINE glm::vec3 offsetPoint(const glm::vec3& p, const glm::vec3& ng, float extent = 0.0f)
{
    const float m = fmaxf(fmaxf(fmaxf(fabsf(p.x), fabsf(p.y)), fmaxf(fabsf(p.z), extent)), 1e-30f);
    return p + ng * (m * 2e-5f);
}

// Shading runs in stages, each a SYLVA_HD function the CPU loop and the GPU kernel chain the same way
// (shadeRay): intersect -> surface -> volume -> background and lights. A new stage or a new kind of
// light goes into this chain once and runs on every backend.

// Stage 1, intersect: the first surface along a camera ray (ground, or a mesh reached through the levels).
SYLVA_HD SYLVA_INLINE bool intersectStage(const RenderView& v, const Ray& ray, Hit& hit) { return traceScene<false>(v, ray, hit); }

// What the surface stage finds at a hit: the point, the normal facing the viewer, the material and the
// LB lighting sample (species frame) the light stage needs.
struct SurfacePoint {
    glm::vec3 p;             // camera-relative
    glm::vec3 ng;            // unit normal facing the viewer
    glm::vec3 viewDir;       // toward the camera
    glm::vec3 albedo;        // diffuse colour (times the texture)
    glm::vec3 specular;
    float shininess;
    float extent;            // the hit's largest species-frame coordinate in world units (offsetPoint); 0 = ground
    glm::vec3 lighting;      // normalized LB photon density at the point (meshes)
    glm::vec3 indirectWeight; // what the surface makes of it (SpeciesRecord leafIndirect / barkIndirect; 1 on the ground)
    bool ground;
};

// Stage 2, surface: geometry and material at the hit.
SYLVA_HD inline SurfacePoint surfaceStage(const RenderView& v, const Ray& ray, const Hit& hit)
{
    SurfacePoint s{};
    s.p = ray.org + hit.t * ray.dir;
    s.viewDir = glm::normalize(-ray.dir);
    if (hit.prim == kGroundPrim) {
        s.ground = true;
        s.ng = glm::vec3(0.0f, ray.dir.y < 0.0f ? 1.0f : -1.0f, 0.0f);
        s.albedo = v.groundColor;
        return s;
    }
    if (hit.inst == kTerrainInst) {
        // The triangle's normal (terrain frame = world orientation) facing the viewer; the colour from
        // slope and altitude: rock where steeper than the rock slope, snow above the snow line.
        s.ground = true;
        const glm::vec3 n = heightFieldNormal(HeightFieldView{v.terrain, v.terrainHeights, v.terrainRanges}, hit.prim);
        s.ng = glm::dot(n, s.viewDir) < 0.0f ? -n : n;
        const float y = (s.p - v.terrainOrigin).y;
        s.albedo = y > v.terrainSnowY ? v.terrainSnow : (n.y < v.terrainRockCos ? v.terrainRock : v.groundColor);
        // The hit was computed in the height field's rebased frame, whose heights keep their magnitude.
        const glm::vec3 lp = s.p - v.terrainBase;
        s.extent = fmaxf(fmaxf(fabsf(lp.x), fabsf(lp.y)), fabsf(lp.z));
        return s;
    }
    const InstanceRecord in = hitInstance(v, hit);
    const SpeciesRecord& sp = v.species[v.geometries[in.geometry].species];
    const glm::uvec3 tv = v.triVerts[hit.prim];
    const MaterialRecord m = v.materials[v.triMaterial[hit.prim]];
    // Geometric normal from the triangle's vertices (species frame) and the interpolated shading normal.
    const glm::vec3 lp = toLocalPoint(in, ray.org) + hit.t * toLocalDir(in, ray.dir);
    const float b0 = 1.0f - hit.u - hit.v;
    glm::vec3 ns = b0 * v.normals[tv.x] + hit.u * v.normals[tv.y] + hit.v * v.normals[tv.z];
    glm::vec3 ng = glm::normalize(toWorldNormal(in, ns));
    if (!(glm::dot(ng, ng) > 0.5f)) ng = glm::vec3(0.0f, 1.0f, 0.0f);
    if (glm::dot(ng, s.viewDir) < 0.0f) ng = -ng;   // two-sided: face the viewer
    s.ng = ng;
    glm::vec3 kd = m.diffuse;
    if (m.texture >= 0) {
        const glm::vec2 uv = b0 * v.uvs[tv.x] + hit.u * v.uvs[tv.y] + hit.v * v.uvs[tv.z];
        kd *= glm::vec3(sampleTexture(v, m.texture, uv));
    }
    s.albedo = kd;
    s.indirectWeight = m.isLeaf ? sp.leafIndirect : glm::vec3(sp.barkIndirect);
    if (m.isLeaf)   // a leaf scatters at most kMaxLeafScattering of what it receives (leaf_optics.h)
        for (int c = 0; c < 3; ++c)
            if (kd[c] * s.indirectWeight[c] > sp.leafIndirectCap) s.indirectWeight[c] = sp.leafIndirectCap / kd[c];
    s.specular = m.specular;
    s.shininess = m.shininess;
    s.extent = in.scale * fmaxf(fmaxf(fabsf(lp.x), fabsf(lp.y)), fabsf(lp.z));
    // The forest grid's factor: per top-level instance, or for a landscape plant the landscape lattice's at the hit.
    const glm::vec3 factor = hit.inst == kLandscapeInst ? landLightFactor(v.landLightLayout, v.landLight, s.p - v.terrainOrigin) : forestFactor(v, in, lp);
    s.lighting = sampleLighting(v, sp, lp) * factor;
    return s;
}

// Stage 3, volume: what participating media along the camera ray's segment [ray.tmin, tEnd] add to
// and take from the parts behind them (no volume kind yet: the parts pass unchanged).
SYLVA_HD SYLVA_INLINE VolumeArrays volumeViewOf(const RenderView& v)
{
    return VolumeArrays{v.volumeGrids, v.volumeInstances, v.volumeDensity, v.volumeBricks, v.volumeLight, v.volumeTemperature,
                      v.volumeBlackbody, v.volumeCount};
}

// The volumes the segment crosses are composed back to front (each one's entry point orders them):
// what lies behind is multiplied by the volume's transmittance (the constant sky through skyCover x its
// mean, the colour difference into background) and the volume's own light is added (core/render/
// volume_trace.h marchVolume: sun single scattering and emission into local, LB into indirect, the
// scattered share of a uniform ambient into albedo, so every render mode keeps its meaning). Without
// volumes the parts pass unchanged.
SYLVA_HD inline void volumeStage(const RenderView& v, const Ray& ray, float tEnd, SampleParts& parts)
{
    if (v.volumeCount == 0) return;
    const VolumeArrays vv = volumeViewOf(v);
    uint32_t order[kMaxRayVolumes];
    float entry[kMaxRayVolumes];
    int n = 0;
    for (uint32_t i = 0; i < v.volumeCount; ++i) {
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
        const VolumeSegment s = marchVolume(vv, v.volumeInstances[order[k]], ray.org, ray.dir, ray.tmin, tEnd, v.sunDir, v.sunRadiance,
                                            v.lbRadiance, v.indirectScale);
        const glm::vec3& T = s.transmittance;
        const float mean = (T.x + T.y + T.z) * (1.0f / 3.0f);
        parts.local = parts.local * T + s.local;
        parts.indirect = parts.indirect * T + s.indirect;
        parts.albedo = parts.albedo * T + s.albedo;
        parts.background = parts.background * T + parts.skyCover * (T - mean) * v.sky;
        parts.skyCover *= mean;
    }
}

// The sun's light at camera-relative point p that gets through the volumes (1 without volumes).
SYLVA_HD SYLVA_INLINE glm::vec3 sunThroughVolumes(const RenderView& v, const glm::vec3& p)
{
    return v.volumeCount == 0 ? glm::vec3(1.0f) : volumeTransmittance(volumeViewOf(v), p, v.sunDir);
}

// Stage 4, background and lights: a ray that hit nothing sees the sky (the constant one through
// skyCover, a Preetham or map sky's radiance toward the ray in `background`); a surface gets the sun
// (with a shadow ray), the sky's virtual lights of its interleaved subset (shadow rays, into `local`)
// and its indirect light (LB on meshes, the uniform constant sky on the Lambertian ground).
SYLVA_HD SYLVA_INLINE SampleParts backgroundStage(const RenderView& v, const Ray& ray)
{
    SampleParts out{glm::vec3(0.0f), glm::vec3(0.0f), glm::vec3(0.0f), 1.0f, glm::vec3(0.0f), kSkyDepth, glm::vec3(0.0f)};
    if (v.skyModel.kind != sky::SkyKind::Constant) out.background = viewSkyRadiance(v, ray.dir);
    return out;
}

// Whether the light stage casts a shadow ray toward the sun from surface s (sunShadowRay: that ray).
SYLVA_HD SYLVA_INLINE bool castsSunRay(const RenderView& v, const SurfacePoint& s) { return v.shadows && glm::dot(s.ng, v.sunDir) > 0.0f; }
SYLVA_HD SYLVA_INLINE Ray sunShadowRay(const RenderView& v, const SurfacePoint& s) { return Ray{offsetPoint(s.p, s.ng, s.extent), 0.0f, v.sunDir, 1e30f}; }

// sunSeen: -1 traces the sun's shadow ray here; 0 or 1 is its answer traced by the caller (a packet of a
// tile's shadow rays, core/render/render_cpu.cpp), used only where castsSunRay.
SYLVA_HD inline SampleParts lightStage(const RenderView& v, const SurfacePoint& s, int px = 0, int py = 0, int sample = 0, int sunSeen = -1)
{
    SampleParts out{glm::vec3(0.0f), glm::vec3(0.0f), s.albedo, 0.0f, s.ng, glm::dot(s.p, v.camera.forward), glm::vec3(0.0f)};
    const float nl = glm::dot(s.ng, v.sunDir);
    auto sunLit = [&] { return sunSeen >= 0 ? (!v.shadows || sunSeen != 0) : sunVisible(v, offsetPoint(s.p, s.ng, s.extent)); };
    if (s.ground) {   // the plane or the terrain: Lambertian, lit by the sun and the uniform sky
        if (nl > 0.0f && sunLit()) {
            out.local = s.albedo * v.sunRadiance * nl;
            if (v.volumeCount > 0) out.local *= sunThroughVolumes(v, s.p);   // cloud shadows
        }
        if (v.skyLightCount > 0) out.local += s.albedo * skyLightIrradiance(v, offsetPoint(s.p, s.ng, s.extent), s.ng, px, py, sample);
        out.indirect = s.albedo * v.sky;
        return out;
    }
    if (nl > 0.0f && sunLit()) {
        glm::vec3 c = s.albedo * nl;
        if (s.shininess > 0.0f && (s.specular.x > 0.0f || s.specular.y > 0.0f || s.specular.z > 0.0f)) {
            const glm::vec3 r = 2.0f * nl * s.ng - v.sunDir;
            const float vr = glm::dot(s.viewDir, r);
            if (vr > 0.0f) c += s.specular * powf(vr, s.shininess);
        }
        out.local = c * v.sunRadiance;
        if (v.volumeCount > 0) out.local *= sunThroughVolumes(v, s.p);
    }
    if (v.skyLightCount > 0) out.local += s.albedo * skyLightIrradiance(v, offsetPoint(s.p, s.ng, s.extent), s.ng, px, py, sample);
    out.indirect = s.albedo * s.lighting * s.indirectWeight * v.lbRadiance * v.indirectScale;
    return out;
}

// The stages after intersect for a camera ray whose first hit is known (found; hit and its surface sp where
// found), sample s of pixel (px, py); sunSeen as lightStage takes it.
SYLVA_HD inline SampleParts shadeFound(const RenderView& v, const Ray& ray, bool found, const Hit& hit, const SurfacePoint& sp, int px, int py, int s,
                                       int sunSeen = -1)
{
    SampleParts out = found ? lightStage(v, sp, px, py, s, sunSeen) : backgroundStage(v, ray);
    volumeStage(v, ray, found ? hit.t : ray.tmax, out);
    return out;
}

// Shades one camera ray, sample s of pixel (px, py) (which subset of the sky lights it uses): the stages in order.
SYLVA_HD inline SampleParts shadeRay(const RenderView& v, const Ray& ray, int px = 0, int py = 0, int s = 0)
{
    Hit hit{};
    const bool found = intersectStage(v, ray, hit);
    return shadeFound(v, ray, found, hit, found ? surfaceStage(v, ray, hit) : SurfacePoint{}, px, py, s);
}

// Camera ray through image position (x, y) in pixels (y down, 0..width/height), camera-relative.
SYLVA_HD SYLVA_INLINE Ray cameraRay(const RenderView& v, float x, float y)
{
    const float sx = (2.0f * x / float(v.width) - 1.0f) * v.camera.tanHalfX;
    const float sy = (1.0f - 2.0f * y / float(v.height)) * v.camera.tanHalfY;
    Ray r;
    r.org = glm::vec3(0.0f);
    r.dir = glm::normalize(v.camera.forward + sx * v.camera.right + sy * v.camera.up);
    r.tmin = 0.0f;
    r.tmax = 1e30f;
    return r;
}

// A hash-based random number in [0,1) for sample positions (deterministic per pixel and sample).
SYLVA_HD SYLVA_INLINE float hashToUnit(uint32_t a, uint32_t b, uint32_t c)
{
    uint32_t h = a * 0x9E3779B1u ^ (b + 0x7F4A7C15u) * 0x85EBCA77u ^ (c + 0x165667B1u) * 0xC2B2AE3Du;
    h ^= h >> 16;
    h *= 0x7FEB352Du;
    h ^= h >> 15;
    h *= 0x846CA68Bu;
    h ^= h >> 16;
    return float(h >> 8) * (1.0f / 16777216.0f);
}

// Sample s of spp inside pixel (px, py): one sample at the centre; a stratified n x n grid when spp
// is a square; otherwise jittered random positions.
SYLVA_HD SYLVA_INLINE glm::vec2 samplePosition(int px, int py, int s, int spp)
{
    if (spp == 1) return glm::vec2(float(px) + 0.5f, float(py) + 0.5f);
    int n = int(sqrtf(float(spp)) + 0.5f);
    const float jx = hashToUnit(uint32_t(px), uint32_t(py), uint32_t(2 * s));
    const float jy = hashToUnit(uint32_t(px), uint32_t(py), uint32_t(2 * s + 1));
    if (n * n == spp) {
        const int sx = s % n, sy = s / n;
        return glm::vec2(float(px) + (float(sx) + jx) / float(n), float(py) + (float(sy) + jy) / float(n));
    }
    return glm::vec2(float(px) + jx, float(py) + jy);
}

// A pixel's box filter: the samples summed in order (the depth their minimum), then averaged.
SYLVA_HD SYLVA_INLINE SampleParts pixelSumStart()
{
    return SampleParts{glm::vec3(0.0f), glm::vec3(0.0f), glm::vec3(0.0f), 0.0f, glm::vec3(0.0f), kSkyDepth, glm::vec3(0.0f)};
}
SYLVA_HD SYLVA_INLINE void pixelSumAdd(SampleParts& sum, const SampleParts& p)
{
    sum.local += p.local;
    sum.indirect += p.indirect;
    sum.albedo += p.albedo;
    sum.skyCover += p.skyCover;
    sum.normal += p.normal;
    sum.depth = fminf(sum.depth, p.depth);
    sum.background += p.background;
}
SYLVA_HD SYLVA_INLINE void pixelSumAverage(SampleParts& sum, int samples)
{
    const float inv = 1.0f / float(samples > 0 ? samples : 1);
    sum.local *= inv;
    sum.indirect *= inv;
    sum.albedo *= inv;
    sum.skyCover *= inv;
    sum.normal *= inv;
    sum.background *= inv;
}

// The samples a pixel takes in this view: v.sampleBegin .. sampleEnd (all spp when sampleEnd is 0).
SYLVA_HD SYLVA_INLINE int sampleEndOf(const RenderView& v) { return v.sampleEnd > 0 ? v.sampleEnd : v.spp; }

// Camera ray of sample s of pixel (px, py).
SYLVA_HD SYLVA_INLINE Ray sampleRay(const RenderView& v, int px, int py, int s)
{
    const glm::vec2 pos = samplePosition(px, py, s, v.spp);
    return cameraRay(v, pos.x, pos.y);
}

// All samples of one pixel (or those of v.sampleBegin .. sampleEnd), box-filtered.
SYLVA_HD inline SampleParts shadePixel(const RenderView& v, int px, int py)
{
    SampleParts sum = pixelSumStart();
    const int sBegin = v.sampleBegin, sEnd = sampleEndOf(v);
    for (int s = sBegin; s < sEnd; ++s) pixelSumAdd(sum, shadeRay(v, sampleRay(v, px, py, s), px, py, s));
    pixelSumAverage(sum, sEnd - sBegin);
    return sum;
}

} // namespace sylva
