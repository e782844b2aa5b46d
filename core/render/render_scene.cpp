// Flattens species, pruned levels, instance groups, textures and lighting grids into the RenderView arrays;
// builds every level's acceleration structure. The one builder of the levels, for every front end.
#include "core/render/render_scene.h"
#include "core/render/render_volumes.h"

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

// The parent-frame box of an instance of a geometry whose own-frame bounds are `b`, from the instance's
// description in double, grown by a relative epsilon so float rounding of the transform never clips geometry.
Bounds3 instanceBox(const InstanceDesc& d, const Bounds3& b, const glm::dvec3& frameOrigin)
{
    Bounds3 box;
    const glm::dmat3 r = rotationDeg(d.rotationDeg) * double(d.scale);
    for (int c = 0; c < 8; ++c) {
        const glm::dvec3 corner((c & 1) ? b.hi.x : b.lo.x, (c & 2) ? b.hi.y : b.lo.y, (c & 4) ? b.hi.z : b.lo.z);
        box.extend(glm::vec3(r * corner + (d.position - frameOrigin)));
    }
    const glm::vec3 pad = 1e-5f * (glm::abs(box.lo) + glm::abs(box.hi)) + 1e-6f;
    box.lo -= pad;
    box.hi += pad;
    return box;
}

// The level of detail of each of the scene's own instances from the distance of its species' box centre
// to the camera (instances of groups, and every instance when pruning is off: level 0).
std::vector<int> instanceLevels(const Scene& scene, const std::vector<RenderScene::MeshLevels>& ml)
{
    std::vector<int> level(scene.instances.size(), 0);
    const double start = scene.render.pruneDistance;
    if (!(start > 0.0)) return level;
    for (size_t i = 0; i < level.size(); ++i) {
        const InstanceDesc& d = scene.instances[i];
        if (d.group != kNoGroup || d.species >= ml.size()) continue;
        const glm::dvec3 c = rotationDeg(d.rotationDeg) * (double(d.scale) * ml[d.species].centre) + d.position;
        level[i] = pruneLevelFor(glm::length(c - scene.camera.position), start, ml[d.species].levels);
    }
    return level;
}

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

// The byte figures of AccelStats from the array table: each array counts towards its stat column.
void countBytes(RenderScene& rs)
{
    size_t bytes[size_t(ArrayStat::None) + 1] = {};
#define SYLVA_X(part, where, T, name, stat) bytes[size_t(ArrayStat::stat)] += rs.name.size() * sizeof(T);
    SYLVA_RENDER_ARRAYS(SYLVA_X)
#undef SYLVA_X
    AccelStats& st = rs.m_stats;
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

void addCutout(const ImageRgba& img, RenderScene& rs, MaterialRecord& m)
{
    if (img.empty()) return;
    bool anyClear = false;
    for (size_t p = 0; p < size_t(img.width) * size_t(img.height) && !anyClear; ++p) anyClear = img.pixels[p * 4 + 3] < 0.5f;
    if (!anyClear) return;
    AlphaMaskRecord rec{img.width, img.height, uint32_t(rs.alphaBits.size()), 0};
    const size_t bits = size_t(img.width) * size_t(img.height);
    rs.alphaBits.resize(rs.alphaBits.size() + (bits + 31) / 32, 0u);
    for (size_t b = 0; b < bits; ++b)
        if (img.pixels[b * 4 + 3] >= 0.5f) rs.alphaBits[rec.offset + b / 32] |= 1u << (b % 32);
    m.alphaMask = int32_t(rs.alphaMasks.size());
    rs.alphaMasks.push_back(rec);
}

void addTexture(const ImageRgba& img, RenderScene& rs, MaterialRecord& m)
{
    if (img.empty()) return;
    TextureRecord rec{img.width, img.height, uint32_t(rs.texels.size()), 0};
    const size_t n = size_t(img.width) * size_t(img.height);
    rs.texels.reserve(rs.texels.size() + n);
    for (size_t p = 0; p < n; ++p) {
        const float* px = &img.pixels[p * 4];
        rs.texels.emplace_back(srgbDecode(px[0]), srgbDecode(px[1]), srgbDecode(px[2]), px[3]);
    }
    m.texture = int32_t(rs.textures.size());
    rs.textures.push_back(rec);
}

} // namespace

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
    RenderView v = base;
#define SYLVA_X(part, where, T, name, stat) v.name = name.empty() ? nullptr : name.data();
    SYLVA_RENDER_ARRAYS(SYLVA_X)
#undef SYLVA_X
    v.instanceCount = uint32_t(instances.size());
    v.volumeCount = uint32_t(volumeInstances.size());
    v.lightCount = uint32_t(lights.size());
    v.spheres.count = uint32_t(sphereRecords.size());
    return v;
}

namespace {

// `scene` with its on-terrain instances standing on the terrain (world y = the surface's height at their
// x, z + their y): `storage` holds that copy, or `scene` itself is returned when no instance stands on
// the terrain. Throws Error naming an on-terrain instance without a terrain or off its footprint.
const Scene& onTerrain(const Scene& scene, Scene& storage)
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

} // namespace

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

void setFrameSky(RenderScene& rs, const SkyDesc& d, bool groundPlane)
{
    rs.base.sky.model = sky::SkyView{};
    rs.base.sky.lightCount = 0;
    rs.base.sky.interleave = sky::Interleave{};
    rs.skyMap.clear();
    rs.skyLights.clear();
    if (!d.analytic()) return;
    if (!d.built) throw Error("render: the scene's sky was not built (loadSceneSky)");
    if (d.lights < sky::kMinVirtualLights || d.lights > sky::kMaxVirtualLights)
        throw Error("render: sky.lights must be " + std::to_string(sky::kMinVirtualLights) + " .. " + std::to_string(sky::kMaxVirtualLights));
    if (d.interleave < 1) throw Error("render: sky.interleave must be >= 1");
    const sky::Sky& built = *d.built;
    sky::SkyView v = built.view();
    if (built.kind == sky::SkyKind::Map && built.map) rs.skyMap = built.map->rgb;
    v.map.rgb = nullptr;   // the frame's skyMap array (host or device) is read instead
    rs.base.sky.model = v;
    rs.skyLights = sky::skyLights(built, d.lights, 512, groundPlane);
    rs.base.sky.lightCount = uint32_t(rs.skyLights.size());
    rs.base.sky.interleave = sky::makeInterleave(d.interleave, int(rs.skyLights.size()));
}

namespace {

// The first species with a density grid (its optics light the forest grid), -1 when none has one.
int forestOptics(const std::vector<lb::ForestSpecies>& species)
{
    for (size_t s = 0; s < species.size(); ++s)
        if (species[s].biomass > 0.0) return int(s);
    return -1;
}

// The forest grid's optics and sun: species `optics`' LB settings with the scene's sun.
lb::LbParams forestGridParams(const Scene& scene, int optics)
{
    lb::LbParams p = scene.species[size_t(optics)].lighting;
    p.sun = scene.sun.direction;
    return p;
}

// The terrain-frame height above which the ground is snow (> any height: none), and the cosine below which
// a normal is rock: the shader's colour rule and the landscape's masks (RenderView::terrainSnowY, terrainRockCos).
float terrainSnowY(const TerrainDesc& t) { return t.snowLine > 0.0f ? float(double(t.snowLine) - t.origin.y) : 3.0e38f; }
float terrainRockCos(const TerrainDesc& t) { return float(std::cos(double(t.rockSlope) * 3.14159265358979323846 / 180.0)); }

// The forest grid's share over the landscape's plants (core/terrain/landscape_light.h): the lattice of which
// plants grow now, applied unless off or (auto) exposure is uniform over the cells with plants.
void buildLandscapeLight(RenderScene& rs, const Scene& scene)
{
    LandscapeLightStats& st = rs.m_stats.landscapeLight;
    st = LandscapeLightStats{};
    rs.landLight.clear();
    rs.base.landscape.lightLayout = LandLightLayout{};
    const ForestGridMode mode = scene.lighting.forestGrid;
    if (mode == ForestGridMode::Off || rs.landCells.empty()) return;
    const int optics = forestOptics(rs.forestSpecies);
    if (optics < 0) {
        st.skipped = mode == ForestGridMode::Auto;
        return;
    }
    const TerrainDesc& t = scene.terrain;
    LandscapeLightSettings settings;
    settings.resolution = scene.lighting.forestGridResolution;
    LandscapeLight l = solveLandscapeLight(*t.field, rs.base.landscape.layout, rs.landCells, rs.tileRecords, rs.tilePlants, terrainSnowY(t), terrainRockCos(t),
                                           rs.forestSpecies, forestGridParams(scene, optics), settings);
    st.solved = l.cellsWithPlants > 0;
    st.resolution = l.resolution;
    st.dims = l.geometry.dims;
    st.spacing = l.geometry.spacing;
    st.seconds = l.seconds;
    st.plantsTested = l.plantsTested;
    st.plantsGrowing = l.plantsGrowing;
    st.stride = l.stride;
    st.cells = l.cellsWithPlants;
    st.minFactor = l.minFactor;
    st.medianFactor = l.medianFactor;
    st.maxFactor = l.maxFactor;
    st.spread = l.spread;
    st.skipped = mode == ForestGridMode::Auto && (!st.solved || l.uniform);
    st.applied = st.solved && !st.skipped;
    if (!st.applied) return;
    rs.landLight = std::move(l.nodes);
    rs.base.landscape.lightLayout = l.layout;
}

// The forest-level LB grid (core/lb/forest_grid.h) over the scene's top-level instances of species with a
// density grid, with the scene's sun and the first such species' optics; its factors become instanceLights
// (one record per scene instance, factor 1 for those outside it). Auto applies them only where exposure
// differs: factors and face factors spread by at least uniformSpread (2%).
void buildForestGrid(RenderScene& rs, const Scene& scene)
{
    ForestGridStats& st = rs.m_stats.forestGrid;
    const ForestGridMode mode = scene.lighting.forestGrid;
    st = ForestGridStats{};
    st.mode = forestGridModeName(mode);
    st.resolution = scene.lighting.forestGridResolution;
    rs.instanceLights.clear();
    if (mode == ForestGridMode::Off) return;
    const std::vector<lb::ForestSpecies>& species = rs.forestSpecies;
    const int optics = forestOptics(species);
    std::vector<lb::ForestPlant> plants;
    std::vector<size_t> which;   // plant -> scene instance
    for (size_t i = 0; i < scene.instances.size(); ++i) {
        const InstanceDesc& d = scene.instances[i];
        if (d.group != kNoGroup || !(species[d.species].biomass > 0.0)) continue;
        plants.push_back({d.position, d.scale, int(d.species)});
        which.push_back(i);
    }
    st.plants = plants.size();
    if (plants.empty()) {
        st.skipped = mode == ForestGridMode::Auto;
        return;
    }
    const lb::LbParams p = forestGridParams(scene, optics);
    lb::ForestGridSettings settings;
    settings.resolution = scene.lighting.forestGridResolution;
    const lb::ForestGridResult r = lb::solveForestGrid(plants, species, p, settings);
    st.solved = true;
    st.resolution = r.resolution;
    st.dims = r.geometry.dims;
    st.spacing = r.geometry.spacing;
    st.seconds = r.seconds;
    st.minFactor = r.minFactor;
    st.medianFactor = r.medianFactor;
    st.maxFactor = r.maxFactor;
    st.minFaceFactor = r.minFaceFactor;
    st.maxFaceFactor = r.maxFaceFactor;
    const float most = std::max(r.maxFactor, r.maxFaceFactor);
    st.spread = most > 0.0f ? (most - std::min(r.minFactor, r.minFaceFactor)) / most : 0.0f;
    st.skipped = mode == ForestGridMode::Auto && r.uniform;
    st.applied = !st.skipped;
    if (!st.applied) return;
    rs.instanceLights.assign(scene.instances.size(), InstanceLightRecord{});
    for (InstanceLightRecord& rec : rs.instanceLights) {   // outside the grid: factor 1
        rec.factor = glm::vec4(1.0f);
        for (glm::vec4& f : rec.face) f = glm::vec4(1.0f);
    }
    for (size_t k = 0; k < plants.size(); ++k) {
        const lb::ForestSpecies& sp = species[size_t(plants[k].species)];
        InstanceLightRecord& rec = rs.instanceLights[which[k]];
        rec.centre = glm::vec3(0.5 * (sp.boxMin + sp.boxMax));
        const glm::dvec3 e = sp.boxMax - sp.boxMin;
        rec.invRadius = float(2.0 / std::max({e.x, e.y, e.z, 1e-9}));
        rec.factor = glm::vec4(r.factors[k], 1.0f);
        for (int f = 0; f < lb::kFaces; ++f) rec.face[f] = glm::vec4(r.faceFactors[k][size_t(f)], 1.0f);
    }
}

} // namespace

RenderScene buildSceneGeometry(const Scene& sceneIn, const std::vector<SpeciesAssets>& assets, LodLevels lod, Progress* progress)
{
    Scene lifted;
    const Scene& scene = onTerrain(sceneIn, lifted);
    if (assets.size() != scene.species.size()) throw Error("render: one set of assets per species is required");
    if (scene.instances.empty() && !scene.terrain.enabled()) throw Error("render: the scene has no instances and no terrain");
    if (scene.terrain.enabled() && !scene.terrain.field)
        throw Error("render: the terrain's heights were not loaded (" + scene.terrain.dem + ")");
    RenderScene rs;
    if (scene.terrain.enabled()) {
        const HeightField& hf = *scene.terrain.field;
        rs.terrainHeights = hf.heights;
        rs.terrainRanges = hf.ranges;
        rs.base.terrain.layout = hf.layout;
        rs.m_stats.terrainSamplesX = hf.layout.nx;
        rs.m_stats.terrainSamplesZ = hf.layout.nz;
    }
    setFrameSky(rs, scene.skyModel, groundPlaneShown(scene));
    rs.accel = scene.render.accel;
    rs.lodLevels = lod;
    const size_t ns = assets.size(), ni = scene.instances.size();
    for (size_t s = 0; s < ns; ++s)
        if (assets[s].mesh.triangles.empty()) throw Error("render: species '" + scene.species[s].name + "' has no triangles");
    for (size_t i = 0; i < ni; ++i) checkReference(scene, scene.instances[i], "instance " + std::to_string(i));
    const std::vector<uint32_t> groupOrder = groupBuildOrder(scene);

    // Stochastic pruning: the levels each species supports (only analysed when the scene prunes).
    const bool prune = scene.render.pruneDistance > 0.0;
    rs.meshLevels.resize(ns);
    std::vector<LeafElements> leaves(prune ? ns : 0);
    std::vector<std::vector<uint32_t>> orders(leaves.size());
    for (RenderScene::MeshLevels& m : rs.meshLevels) std::fill(std::begin(m.geometry), std::end(m.geometry), kNoHit);
    if (prune) {
        tbb::parallel_for(size_t(0), ns, [&](size_t s) {
            leaves[s] = findLeafElements(assets[s].mesh);
            orders[s] = pruneOrder(leaves[s].count());
            rs.meshLevels[s].levels = pruneLevelCount(leaves[s]);
            rs.meshLevels[s].centre = glm::dvec3(meshBounds(assets[s].mesh).center());
        });
    } else {
        for (RenderScene::MeshLevels& m : rs.meshLevels) m.levels = 0;   // not analysed: only level 0 exists
    }

    // Mesh records: the species (0 .. ns-1), then the pruned levels (in order of first use by an instance,
    // or every level of every species for LodLevels::All).
    struct MeshBuild {
        uint32_t species;
        int level;
        PrunedLevel pruned;   // level > 0
        Bvh bvh;
        size_t triangles = 0;
    };
    std::vector<MeshBuild> meshes(ns);
    for (size_t s = 0; s < ns; ++s) {
        meshes[s].species = uint32_t(s);
        meshes[s].level = 0;
        rs.meshLevels[s].geometry[0] = uint32_t(s);
    }
    auto useLevel = [&](uint32_t sp, int level) {
        uint32_t& g = rs.meshLevels[sp].geometry[size_t(level)];
        if (g != kNoHit) return;
        g = uint32_t(meshes.size());
        meshes.push_back(MeshBuild{sp, level, {}, {}, 0});
    };
    if (prune && lod == LodLevels::All) {
        for (uint32_t sp = 0; sp < ns; ++sp)
            for (int l = 1; l < rs.meshLevels[sp].levels; ++l) useLevel(sp, l);
    } else if (prune) {
        const std::vector<int> level = instanceLevels(scene, rs.meshLevels);
        for (size_t i = 0; i < ni; ++i)
            if (scene.instances[i].group == kNoGroup) useLevel(scene.instances[i].species, level[i]);
    }

    // Bottom level: one BVH per mesh record, built in parallel.
    tbb::parallel_for(size_t(0), meshes.size(), [&](size_t g) {
        MeshBuild& geo = meshes[g];
        const TriangleMesh& m = assets[geo.species].mesh;
        std::vector<Bounds3> boxes;
        if (geo.level == 0) {
            boxes.resize(m.triangles.size());
            for (size_t t = 0; t < boxes.size(); ++t)
                for (int c = 0; c < 3; ++c) boxes[t].extend(m.positions[m.triangles[t][c]]);
        } else {
            geo.pruned = buildPrunedLevel(m, leaves[geo.species], orders[geo.species], geo.level);
            boxes.resize(geo.pruned.tris.size());
            for (size_t t = 0; t < boxes.size(); ++t)
                for (int c = 0; c < 3; ++c) boxes[t].extend(geo.pruned.corners[3 * t + size_t(c)]);
        }
        geo.triangles = boxes.size();
        BvhBuildSettings bs;
        bs.maxLeafSize = 4;
        bs.leafBlock = 4;   // leaves are tested as one 4-wide block
        bs.wide = scene.render.accel == AccelKind::Bvh;   // the host traverses 8-wide nodes
        geo.bvh = buildBvh(boxes, bs);
    });
    if (progress) progress->report(0.7, "species BVHs built");
    // A triangle's corner uvs for TriBlock::uv: each axis shifted by the whole units below its smallest
    // corner (the cut-out wraps, so the test sees the same texels), rounded to 1/kBlockUvScale. False
    // when a corner lies 4 units or more above that (no room in 16 bits) or is not finite.
    auto packBlockUv = [](const glm::uvec3& corners, const std::vector<glm::vec2>& uvs, uint16_t (&out)[6]) {
        for (int axis = 0; axis < 2; ++axis) {
            float lo = uvs[corners[0]][axis];
            for (int c = 1; c < 3; ++c) lo = std::min(lo, uvs[corners[c]][axis]);
            if (!std::isfinite(lo)) return false;
            const double base = std::floor(double(lo));
            for (int c = 0; c < 3; ++c) {
                const double q = std::round((double(uvs[corners[c]][axis]) - base) * double(kBlockUvScale));
                if (!(q >= 0.0 && q <= 65535.0)) return false;
                out[2 * c + axis] = uint16_t(q);
            }
        }
        return true;
    };

    // Triangles of a geometry record in BVH order, then its leaves as 4-wide blocks. corner(prim, c)
    // is the species-frame position of corner c of BVH primitive prim, meshTri(prim) its mesh triangle.
    std::vector<uint32_t> triBase(ns);
    auto appendTriangles = [&rs, &packBlockUv](GeometryRecord& sr, const Bvh& bvh, uint32_t base, auto corner, auto meshTri) {
        sr.nodeOffset = uint32_t(rs.blasNodes.size());
        sr.triOffset = uint32_t(rs.tris.size());
        rs.blasNodes.insert(rs.blasNodes.end(), bvh.nodes.begin(), bvh.nodes.end());
        for (uint32_t prim : bvh.primOrder) {
            const glm::vec3 v0 = corner(prim, 0);
            TriAccel ta{};
            ta.v0 = v0;
            ta.e1 = corner(prim, 1) - v0;
            ta.e2 = corner(prim, 2) - v0;
            ta.tri = base + meshTri(prim);
            const MaterialRecord& mr = rs.materials[rs.triMaterial[ta.tri]];
            ta.alpha = mr.alphaMask >= 0 ? uint32_t(mr.alphaMask) + 1u : 0u;
            rs.tris.push_back(ta);
        }
        // BVH leaves become 4-wide triangle blocks: leaf children then index blocks, not slots.
        sr.primOffset = uint32_t(rs.blocks.size());
        std::vector<uint32_t> blockOfSlot(bvh.wideNodes.empty() ? 0 : bvh.primOrder.size(), kNoHit);
        for (size_t ni2 = sr.nodeOffset; ni2 < rs.blasNodes.size(); ++ni2) {
            BvhNode& node = rs.blasNodes[ni2];
            for (int k = 0; k < 4; ++k) {
                if (node.count[k] == 0 || node.child[k] == kNoHit) continue;
                if (node.count[k] > 4) throw Error("render: a BVH leaf holds more than four triangles");
                TriBlock blk{};
                for (uint32_t l = 0; l < node.count[k]; ++l) {
                    const TriAccel& t = rs.tris[sr.triOffset + node.child[k] + l];
                    blk.v0x[l] = t.v0.x, blk.v0y[l] = t.v0.y, blk.v0z[l] = t.v0.z;
                    blk.e1x[l] = t.e1.x, blk.e1y[l] = t.e1.y, blk.e1z[l] = t.e1.z;
                    blk.e2x[l] = t.e2.x, blk.e2y[l] = t.e2.y, blk.e2z[l] = t.e2.z;
                    blk.tri[l] = t.tri;
                    blk.alpha[l] = t.alpha;
                    if (t.alpha != 0u && packBlockUv(rs.triVerts[t.tri], rs.uvs, blk.uv[l])) blk.uvPacked |= 1u << l;
                }
                if (!blockOfSlot.empty()) blockOfSlot[node.child[k]] = uint32_t(rs.blocks.size() - sr.primOffset);
                node.child[k] = uint32_t(rs.blocks.size() - sr.primOffset);
                rs.blocks.push_back(blk);
            }
        }
        // The 8-wide flattening has the same leaves: their children become the same blocks.
        sr.wideNodeOffset = uint32_t(rs.blasWideNodes.size());
        for (BvhNode8 node : bvh.wideNodes) {
            for (int k = 0; k < 8; ++k)
                if (node.count[k] > 0) node.child[k] = blockOfSlot.at(node.child[k]);
            rs.blasWideNodes.push_back(node);
        }
    };

    // Every array below at its final size before the first append: grown by doubling instead, they would copy
    // themselves into fresh memory several times (a page fault per page each time), most of the serial build.
    {
        size_t nodes = 0, tris = 0, blocks = 0, wide = 0, verts = 0, faces = 0, light = 0;
        for (const MeshBuild& geo : meshes) {
            nodes += geo.bvh.nodes.size();
            tris += geo.bvh.primOrder.size();
            wide += geo.bvh.wideNodes.size();
            for (const BvhNode& node : geo.bvh.nodes)
                for (int k = 0; k < 4; ++k) blocks += node.count[k] != 0 && node.child[k] != kNoHit ? 1 : 0;
        }
        for (const SpeciesAssets& a : assets) {
            verts += a.mesh.positions.size();
            faces += a.mesh.triangles.size();
            light += a.lighting.rgb.size();
        }
        rs.blasNodes.reserve(rs.blasNodes.size() + nodes);
        rs.tris.reserve(rs.tris.size() + tris);
        rs.blocks.reserve(rs.blocks.size() + blocks);
        rs.blasWideNodes.reserve(rs.blasWideNodes.size() + wide);
        rs.normals.reserve(rs.normals.size() + verts);
        rs.uvs.reserve(rs.uvs.size() + verts);
        rs.triVerts.reserve(rs.triVerts.size() + faces);
        rs.triMaterial.reserve(rs.triMaterial.size() + faces);
        rs.lighting.reserve(rs.lighting.size() + light);
    }
    for (size_t s = 0; s < ns; ++s) {
        const SpeciesAssets& a = assets[s];
        const TriangleMesh& m = a.mesh;
        const uint32_t vertBase = uint32_t(rs.normals.size());
        const uint32_t matBase = uint32_t(rs.materials.size());
        triBase[s] = uint32_t(rs.triVerts.size());

        // Shading arrays (normals: given, else from the faces).
        std::vector<glm::vec3> normals = m.normals;
        if (normals.size() != m.positions.size()) {
            normals.assign(m.positions.size(), glm::vec3(0.0f));
            for (const auto& t : m.triangles) {
                const glm::vec3 n = glm::cross(m.positions[t.y] - m.positions[t.x], m.positions[t.z] - m.positions[t.x]);
                for (int c = 0; c < 3; ++c) normals[t[c]] += n;
            }
        }
        for (glm::vec3& n : normals) {
            const float l = glm::length(n);
            n = l > 0.0f ? n / l : glm::vec3(0.0f, 1.0f, 0.0f);
        }
        rs.normals.insert(rs.normals.end(), normals.begin(), normals.end());
        if (m.uvs.size() == m.positions.size()) rs.uvs.insert(rs.uvs.end(), m.uvs.begin(), m.uvs.end());
        else rs.uvs.resize(rs.uvs.size() + m.positions.size(), glm::vec2(0.0f));
        for (const auto& t : m.triangles) rs.triVerts.push_back(t + glm::uvec3(vertBase));
        for (size_t t = 0; t < m.triangles.size(); ++t)
            rs.triMaterial.push_back(matBase + (m.triangleMaterial.empty() ? 0u : m.triangleMaterial[t]));

        // Materials, textures, cut-outs.
        const size_t nm = std::max<size_t>(1, m.materials.size());
        for (size_t i = 0; i < nm; ++i) {
            MaterialRecord r{};
            const Material def;
            const Material& mat = i < m.materials.size() ? m.materials[i] : def;
            r.diffuse = mat.diffuse;
            r.specular = mat.specular;
            r.shininess = mat.shininess;
            r.isLeaf = mat.isLeaf ? 1u : 0u;
            r.texture = -1;
            r.alphaMask = -1;
            if (i < a.diffuse.size()) addTexture(a.diffuse[i], rs, r);
            if (i < a.cutout.size()) addCutout(a.cutout[i], rs, r);
            rs.materials.push_back(r);
        }

        // Triangles in BVH order.
        GeometryRecord gr{};
        gr.kind = GeometryKind::Mesh;
        gr.species = uint32_t(s);
        appendTriangles(
            gr, meshes[s].bvh, triBase[s], [&m](uint32_t prim, int c) { return m.positions[m.triangles[prim][c]]; },
            [](uint32_t prim) { return prim; });
        rs.geometries.push_back(gr);
        SpeciesRecord sr{};
        sr.leafIndirect = glm::vec3(1.0f);
        sr.barkIndirect = 1.0f;
        sr.leafIndirectCap = std::numeric_limits<float>::max();   // the seed's sum: kd x L, uncapped (old pictures)

        // Lighting grid, normalized by the unobstructed photon density.
        const LightingGrid& g = a.lighting;
        if (!g.rgb.empty()) {
            if (g.rgb.size() != g.geometry.nodeCount() * 3) throw Error("render: lighting grid size does not match its dims");
            sr.gridOrigin = glm::vec3(g.geometry.origin);
            sr.gridInvSpacing = float(1.0 / g.geometry.spacing);
            sr.gridDims = g.geometry.dims;
            sr.gridOffset = uint32_t(rs.lighting.size());
            for (size_t i = 0; i < g.rgb.size(); ++i) {
                const float norm = a.lightingNorm[int(i % 3)];
                rs.lighting.push_back(norm > 0.0f ? g.rgb[i] / norm : 0.0f);
            }
            if (scene.lighting.direct == DirectLight::Once && s < scene.species.size()) {
                // The grid holds scattered light only: each face gets a quarter of its fluence (leaf_optics.h).
                const lb::ScatteredWeights w = lb::scatteredWeights(scene.species[s].lighting);
                sr.leafIndirect = w.leaf;
                sr.barkIndirect = w.bark;
                sr.leafIndirectCap = w.leafCap;
            }
        }
        rs.species.push_back(sr);
        rs.m_stats.speciesTriangles += m.triangles.size();
        rs.m_stats.maxBlasDepth = std::max(rs.m_stats.maxBlasDepth, meshes[s].bvh.depth);
        rs.m_stats.maxWideBlasDepth = std::max(rs.m_stats.maxWideBlasDepth, meshes[s].bvh.wideDepth);
    }

    // Pruned levels: own triangles and BVH, the species' shading data and lighting grid.
    const size_t nodesBefore = rs.blasNodes.size(), trisBefore = rs.tris.size(), blocksBefore = rs.blocks.size();
    const size_t wideBefore = rs.blasWideNodes.size();
    for (size_t gi = ns; gi < meshes.size(); ++gi) {
        const MeshBuild& geo = meshes[gi];
        GeometryRecord gr{};
        gr.kind = GeometryKind::Mesh;
        gr.species = geo.species;
        const PrunedLevel& p = geo.pruned;
        appendTriangles(
            gr, geo.bvh, triBase[geo.species], [&p](uint32_t prim, int c) { return p.corners[3 * size_t(prim) + size_t(c)]; },
            [&p](uint32_t prim) { return p.tris[prim]; });
        rs.geometries.push_back(gr);
        rs.m_stats.maxBlasDepth = std::max(rs.m_stats.maxBlasDepth, geo.bvh.depth);
        rs.m_stats.maxWideBlasDepth = std::max(rs.m_stats.maxWideBlasDepth, geo.bvh.wideDepth);
    }
    rs.m_stats.prunedLevels = meshes.size() - ns;
    rs.m_stats.pruneBytes = (rs.blasNodes.size() - nodesBefore) * sizeof(BvhNode) + (rs.tris.size() - trisBefore) * sizeof(TriAccel) +
                            (rs.blocks.size() - blocksBefore) * sizeof(TriBlock) +
                            (rs.blasWideNodes.size() - wideBefore) * sizeof(BvhNode8);

    // Mesh records' bounds and triangle counts; in kd-tree runs their kd-trees (the seed's structure at
    // the mesh level), indexing triangles by BVH slot (the order of rs.tris) and clipping them to the split
    // boxes ("perfect splits").
    const size_t nm = meshes.size();
    rs.geometryBounds.resize(nm);
    rs.geometryTriangles.resize(nm);
    for (size_t g = 0; g < nm; ++g) {
        GeometryRecord& gr = rs.geometries[g];
        rs.geometryBounds[g] = meshes[g].bvh.bounds;
        rs.geometryTriangles[g] = double(meshes[g].triangles);
        gr.primCount = uint32_t(meshes[g].triangles);
        gr.lo = meshes[g].bvh.bounds.lo;
        gr.hi = meshes[g].bvh.bounds.hi;
    }
    if (scene.render.accel == AccelKind::KdTree) {
        rs.m_stats.maxBlasDepth = 0;
        std::vector<KdTree> kd(nm);
        tbb::parallel_for(size_t(0), nm, [&](size_t g) {
            const TriAccel* tris = rs.tris.data() + rs.geometries[g].triOffset;
            const size_t n = meshes[g].triangles;
            std::vector<Bounds3> triBoxes(n);
            for (size_t t = 0; t < n; ++t) {
                triBoxes[t].extend(tris[t].v0);
                triBoxes[t].extend(tris[t].v0 + tris[t].e1);
                triBoxes[t].extend(tris[t].v0 + tris[t].e2);
            }
            KdBuildSettings ks;
            ks.clip = [tris](uint32_t prim, const Bounds3& box) {
                const TriAccel& t = tris[prim];
                return clipTriangleToBox(t.v0, t.v0 + t.e1, t.v0 + t.e2, box);
            };
            kd[g] = buildKdTree(triBoxes, ks);
        });
        for (size_t g = 0; g < nm; ++g) {
            GeometryRecord& gr = rs.geometries[g];
            gr.lo = kd[g].bounds.lo;   // the box kd-tree rays are clipped to
            gr.hi = kd[g].bounds.hi;
            gr.kdNodeOffset = uint32_t(rs.kdNodes.size());
            gr.kdRefOffset = uint32_t(rs.kdRefs.size());
            rs.kdNodes.insert(rs.kdNodes.end(), kd[g].nodes.begin(), kd[g].nodes.end());
            rs.kdRefs.insert(rs.kdRefs.end(), kd[g].primRefs.begin(), kd[g].primRefs.end());
            rs.m_stats.maxBlasDepth = std::max(rs.m_stats.maxBlasDepth, kd[g].stats.depth);
        }
    }

    // Instance groups, each after the groups it places: its instances in its own frame under a BVH.
    rs.groupGeometry.assign(scene.groups.size(), kNoHit);
    for (size_t g = 0; g < scene.groups.size(); ++g) {
        rs.groupGeometry[g] = uint32_t(nm + g);
        rs.geometries.push_back(GeometryRecord{});
        rs.geometryBounds.emplace_back();
        rs.geometryTriangles.push_back(0.0);
    }
    for (uint32_t g : groupOrder) {
        const GroupDesc& gd = scene.groups[g];
        const uint32_t record = rs.groupGeometry[g];
        const uint32_t first = uint32_t(rs.groupInstances.size());
        std::vector<Bounds3> boxes(gd.instances.size());
        double triangles = 0.0;
        for (size_t i = 0; i < gd.instances.size(); ++i) {
            const InstanceDesc& d = gd.instances[i];
            InstanceRecord rec = makeInstance(d, glm::dvec3(0.0));
            rec.geometry = d.group != kNoGroup ? rs.groupGeometry[d.group] : uint32_t(d.species);
            boxes[i] = instanceBox(d, rs.geometryBounds[rec.geometry], glm::dvec3(0.0));
            triangles += rs.geometryTriangles[rec.geometry];
            rs.groupInstances.push_back(rec);
        }
        BvhBuildSettings gs;
        gs.maxLeafSize = 2;
        gs.wide = true;   // the host's 8-wide copy
        const Bvh bvh = buildBvh(boxes, gs);
        GeometryRecord& gr = rs.geometries[record];
        gr.kind = GeometryKind::Group;
        gr.species = kNoHit;
        gr.nodeOffset = uint32_t(rs.groupNodes.size());
        gr.wideNodeOffset = uint32_t(rs.groupWideNodes.size());
        gr.primOffset = uint32_t(rs.groupOrder.size());
        gr.primCount = uint32_t(gd.instances.size());
        gr.lo = bvh.bounds.lo;
        gr.hi = bvh.bounds.hi;
        rs.groupNodes.insert(rs.groupNodes.end(), bvh.nodes.begin(), bvh.nodes.end());
        rs.groupWideNodes.insert(rs.groupWideNodes.end(), bvh.wideNodes.begin(), bvh.wideNodes.end());
        for (uint32_t slot : bvh.primOrder) rs.groupOrder.push_back(first + slot);
        rs.geometryBounds[record] = bvh.bounds;
        rs.geometryTriangles[record] = triangles;
    }
    rs.m_stats.groups = scene.groups.size();
    rs.m_stats.groupInstances = rs.groupInstances.size();

    rs.forestSpecies.clear();
    for (const SpeciesAssets& a : assets) rs.forestSpecies.push_back(a.forest);
    buildLandscapeArrays(rs, scene);   // and its share of the forest grid
    buildVolumeGrids(rs, scene);   // volumes (core/render/render_volumes.h)
    buildForestGrid(rs, scene);
    countBytes(rs);
    return rs;
}

void buildLandscapeArrays(RenderScene& rs, const Scene& scene)
{
    rs.landNodes.clear();
    rs.landCells.clear();
    rs.tileRecords.clear();
    rs.tileNodes.clear();
    rs.tilePlants.clear();
    rs.base.landscape.layout = LandscapeLayout{};
    rs.m_stats.landscape = LandscapeStats{};
    // The landscape (Dietrich, Marmitt & Slusallek, "Terrain Guided Multi-Level Instancing of Highly Complex
    // Plant Populations"): Wang tiles of the species' full meshes on the terrain's cells.
    if (scene.terrain.enabled() && scene.terrain.cells > 0) {
        const TerrainDesc& t = scene.terrain;
        if (!t.field) throw Error("render: the terrain's heights were not loaded (" + t.dem + ")");
        const size_t ns = scene.species.size();
        if (rs.geometryBounds.size() < ns || rs.geometryTriangles.size() < ns)
            throw Error("render: the scene's species differ from the ones the frame was built with");
        std::vector<LandscapeSpecies> ls(ns);
        for (size_t s = 0; s < ns; ++s) ls[s] = LandscapeSpecies{uint32_t(s), rs.geometryBounds[s].lo, rs.geometryBounds[s].hi, rs.geometryTriangles[s]};
        LandscapeBuild lb = buildLandscape(*t.field, uint32_t(t.cells), t.tiles, t.tiling, t.density, t.origin.y, 0.0f, 0.0f, ls);
        rs.landNodes = std::move(lb.nodes);
        rs.landCells = std::move(lb.cells);
        rs.tileRecords = std::move(lb.tiles);
        rs.tileNodes = std::move(lb.tileNodes);
        rs.tilePlants = std::move(lb.plants);
        rs.base.landscape.layout = lb.layout;
        rs.m_stats.landscape = lb.stats;
    }
    buildLandscapeLight(rs, scene);
    countBytes(rs);
}

void setLandscapeDensity(RenderScene& rs, const Scene& scene)
{
    if (rs.landCells.empty()) return;
    setLandscapeDensity(rs.base.landscape.layout, scene.terrain.density, scene.terrain.origin.y);
    buildLandscapeLight(rs, scene);
    countBytes(rs);
}

void rebuildVolumeGrids(RenderScene& rs, const Scene& scene)
{
    buildVolumeGrids(rs, scene);
    countBytes(rs);
}

bool hasLevelsFor(const RenderScene& rs, const Scene& sceneIn)
{
    if (!(sceneIn.render.pruneDistance > 0.0)) return true;
    Scene lifted;
    const Scene& scene = onTerrain(sceneIn, lifted);
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
    const Scene& scene = onTerrain(sceneIn, lifted);
    const size_t ni = scene.instances.size();
    if (ni == 0 && !scene.terrain.enabled()) throw Error("render: the scene has no instances and no terrain");
    if (scene.terrain.enabled() != !rs.terrainHeights.empty())
        throw Error("render: the scene's terrain differs from the one the frame was built with");
    if (rs.meshLevels.size() != scene.species.size() || rs.groupGeometry.size() != scene.groups.size())
        throw Error("render: the scene's species or groups differ from the ones the frame was built with");
    for (size_t i = 0; i < ni; ++i) checkReference(scene, scene.instances[i], "instance " + std::to_string(i));
    if (!hasLevelsFor(rs, scene)) throw Error("render: the frame was built without the levels of detail this camera needs");
    const glm::dvec3 origin = scene.camera.position;
    const std::vector<int> level = instanceLevels(scene, rs.meshLevels);

    AccelStats& st = rs.m_stats;
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
    RenderView& b = rs.base;
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
        const HeightFieldLayout& L = rs.base.terrain.layout;
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
    placeVolumes(rs, scene, scene.camera.position);
    countBytes(rs);
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

RenderScene buildRenderScene(const Scene& scene, const std::vector<SpeciesAssets>& assets, const glm::vec3& sunRadiance,
                             Progress* progress)
{
    RenderScene rs = buildSceneGeometry(scene, assets, LodLevels::Used, progress);
    placeTopLevel(rs, scene, sunRadiance, scene.render.width, scene.render.height, scene.render.spp);
    if (progress) progress->report(1.0, "acceleration structures built");
    return rs;
}

} // namespace sylva
