// The landscape surface kind's builder: the Wang tiling, its tiles' populations and 2D trees, the cells and
// their kd-tree (core/terrain/landscape.h), and the density rule's layout.
#include "core/render/scene_build.h"

#include "core/base/error.h"
#include "core/terrain/landscape.h"

namespace sylva {

void clearLandscapeLight(RenderScene& rs)
{
    rs.landLight.clear();
    rs.frame.landscape.lightLayout = LandLightLayout{};
    rs.buildStats.landscapeLight = LandscapeLightStats{};
}


void buildLandscapeArrays(RenderScene& rs, const Scene& scene)
{
    rs.landNodes.clear();
    rs.landCells.clear();
    rs.tileRecords.clear();
    rs.tileNodes.clear();
    rs.tilePlants.clear();
    rs.frame.landscape.layout = LandscapeLayout{};
    rs.buildStats.landscape = LandscapeStats{};
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
        rs.frame.landscape.layout = lb.layout;
        rs.buildStats.landscape = lb.stats;
    }
    clearLandscapeLight(rs);
    countFrameBytes(rs);
}

void setLandscapeDensity(RenderScene& rs, const Scene& scene)
{
    if (rs.landCells.empty()) return;
    setLandscapeDensity(rs.frame.landscape.layout, scene.terrain.density, scene.terrain.origin.y);
    clearLandscapeLight(rs);
    countFrameBytes(rs);
}

} // namespace sylva
