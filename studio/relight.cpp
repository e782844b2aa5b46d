// Relighting: the basis composed for a sun, written into a built frame's lighting array.
#include "studio/relight.h"

#include <string>

#include "core/base/error.h"
#include "core/lb/lb_basis.h"

namespace sylva {

RelitGrid relitGrid(const SpeciesBasis& basis, const glm::vec3& sun)
{
    lb::LbParams p = basis.params;
    p.sun = sun;
    RelitGrid r;
    r.grid = relight(basis.basis, p);
    r.norm = boundaryWeightsOf(p).totals();
    return r;
}

void setFrameLighting(RenderScene& rs, size_t species, const LightingGrid& grid, const glm::vec3& norm)
{
    if (species >= rs.species.size()) throw Error("relight: the frame has no species " + std::to_string(species));
    const SpeciesRecord& sr = rs.species[species];
    const size_t n = grid.geometry.nodeCount() * 3;
    if (sr.gridInvSpacing == 0.0f || sr.gridDims != grid.geometry.dims || grid.rgb.size() != n || size_t(sr.gridOffset) + n > rs.lighting.size())
        throw Error("relight: species " + std::to_string(species) + "'s lighting grid in the frame differs from the relit one");
    float* out = rs.lighting.data() + sr.gridOffset;
    for (size_t i = 0; i < n; ++i) {
        const float f = norm[int(i % 3)];
        out[i] = f > 0.0f ? grid.rgb[i] / f : 0.0f;
    }
}

void applyRelighting(RenderScene& rs, const std::vector<AssetsPtr>& assets, const Relighting& relight, Progress* progress)
{
    for (size_t s = 0; s < assets.size(); ++s) {
        if (progress && progress->isCancelled()) throw Cancelled();
        if (relight.active()) {
            if (s >= relight.bases.size() || !relight.bases[s]) throw Error("relight: a species has no basis");
            const RelitGrid r = relitGrid(*relight.bases[s], relight.sun);
            setFrameLighting(rs, s, r.grid, r.norm);
        } else if (!assets[s]->lighting.rgb.empty()) {
            setFrameLighting(rs, s, assets[s]->lighting, assets[s]->lightingNorm);
        }
    }
}

} // namespace sylva
