// Relighting the viewport from cached bases: a species' LB lighting for any sun is the
// weighted sum of its basis solves (pipeline/lighting_job.h: lightingBasisFor, relight), so a sun change
// writes the composed grids into the frame the viewport already holds: no LB solve, no frame build.
#pragma once

#include <memory>
#include <vector>

#include <glm/glm.hpp>

#include "core/base/progress.h"
#include "core/render/render_scene.h"
#include "pipeline/lighting_job.h"
#include "studio/asset_store.h"

namespace sylva {

// One species' basis in memory and the parameters it was solved with (the sun is replaced per relight).
struct SpeciesBasis {
    LightingBasis basis;
    lb::LbParams params;
};
using BasisPtr = std::shared_ptr<const SpeciesBasis>;

// What the viewport relights with: one basis per species (in scene order) and the sun to compose for.
// Inactive (no bases): the assets' own grids.
struct Relighting {
    std::vector<BasisPtr> bases;
    glm::vec3 sun{0.0f, 1.0f, 0.0f};
    bool active() const { return !bases.empty(); }
    bool operator==(const Relighting& o) const { return bases == o.bases && (bases.empty() || sun == o.sun); }
};

// The species' lighting for `sun` (relight of the basis with the parameters' sun replaced) and its
// free-field value (what the renderer divides the grid by, as loadSpeciesAssets sets lightingNorm).
struct RelitGrid {
    LightingGrid grid;
    glm::vec3 norm{1.0f};
};
RelitGrid relitGrid(const SpeciesBasis& basis, const glm::vec3& sun);

// Writes a lighting grid into species `species` of a built frame, normalized exactly as the frame build
// does (grid / norm). Throws Error when the frame holds no grid of that size for the species.
void setFrameLighting(RenderScene& rs, size_t species, const LightingGrid& grid, const glm::vec3& norm);

// The frame's lighting for `relight`: each species' composed grid when active, else (going back) the
// assets' own grids. Cancellable between species through progress.
void applyRelighting(RenderScene& rs, const std::vector<AssetsPtr>& assets, const Relighting& relight, Progress* progress = nullptr);

} // namespace sylva
