// Flattens species, pruned levels, instance groups, textures and lighting grids into the RenderView arrays;
// builds every level's acceleration structure. The one builder of the levels, for every front end.
#include "core/render/render_scene.h"
#include "core/render/scene_build.h"

#include <array>
#include <algorithm>
#include <cmath>
#include <limits>

#include <tbb/parallel_for.h>

#include "core/base/error.h"
#include "core/lb/leaf_optics.h"
#include "core/render/prune.h"
#include "core/render/tonemap.h"
#include "core/sky/sky_light.h"
#include "core/terrain/height_field.h"
#include "core/terrain/landscape_light.h"

namespace sylva {

using namespace scene_build;
glm::dmat3 rotationDeg(const glm::vec3& deg)
{
    const glm::dvec3 r = glm::dvec3(deg) * (M_PI / 180.0);
    const double cx = std::cos(r.x), sx = std::sin(r.x), cy = std::cos(r.y), sy = std::sin(r.y);
    const double cz = std::cos(r.z), sz = std::sin(r.z);
    // glm matrices are column-major: m[col][row].
    const glm::dmat3 rx(1, 0, 0, 0, cx, sx, 0, -sx, cx);
    const glm::dmat3 ry(cy, 0, -sy, 0, 1, 0, sy, 0, cy);
    const glm::dmat3 rz(cz, sz, 0, -sz, cz, 0, 0, 0, 1);
    return rz * ry * rx;
}

namespace {



// Checks one instance's reference (species or group) against the scene; `where` names it in the message.
void checkReference(const Scene& scene, const InstanceDesc& d, const std::string& where)
{
    if (d.group != kNoGroup) {
        if (d.group >= scene.groups.size()) throw Error("render: " + where + " names a missing group");
    } else if (d.species >= scene.species.size()) {
        throw Error("render: " + where + " names a missing species");
    }
}

// Groups in build order (every group after the groups it places), refusing cycles and nesting deeper
// than the traversal's levels.
std::vector<uint32_t> groupBuildOrder(const Scene& scene)
{
    const size_t ng = scene.groups.size();
    std::vector<int> height(ng, -1);   // -1 unvisited, -2 on the current path
    std::vector<uint32_t> order;
    auto visit = [&](auto&& self, uint32_t g) -> int {
        if (height[g] == -2) throw Error("render: group '" + scene.groups[g].name + "' contains itself");
        if (height[g] >= 0) return height[g];
        height[g] = -2;
        const GroupDesc& gd = scene.groups[g];
        if (gd.instances.empty()) throw Error("render: group '" + gd.name + "' has no instances");
        int h = 1;
        for (size_t i = 0; i < gd.instances.size(); ++i) {
            const InstanceDesc& d = gd.instances[i];
            checkReference(scene, d, "instance " + std::to_string(i) + " of group '" + gd.name + "'");
            if (d.group != kNoGroup) h = std::max(h, 1 + self(self, d.group));
        }
        if (h > kMaxLevels - 1)
            throw Error("render: group '" + gd.name + "' nests " + std::to_string(h) + " groups deep; at most " +
                        std::to_string(kMaxLevels - 1) + " levels of groups below the scene's instances are traced");
        height[g] = h;
        order.push_back(g);
        return h;
    };
    for (uint32_t g = 0; g < ng; ++g) visit(visit, g);
    return order;
}




} // namespace

// The byte figures of AccelStats from the array table: each array counts towards its stat column.
void countFrameBytes(RenderScene& rs)
{
    size_t bytes[size_t(ArrayStat::None) + 1] = {};
#define SYLVA_X(part, where, T, name, stat) bytes[size_t(ArrayStat::stat)] += rs.name.size() * sizeof(T);
    SYLVA_RENDER_ARRAYS(SYLVA_X)
#undef SYLVA_X
    AccelStats& st = rs.buildStats;
    const bool kd = rs.accel == AccelKind::KdTree;
    st.tlasBytes = bytes[size_t(ArrayStat::Tlas)];
    st.wideTlasBytes = bytes[size_t(ArrayStat::WideTlas)];
    st.instanceBytes = bytes[size_t(ArrayStat::Instances)];
    st.blasBytes = bytes[size_t(ArrayStat::Blas)] + bytes[size_t(kd ? ArrayStat::KdBlas : ArrayStat::BvhBlas)];
    st.wideBlasBytes = bytes[size_t(ArrayStat::WideBlas)];
    st.triangleBytes = bytes[size_t(kd ? ArrayStat::KdTriangles : ArrayStat::BvhTriangles)];
    st.terrainBytes = bytes[size_t(ArrayStat::Terrain)];
    st.landscapeBytes = bytes[size_t(ArrayStat::Landscape)];
}

CameraRecord makeCamera(const CameraDesc& c, int width, int height)
{
    const glm::dvec3 fwd = c.target - c.position;
    if (!(glm::length(fwd) > 0.0)) throw Error("camera: position and target coincide");
    CameraRecord r;
    r.forward = glm::vec3(glm::normalize(fwd));
    const glm::vec3 right = glm::cross(r.forward, c.up);
    if (!(glm::length(right) > 1e-6f)) throw Error("camera: up is parallel to the view direction");
    r.right = glm::normalize(right);
    r.up = glm::cross(r.right, r.forward);
    r.tanHalfY = std::tan(double(c.fovY) * M_PI / 360.0);
    r.tanHalfX = r.tanHalfY * float(width) / float(height);
    return r;
}

InstanceRecord makeInstance(const InstanceDesc& inst, const glm::dvec3& frameOrigin)
{
    // world = R (s x_local) + p  =>  x_local = R^T (world - p) / s, with world = rel + frameOrigin.
    const glm::dmat3 rt = glm::transpose(rotationDeg(inst.rotationDeg)) * (1.0 / double(inst.scale));
    const glm::dvec3 t = -(rt * (inst.position - frameOrigin));
    InstanceRecord r{};
    for (int i = 0; i < 3; ++i) r.row[i] = glm::vec4(float(rt[0][i]), float(rt[1][i]), float(rt[2][i]), float(t[i]));
    r.scale = inst.scale;
    r.geometry = inst.species;   // the full species; the builder picks a pruned level or the group's record
    return r;
}


RenderView RenderScene::view() const
{
    RenderView v = frame;
#define SYLVA_X(part, where, T, name, stat) v.name = name.empty() ? nullptr : name.data();
    SYLVA_RENDER_ARRAYS(SYLVA_X)
#undef SYLVA_X
    v.instanceCount = uint32_t(instances.size());
    v.volumes.count = uint32_t(volumeInstances.size());
    v.lightCount = uint32_t(lights.size());
    v.spheres.count = uint32_t(sphereRecords.size());
    return v;
}

const Scene& sceneOnTerrain(const Scene& scene, Scene& storage)
{
    bool any = false;
    for (const InstanceDesc& d : scene.instances) any = any || d.onTerrain;
    if (!any) return scene;
    storage = scene;
    const TerrainDesc& t = scene.terrain;
    for (size_t i = 0; i < storage.instances.size(); ++i) {
        InstanceDesc& d = storage.instances[i];
        if (!d.onTerrain) continue;
        if (!t.enabled() || !t.field) throw Error(std::string("render: instance ") + std::to_string(i) + " stands on the terrain, and the scene has none");
        const double h = surfaceHeight(*t.field, d.position.x - t.origin.x, d.position.z - t.origin.z);
        if (std::isnan(h))
            throw Error(std::string("render: instance ") + std::to_string(i) + " at x " + std::to_string(d.position.x) + ", z " + std::to_string(d.position.z) +
                        " stands off the terrain");
        d.position.y += t.origin.y + h;
        d.onTerrain = false;
    }
    return storage;
}

void placeLights(RenderScene& rs, const FrameSun& sun)
{
    rs.lights.clear();
    LightRecord l{};
    l.kind = LightKind::Distant;   // first: the light the LB grids are solved toward (lbLight)
    l.direction = sun.direction;
    l.radiance = sun.radiance;
    rs.lights.push_back(l);
    l = LightRecord{};
    l.kind = LightKind::Sky;
    rs.lights.push_back(l);
}

std::vector<float> skySamplingDistribution(const sky::SkyView& sky)
{
    const uint32_t R = kSkySamplingRows, C = kSkySamplingCols;
    std::vector<double> w(size_t(R) * C);
    double total = 0.0;
    for (uint32_t r = 0; r < R; ++r)
        for (uint32_t c = 0; c < C; ++c) {
            double sum = 0.0;   // the luminance at 3 x 3 points of the cell
            for (int j = 0; j < 3; ++j)
                for (int i = 0; i < 3; ++i) {
                    const float y = 1.0f - 2.0f * (float(r) + (float(j) + 0.5f) / 3.0f) / float(R);
                    const float phi = 2.0f * sky::kPi * (float(c) + (float(i) + 0.5f) / 3.0f) / float(C);
                    const float s = std::sqrt(std::max(0.0f, 1.0f - y * y));
                    const glm::vec3 L = sky::skyRadiance(sky, glm::vec3(s * std::cos(phi), y, s * std::sin(phi)));
                    sum += 0.2126 * double(L.x) + 0.7152 * double(L.y) + 0.0722 * double(L.z);
                }
            w[size_t(r) * C + c] = std::max(0.0, sum / 9.0);
            total += w[size_t(r) * C + c];
        }
    // A floor of 1% of the mean: every direction keeps some density (the cells' points may miss a bright speck).
    const double floor = total > 0.0 ? 0.01 * total / double(R * C) : 1.0;
    std::vector<float> out(size_t(R + 1) + size_t(R) * (C + 1));
    float* rows = out.data();
    std::vector<double> rowSum(R, 0.0);
    for (uint32_t r = 0; r < R; ++r) {
        float* cdf = out.data() + (R + 1) + size_t(r) * (C + 1);
        double acc = 0.0;
        for (uint32_t c = 0; c < C; ++c) acc += w[size_t(r) * C + c] + floor;
        rowSum[r] = acc;
        double run = 0.0;
        cdf[0] = 0.0f;
        for (uint32_t c = 0; c < C; ++c) {
            run += w[size_t(r) * C + c] + floor;
            cdf[c + 1] = float(run / acc);
        }
        cdf[C] = 1.0f;
    }
    double all = 0.0;
    for (double x : rowSum) all += x;
    double run = 0.0;
    rows[0] = 0.0f;
    for (uint32_t r = 0; r < R; ++r) {
        run += rowSum[r];
        rows[r + 1] = float(run / all);
    }
    rows[R] = 1.0f;
    return out;
}

namespace {

// The sky's sampling distribution for the frame: above the horizon only where the ground plane hides the rest
// (every point the paths reach lies on or above it, so no direction below the horizon sees the sky); the rows
// below get no probability and the rest is scaled up to sum to 1.
std::vector<float> frameSkySampling(const sky::SkyView& sky, bool groundPlane)
{
    std::vector<float> d = skySamplingDistribution(sky);
    if (!groundPlane) return d;
    const uint32_t R = kSkySamplingRows, upper = R / 2;   // rows 0 .. R/2 - 1 cover y in (0, 1]
    const float above = d[upper];
    if (!(above > 0.0f)) return d;
    for (uint32_t r = 0; r <= R; ++r) d[r] = r <= upper ? d[r] / above : 1.0f;
    return d;
}

} // namespace

void setFrameSky(RenderScene& rs, const SkyDesc& d, bool groundPlane)
{
    rs.frame.sky.model = sky::SkyView{};
    rs.frame.sky.lightCount = 0;
    rs.frame.sky.interleave = sky::Interleave{};
    rs.skyMap.clear();
    rs.skyLights.clear();
    rs.skySampling.clear();
    rs.frame.sky.samplingRows = 0;
    if (!d.analytic()) {
        // The constant sky: uniform, over the upper hemisphere where the ground plane hides the rest.
        if (groundPlane) {
            sky::SkyView flat{};
            flat.constant = glm::vec3(1.0f);
            rs.skySampling = frameSkySampling(flat, true);
            rs.frame.sky.samplingRows = kSkySamplingRows;
        }
        return;
    }
    if (!d.built) throw Error("render: the scene's sky was not built (loadSceneSky)");
    if (d.lights < sky::kMinVirtualLights || d.lights > sky::kMaxVirtualLights)
        throw Error("render: sky.lights must be " + std::to_string(sky::kMinVirtualLights) + " .. " + std::to_string(sky::kMaxVirtualLights));
    if (d.interleave < 1) throw Error("render: sky.interleave must be >= 1");
    const sky::Sky& built = *d.built;
    sky::SkyView v = built.view();
    v.map.levels = 1;
    if (built.kind == sky::SkyKind::Map && built.map) rs.skyMap = sky::envMapMipChain(*built.map, v.map.levels);
    v.map.rgb = nullptr;   // the frame's skyMap array (host or device: the map and its coarser levels) is read instead
    rs.frame.sky.model = v;
    rs.skyLights = sky::skyLights(built, d.lights, 512, groundPlane);
    rs.frame.sky.lightCount = uint32_t(rs.skyLights.size());
    rs.frame.sky.interleave = sky::makeInterleave(d.interleave, int(rs.skyLights.size()));
    rs.skySampling = frameSkySampling(built.view(), groundPlane);
    rs.frame.sky.samplingRows = kSkySamplingRows;
}

namespace {

// Throws Error on integrator settings the frame cannot take (checked at the build and again at each placement).
void checkIntegrator(const Scene& scene)
{
    if (scene.render.integrator == Integrator::Path && !scene.volumes.empty())
        throw Error("render: the path tracer does not trace volumes yet (render.integrator lb renders them)");
    if (scene.render.maxBounces < 0 || scene.render.maxBounces > kMaxPathBounces)
        throw Error("render: max_bounces must be 0 .. " + std::to_string(kMaxPathBounces));
    if (scene.lighting.bounces < 0 || scene.lighting.bounces > kMaxPathBounces)
        throw Error("lighting: bounces must be 0 .. " + std::to_string(kMaxPathBounces));
}

// Throws Error on input the build cannot take; returns the order groups are built in (each after those it places).
std::vector<uint32_t> checkSceneInput(const Scene& scene, const std::vector<SpeciesAssets>& assets)
{
    if (assets.size() != scene.species.size()) throw Error("render: one set of assets per species is required");
    checkIntegrator(scene);
    if (scene.terrain.enabled() && !scene.terrain.field)
        throw Error("render: the terrain's heights were not loaded (" + scene.terrain.dem + ")");
    for (size_t s = 0; s < assets.size(); ++s)
        if (assets[s].mesh.triangles.empty()) throw Error("render: species '" + scene.species[s].name + "' has no triangles");
    for (size_t i = 0; i < scene.instances.size(); ++i) checkReference(scene, scene.instances[i], "instance " + std::to_string(i));
    return groupBuildOrder(scene);
}

} // namespace

// The table of contents: each kind's builder (core/render/surfaces/*_build.cpp), then the sky. The LB solves
// the frame triggers are the pipeline's (pipeline/render/frame_build.h lightFrame).
RenderScene buildSceneGeometry(const Scene& sceneIn, const std::vector<SpeciesAssets>& assets, LodLevels lod, Progress* progress)
{
    Scene lifted;
    const Scene& scene = sceneOnTerrain(sceneIn, lifted);
    const std::vector<uint32_t> groupOrder = checkSceneInput(scene, assets);
    RenderScene rs;
    rs.accel = scene.render.accel;
    rs.lodLevels = lod;
    rs.forestSpecies.clear();
    for (const SpeciesAssets& a : assets) rs.forestSpecies.push_back(a.forest);

    buildTerrainArrays(rs, scene);
    buildMeshGeometry(rs, scene, assets, lod, progress);
    buildGroupGeometry(rs, scene, groupOrder);
    buildLandscapeArrays(rs, scene);   // and its share of the forest grid
    buildVolumeGrids(rs, scene);
    setFrameSky(rs, scene.skyModel, groundPlaneShown(scene));
    countFrameBytes(rs);
    return rs;
}



void rebuildVolumeGrids(RenderScene& rs, const Scene& scene)
{
    buildVolumeGrids(rs, scene);
    countFrameBytes(rs);
}

bool hasLevelsFor(const RenderScene& rs, const Scene& sceneIn)
{
    if (!(sceneIn.render.pruneDistance > 0.0)) return true;
    Scene lifted;
    const Scene& scene = sceneOnTerrain(sceneIn, lifted);
    if (rs.meshLevels.size() != scene.species.size()) return false;
    for (const RenderScene::MeshLevels& m : rs.meshLevels)
        if (m.levels == 0) return false;   // built without pruning: the levels were never made
    const std::vector<int> level = instanceLevels(scene, rs.meshLevels);
    for (size_t i = 0; i < level.size(); ++i) {
        const InstanceDesc& d = scene.instances[i];
        if (d.group == kNoGroup && rs.meshLevels[d.species].geometry[size_t(level[i])] == kNoHit) return false;
    }
    return true;
}

void placeTopLevel(RenderScene& rs, const Scene& sceneIn, const glm::vec3& sunRadiance, int width, int height, int spp)
{
    Scene lifted;
    const Scene& scene = sceneOnTerrain(sceneIn, lifted);
    const size_t ni = scene.instances.size();
    if (scene.terrain.enabled() != !rs.terrainHeights.empty())
        throw Error("render: the scene's terrain differs from the one the frame was built with");
    if (rs.meshLevels.size() != scene.species.size() || rs.groupGeometry.size() != scene.groups.size())
        throw Error("render: the scene's species or groups differ from the ones the frame was built with");
    for (size_t i = 0; i < ni; ++i) checkReference(scene, scene.instances[i], "instance " + std::to_string(i));
    if (!hasLevelsFor(rs, scene)) throw Error("render: the frame was built without the levels of detail this camera needs");
    checkIntegrator(scene);
    const glm::dvec3 origin = scene.camera.position;
    const std::vector<int> level = instanceLevels(scene, rs.meshLevels);

    AccelStats& st = rs.buildStats;
    st.instancedTriangles = 0.0;
    std::fill(std::begin(st.instancesPerLevel), std::end(st.instancesPerLevel), size_t(0));
    rs.instances.clear();
    rs.instances.reserve(ni);
    std::vector<Bounds3> boxes(ni);
    for (size_t i = 0; i < ni; ++i) {
        const InstanceDesc& d = scene.instances[i];
        InstanceRecord rec = makeInstance(d, origin);
        rec.geometry = d.group != kNoGroup ? rs.groupGeometry[d.group] : rs.meshLevels[d.species].geometry[size_t(level[i])];
        // The forest grid's record (built for these instances: a scene with more or fewer takes none).
        if (d.group == kNoGroup && rs.instanceLights.size() == ni) rec.light = uint32_t(i + 1);
        rs.instances.push_back(rec);
        boxes[i] = instanceBox(d, rs.geometryBounds[rec.geometry], origin);
        st.instancedTriangles += rs.geometryTriangles[rec.geometry];
        if (d.group == kNoGroup) ++st.instancesPerLevel[size_t(level[i])];
    }
    rs.tlasNodes.clear();
    rs.tlasWideNodes.clear();
    rs.tlasOrder.clear();
    st.tlasDepth = st.wideTlasDepth = 0;
    if (ni > 0) {
        BvhBuildSettings ts;
        ts.maxLeafSize = 2;
        ts.wide = true;   // the host's 8-wide copy
        Bvh tlas = buildBvh(boxes, ts);
        rs.tlasNodes = std::move(tlas.nodes);
        rs.tlasWideNodes = std::move(tlas.wideNodes);
        rs.tlasOrder = std::move(tlas.primOrder);
        st.tlasDepth = tlas.depth;
        st.wideTlasDepth = tlas.wideDepth;
    }
    st.instances = ni;

    // Environment, camera, settings.
    RenderView& b = rs.frame;
    const TerrainDesc& t = scene.terrain;
    b.ground.enabled = groundPlaneShown(scene);   // a terrain is the ground
    b.ground.y = float(scene.ground.height - origin.y);
    b.ground.color = scene.ground.color;
    b.terrain.enabled = t.enabled();
    if (t.enabled()) {
        b.terrain.origin = glm::vec3(t.origin - origin);   // camera-relative, in double first
        b.terrain.rock = t.rock;
        b.terrain.snow = t.snow;
        b.terrain.rockCos = terrainRockCos(t);
        b.terrain.snowY = terrainSnowY(t);
        // The height field's and the landscape's frames are rebased under the camera, in double (Dietrich et
        // al. 2006 at UTM coordinates: millions of metres from the world origin, centimetres near the camera).
        const HeightFieldLayout& L = rs.frame.terrain.layout;
        const glm::dvec3 camLocal = origin - t.origin;   // the camera in the DEM's frame
        const auto nearest = [](double x, double step, uint32_t n) { return int32_t(std::clamp(std::floor(x / step), 0.0, double(n))); };
        b.terrain.baseI = nearest(camLocal.x, double(L.dx), L.nx - 1);
        b.terrain.baseJ = nearest(camLocal.z, double(L.dz), L.nz - 1);
        b.terrain.base = glm::vec3(t.origin + glm::dvec3(double(b.terrain.baseI) * double(L.dx), 0.0, double(b.terrain.baseJ) * double(L.dz)) - origin);
        b.landscape.enabled = !rs.landCells.empty();
        if (b.landscape.enabled) {
            const double C = double(b.landscape.layout.cellSize);
            b.landscape.baseCell = glm::ivec2(nearest(camLocal.x, C, b.landscape.layout.cellsX), nearest(camLocal.z, C, b.landscape.layout.cellsZ));
            b.landscape.base = glm::vec3(t.origin + glm::dvec3(double(b.landscape.baseCell.x) * C, 0.0, double(b.landscape.baseCell.y) * C) - origin);
        }
    }
    const FrameSun sun = frameSun(scene, sunRadiance);
    placeLights(rs, sun);
    b.lbRadiance = lbRadiance(scene, sun);
    b.sky.constant = composeSky(scene);
    b.camera = makeCamera(scene.camera, width, height);
    b.width = width;
    b.height = height;
    b.spp = spp;
    b.accel = rs.accel;
    b.shadows = scene.render.shadows;
    b.indirectScale = scene.render.indirectScale;
    b.alphaDistance = scene.render.alphaDistance;
    b.integrator = scene.render.integrator;
    b.maxBounces = scene.render.maxBounces;
    b.lightingBounces = scene.lighting.bounces;
    const int bounceSamples = scene.render.bounceSamples;
    b.bounceStride = bounceSamples > 0 && bounceSamples < spp ? spp / bounceSamples : 1;
    b.atmosphere = scene.skyModel.aerialPerspective ? makeAtmosphere(scene.skyModel.turbidity, origin.y) : AtmosphereRecord{};
    placeVolumes(rs, scene, scene.camera.position);
    countFrameBytes(rs);
}

FrameSun frameSun(const Scene& scene, const glm::vec3& sunRadiance)
{
    const glm::vec3 sd = scene.sun.direction;
    if (!(glm::length(sd) > 0.0f)) throw Error("sun: direction must not be zero");
    FrameSun out{glm::normalize(sd), sunRadiance};
    const SkyDesc& skyDesc = scene.skyModel;
    if (skyDesc.analytic() && skyDesc.built && (skyDesc.kind == sky::SkyKind::Preetham || (skyDesc.kind == sky::SkyKind::Map && skyDesc.sunFromMap))) {
        // The sky's own sun replaces the scene's (scaled by sun.intensity). Its radiance() is the irradiance
        // facing it; the renderer's sun shows albedo x sunRadiance x cos, so the irradiance / pi (the same
        // Lambertian surface the virtual lights light with albedo / pi x their power).
        const sky::SkySun& sun = skyDesc.built->sun;
        if (sun.present) out.direction = glm::normalize(sun.direction);
        out.radiance = sun.present ? sun.radiance() * (scene.sun.intensity / sky::kPi) : glm::vec3(0.0f);
    }
    return out;
}

glm::vec3 lbSunDirection(const Scene& scene)
{
    const SkyDesc& d = scene.skyModel;
    if (d.kind == sky::SkyKind::Map && d.sunFromMap && d.built && d.built->sun.present) return d.built->sun.direction;
    return scene.sun.direction;
}

glm::vec3 lbRadiance(const Scene& scene, const FrameSun& sun)
{
    if (scene.lighting.boundary == LbBoundary::Sun) return sun.radiance;
    glm::vec3 u = sun.radiance;
    for (int c = 0; c < 3; ++c)
        if (!(u[c] > 0.0f)) u[c] = 1.0f;
    return u;
}

} // namespace sylva
