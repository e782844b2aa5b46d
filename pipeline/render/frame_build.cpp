// A frame from a scene: the renderer's build (core/render/render_scene.h), the LB solves the frame triggers
// (the forest-level grid over the top level's instances, core/lb/forest_grid.h, and its share over the
// landscape's plants, core/terrain/landscape_light.h: each applied unless off or, auto, exposure is uniform),
// then the top level.
#include "pipeline/render/frame_build.h"

#include <algorithm>

#include "core/base/error.h"
#include "core/terrain/landscape_light.h"

namespace sylva {

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

// The landscape's share, into rs (cleared first by lightLandscape).
void solveLandscapeShare(RenderScene& rs, const Scene& scene)
{
    LandscapeLightStats& st = rs.buildStats.landscapeLight;
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
    LandscapeLight l = solveLandscapeLight(*t.field, rs.frame.landscape.layout, rs.landCells, rs.tileRecords, rs.tilePlants, terrainSnowY(t), terrainRockCos(t),
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
    rs.frame.landscape.lightLayout = l.layout;
}

} // namespace

void lightLandscape(RenderScene& rs, const Scene& scene)
{
    clearLandscapeLight(rs);
    solveLandscapeShare(rs, scene);
    countFrameBytes(rs);
}

void lightForestGrid(RenderScene& rs, const Scene& scene)
{
    ForestGridStats& st = rs.buildStats.forestGrid;
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

void lightFrame(RenderScene& rs, const Scene& scene)
{
    lightLandscape(rs, scene);
    lightForestGrid(rs, scene);
}

RenderScene buildRenderScene(const Scene& scene, const std::vector<SpeciesAssets>& assets, const glm::vec3& sunRadiance,
                             Progress* progress)
{
    RenderScene rs = buildSceneGeometry(scene, assets, LodLevels::Used, progress);
    lightFrame(rs, scene);
    placeTopLevel(rs, scene, sunRadiance, scene.render.width, scene.render.height, scene.render.spp);
    if (progress) progress->report(1.0, "acceleration structures built");
    return rs;
}

} // namespace sylva
