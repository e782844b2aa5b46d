// Presets from the papers (docs/LB_MODEL.md "Parameter presets") and parameter validation with messages that
// name the bound. Geist & Steele 2008 = Geist & Steele, "A Lighting Model for Fast Rendering of Forest
// Ecosystems"; Geist & Westall = Geist & Westall, "Lattice-Boltzmann Lighting Models".
#include "core/lb/lb_params.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "core/base/error.h"
#include "core/base/number_text.h"
#include "core/grid/grid.h"

namespace sylva::lb {

const std::vector<Preset>& presets()
{
    static const std::vector<Preset> list = {
        {"leaf", "green leaves, Knapp-Carter optics (Geist & Steele 2008, Table 1)",
         {{{0.109f, 0.891f, -0.120f}, {0.091f, 0.909f, 0.091f}, {0.118f, 0.882f, -0.333f}}}, true},
        {"dogrose", "dogrose bush (Geist & Westall, Table 1)",
         {{{0.109f, 0.891f, -0.231f}, {0.091f, 0.909f, 0.103f}, {0.118f, 0.882f, -0.750f}}}, true},
        {"cloud", "cloud, albedo 0.99, forward scattering (Geist & Westall, section 3.2.1)",
         {{{0.008f, 0.792f, 0.9f}, {0.008f, 0.792f, 0.9f}, {0.008f, 0.792f, 0.9f}}}, false},
        {"pmma", "PMMA plastic (Geist & Westall, Table 2)",
         {{{0.01f, 0.99f, 0.80f}, {0.01f, 0.99f, -0.88f}, {0.01f, 0.99f, -0.88f}}}, false},
    };
    return list;
}

const Preset* findPreset(const std::string& name)
{
    for (const auto& p : presets())
        if (p.name == name) return &p;
    return nullptr;
}

LbParams paramsFromPreset(const Preset& preset)
{
    LbParams p;
    p.channels = preset.channels;
    p.zeroF0 = preset.zeroF0;
    return p;
}

void useFrontDefaults(LbParams& params)
{
    params.storage = Storage::Fp16;
    params.stepsPerEdge = 1;
}

int defaultSteps(const glm::ivec3& dims) { return 2 * glm::max(dims.x, glm::max(dims.y, dims.z)); }

int fixedSteps(const LbParams& params, const glm::ivec3& dims)
{
    if (params.steps > 0) return params.steps;
    return std::max(1, params.stepsPerEdge * glm::max(dims.x, glm::max(dims.y, dims.z)));
}

void validate(const LbParams& params)
{
    static const char* names[3] = {"R", "G", "B"};
    for (int c = 0; c < 3; ++c) {
        const ChannelParams& ch = params.channels[size_t(c)];
        auto fail = [&](const std::string& what) {
            throw Error(std::string("invalid LB parameter for channel ") + names[c] + ": " + what);
        };
        if (!std::isfinite(ch.sigmaA) || ch.sigmaA < 0.0f)
            fail("sigma_a = " + numberText(ch.sigmaA, kFloatDigits) + " must be finite and >= 0");
        if (!std::isfinite(ch.sigmaS) || ch.sigmaS < 0.0f)
            fail("sigma_s = " + numberText(ch.sigmaS, kFloatDigits) + " must be finite and >= 0");
        // Stability (docs/LB_MODEL.md): every coefficient of I + rho*Omega is >= 0 iff sigma_t * max(rho) <= 1.
        // Checked on the float sum the kernels use (compactOmega): any excess over 1 makes the coefficient
        // 1 - rho * sigma_t negative and f with it. Decimal inputs that sum to 1 (0.118 + 0.882) round to
        // exactly 1 there.
        const float sigmaT = ch.sigmaA + ch.sigmaS;
        if (sigmaT > 1.0f)
            fail("sigma_t = sigma_a + sigma_s = " + numberText(sigmaT, kFloatDigits) +
                 " exceeds the stability bound 1 (sigma_t * max density must be <= 1)");
        if (!std::isfinite(ch.g) || std::fabs(ch.g) > 1.0f)
            fail("g = " + numberText(ch.g, kFloatDigits) + " must lie in [-1, 1]");
    }
    const glm::vec3 s = params.sun;
    if (!std::isfinite(s.x) || !std::isfinite(s.y) || !std::isfinite(s.z) || glm::length(s) < 1e-12f)
        throw Error("invalid sun direction: it must be a finite, non-zero vector");
    for (int c = 0; c < 3; ++c)
        if (!std::isfinite(params.intensity[c]) || params.intensity[c] < 0.0f)
            throw Error(std::string("invalid sun intensity for channel ") + names[c] + ": must be finite and >= 0");
    if (!params.boundary.empty()) {
        if (params.boundary.size() != size_t(kDirections))
            throw Error("invalid LB boundary distribution: " + std::to_string(params.boundary.size()) + " values, expected 19");
        for (float v : params.boundary)
            if (!std::isfinite(v) || v < 0.0f) throw Error("invalid LB boundary distribution: values must be finite and >= 0");
    }
    if (params.steps < 0) throw Error("invalid step count " + std::to_string(params.steps) + ": must be >= 1");
    if (!paramHolds(kStepsPerEdge, (long long)params.stepsPerEdge))
        throw Error("invalid steps per edge " + std::to_string(params.stepsPerEdge) + ": must be in [" + paramNumber(kStepsPerEdge.lo) + ", " +
                    paramNumber(kStepsPerEdge.hi) + "]");
    if (!std::isfinite(params.tolerance) || params.tolerance < 0.0)
        throw Error("invalid tolerance: must be a finite number > 0");
    if (params.checkEvery < 0) throw Error("invalid tolerance check period: must be >= 1 step (or 0 for automatic)");
    if (params.maxSteps < 0) throw Error("invalid maximum step count: must be >= 1");
    if (params.blockSteps < 0) throw Error("invalid block depth: must be >= 1 (or 0 for automatic)");
    if (!(params.brownThreshold >= 0.0f && params.brownThreshold <= 1.0f))
        throw Error("invalid brown threshold: must lie in [0, 1]");
    if (params.storage == Storage::Fp16) {
        const float maxI = glm::max(params.intensity.x, glm::max(params.intensity.y, params.intensity.z));
        if (maxI > 1000.0f)
            throw Error("sun intensity " + std::to_string(maxI) +
                        " is too large for fp16 storage (max 1000); use fp32 storage or scale the intensity");
    }
}

void validateDensity(const DensityGrid& density)
{
    const glm::ivec3 d = density.geometry.dims;
    if (d.x < 3 || d.y < 3 || d.z < 3)
        throw Error("density grid " + std::to_string(d.x) + "x" + std::to_string(d.y) + "x" + std::to_string(d.z) +
                    " is too small: every axis needs at least 3 nodes");
    if (density.density.size() != density.geometry.nodeCount())
        throw Error("density grid holds " + std::to_string(density.density.size()) + " values for " +
                    std::to_string(density.geometry.nodeCount()) + " nodes");
    if (!density.woodFraction.empty() && density.woodFraction.size() != density.density.size())
        throw Error("wood fraction grid size differs from the density grid");
    for (size_t n = 0; n < density.woodFraction.size(); ++n) {
        const float w = density.woodFraction[n];
        if (!(w >= 0.0f && w <= 1.0f)) {
            std::ostringstream msg;
            msg << "wood fraction " << w << " at node " << n << " is outside [0, 1]";
            throw Error(msg.str());
        }
    }
    for (size_t n = 0; n < density.density.size(); ++n) {
        const float r = density.density[n];
        if (!(r >= 0.0f && r <= 1.0f)) {
            std::ostringstream msg;
            msg << "density value " << r << " at node " << n << " is outside [0, 1]";
            throw Error(msg.str());
        }
    }
}

} // namespace sylva::lb
