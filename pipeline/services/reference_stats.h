// The numbers `sylva reference` prints: the Monte Carlo reference on the scale of the unobstructed
// value, and an LB grid measured against it (docs/ACCURACY.md "Normalization").
#pragma once

#include <vector>

#include <glm/glm.hpp>

#include "core/grid/grid.h"
#include "core/lb/lb_params.h"
#include "core/reference/mc_reference.h"

namespace sylva {

struct ReferenceSummary {
    LightingGrid normalized;               // the mean fluence / unobstructedValue per channel
    std::vector<float> normalizedError;    // its standard error on the same scale
    glm::dvec3 meanNormalized{0.0};        // mean over all nodes per channel (1 in empty space)
    double relativeNoise = 0.0;            // relativeNoiseInterior(normalized, normalizedError)
};
ReferenceSummary summarizeReference(const ReferenceResult& reference, const lb::LbParams& params);

struct ReferenceComparison {
    double relativeL2 = 0.0;                // ||lb - ref|| / ||ref|| over the interior nodes, all channels
    glm::dvec3 relativeL2PerChannel{0.0};   // the same per channel
    double noise = 0.0;                     // the reference's own relative noise
    double withoutNoise = 0.0;              // sqrt(max(0, relativeL2^2 - noise^2)): the error the noise does not explain
    double meanRatio = 0.0;                 // sum of lb / sum of ref over the interior nodes (0 when the reference sums to 0)
};
// lb is an LB lighting grid on its own scale (as `sylva light` writes it) on the reference's grid; both
// are compared after normalizing by the unobstructed value of params. Throws Error when the grids differ in size.
ReferenceComparison compareWithReference(LightingGrid lb, const ReferenceSummary& reference, const lb::LbParams& params);

} // namespace sylva
