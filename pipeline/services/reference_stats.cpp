// The reference's normalized summary and the LB error against it (reference_stats.h).
#include "pipeline/services/reference_stats.h"

#include <algorithm>
#include <cmath>

#include "pipeline/services/grid_stats.h"

namespace sylva {

ReferenceSummary summarizeReference(const ReferenceResult& reference, const lb::LbParams& params)
{
    ReferenceSummary s;
    s.normalized = reference.mean;
    s.normalizedError = reference.standardError;
    normalizeToUnobstructed(s.normalized, params, &s.normalizedError);
    s.meanNormalized = channelStats(s.normalized).mean;
    s.relativeNoise = relativeNoiseInterior(s.normalized, s.normalizedError);
    return s;
}

ReferenceComparison compareWithReference(LightingGrid lb, const ReferenceSummary& reference, const lb::LbParams& params)
{
    const LightingGrid& ref = reference.normalized;
    normalizeToUnobstructed(lb, params);
    ReferenceComparison c;
    c.relativeL2 = relativeL2Interior(lb, ref);   // checks the sizes first
    for (int ch = 0; ch < 3; ++ch) c.relativeL2PerChannel[ch] = relativeL2Interior(lb, ref, ch);
    c.noise = reference.relativeNoise;
    c.withoutNoise = std::sqrt(std::max(0.0, c.relativeL2 * c.relativeL2 - c.noise * c.noise));
    double sumLb = 0.0, sumRef = 0.0;
    for (int i = 1; i < ref.geometry.dims.x - 1; ++i)
        for (int j = 1; j < ref.geometry.dims.y - 1; ++j)
            for (int k = 1; k < ref.geometry.dims.z - 1; ++k)
                for (int ch = 0; ch < 3; ++ch) {
                    sumLb += lb.at(i, j, k, ch);
                    sumRef += ref.at(i, j, k, ch);
                }
    c.meanRatio = sumRef > 0.0 ? sumLb / sumRef : 0.0;
    return c;
}

} // namespace sylva
