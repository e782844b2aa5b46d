// A frame from a scene in the pipeline: the renderer's build (core/render/render_scene.h buildSceneGeometry,
// placeTopLevel) with the LB solves the frame triggers between them. The geometry build solves nothing; the
// scene-level LB grids are solved here, where the pipeline's other LB solves run.
#pragma once

#include <vector>

#include "core/base/progress.h"
#include "core/render/render_scene.h"

namespace sylva {

// The forest-level LB grid (core/lb/forest_grid.h) over the scene's top-level instances of species with a
// density grid, with the scene's sun and the first such species' optics: its factors become rs.instanceLights
// (one record per scene instance, factor 1 outside it; placeTopLevel points each instance at its record).
// Auto applies them only where exposure differs (factors and face factors spread by at least 2%); off clears
// them. The statistics go to rs.buildStats.forestGrid.
void lightForestGrid(RenderScene& rs, const Scene& scene);

// The forest grid's share over the landscape's plants (core/terrain/landscape_light.h): the lattice of which
// plants grow now (after buildLandscapeArrays or setLandscapeDensity), applied unless off or (auto) exposure
// is uniform over the cells with plants. Statistics in rs.buildStats.landscapeLight.
void lightLandscape(RenderScene& rs, const Scene& scene);

// Both, after buildSceneGeometry (rs built from `scene`).
void lightFrame(RenderScene& rs, const Scene& scene);

// The build, the LB solves and the top level at the scene's own size and samples: what sylva render, the
// banded renders, the studies and the exports trace.
RenderScene buildRenderScene(const Scene& scene, const std::vector<SpeciesAssets>& assets, const glm::vec3& sunRadiance,
                             Progress* progress = nullptr);

} // namespace sylva
