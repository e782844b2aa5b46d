// Pictures compared in linear radiance, before any exposure or tone curve: a picture uniformly too bright
// or too dark fails, which a comparison of auto-exposed pictures cannot see (each picture's own
// log-average cancels a uniform scale). Plain C++ and GLM, so gpu_replay (core and CUDA only) uses it too.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdio>
#include <string>
#include <vector>

#include <glm/glm.hpp>

namespace sylva::test {

// What a comparison allows.
// - A value (one channel of one pixel) is off when |got - want| > pixelRelative x |want| + floor, where the
//   floor is floorOfMean x the reference's mean over all values (so dark pixels are not judged by their
//   rounding alone).
// - The picture fails when more than offShare of its values are off, or when the mean of a channel differs
//   by more than meanRelative of the reference's mean (a uniform change of brightness or colour).
struct LinearTolerance {
    double pixelRelative;
    double floorOfMean;
    double offShare;
    double meanRelative;
};

struct LinearComparison {
    size_t values = 0;
    size_t off = 0;
    double floor = 0.0;                 // floorOfMean x the reference's mean over all values
    double worst = 0.0;                 // the largest |got - want| / (pixelRelative x |want| + floor): > 1 is off
    glm::dvec3 meanGot{0.0}, meanWant{0.0};
    double meanError = 0.0;             // the largest |mean got - mean want| / mean want over the channels
    bool finite = true;                 // every value of got is finite
    bool pass = false;
    std::string summary;                // one line: the figures and the bounds
};

inline LinearComparison compareLinear(const std::vector<glm::vec3>& got, const std::vector<glm::vec3>& want, const LinearTolerance& tol)
{
    LinearComparison c;
    if (got.size() != want.size() || want.empty()) {
        c.summary = "sizes differ: " + std::to_string(got.size()) + " against " + std::to_string(want.size()) + " pixels";
        return c;
    }
    c.values = want.size() * 3;
    double all = 0.0;
    for (size_t i = 0; i < want.size(); ++i) {
        c.meanWant += glm::dvec3(want[i]);
        c.meanGot += glm::dvec3(got[i]);
        all += double(want[i].x) + double(want[i].y) + double(want[i].z);
        c.finite = c.finite && std::isfinite(got[i].x) && std::isfinite(got[i].y) && std::isfinite(got[i].z);
    }
    c.meanWant /= double(want.size());
    c.meanGot /= double(want.size());
    c.floor = tol.floorOfMean * std::fabs(all) / double(c.values);
    for (size_t i = 0; i < want.size(); ++i)
        for (int k = 0; k < 3; ++k) {
            const double w = want[i][k], g = got[i][k];
            const double r = std::fabs(g - w) / (tol.pixelRelative * std::fabs(w) + c.floor);
            c.worst = std::max(c.worst, std::isfinite(r) ? r : 1e30);
            c.off += !(r <= 1.0);
        }
    for (int k = 0; k < 3; ++k) {
        const double m = std::fabs(c.meanWant[k]);
        c.meanError = std::max(c.meanError, m > 0.0 ? std::fabs(c.meanGot[k] - c.meanWant[k]) / m : std::fabs(c.meanGot[k]));
    }
    c.pass = c.finite && double(c.off) <= tol.offShare * double(c.values) && c.meanError <= tol.meanRelative;
    char line[400];
    std::snprintf(line, sizeof line,
                  "%zu of %zu values off by more than %.3g relative + %.3g of the mean (at most %.3g%% allowed), worst %.3g of "
                  "the bound; channel means differ by %.3g%% (at most %.3g%%)%s",
                  c.off, c.values, tol.pixelRelative, tol.floorOfMean, 100.0 * tol.offShare, c.worst, 100.0 * c.meanError,
                  100.0 * tol.meanRelative, c.finite ? "" : "; NOT FINITE");
    c.summary = line;
    return c;
}

// The GPU's film against the CPU's for the same prepared frame, in every mode (tst_gpu, gpu_replay). The device
// runs the same shading code; its bits differ only where fused multiply-adds round differently, which moves a
// value by about 1e-6 of itself, except where a ray near a plant's or the terrain's edge hits the other side of
// it (the landscape: at most 0.10% of values in the recorded device runs, counted after tone mapping as values
// off by 0.1). So: a value is off above 0.5% of itself + 0.1% of the mean; at most 1% of values off (ten times
// the recorded flips); channel means within 0.5%. A sun 2% brighter on one side moves every lit value by 2% and
// fails in every mode (tst_gpu::linearCheckCatchesBrighterSun), though the sky keeps the means within 0.6%.
inline constexpr LinearTolerance kGpuAgainstCpu{0.005, 0.001, 0.01, 0.005};

} // namespace sylva::test
