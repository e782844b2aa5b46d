// The host control flow of an LB solve, the same for every device: channel grouping, solves per pass,
// memory check, coarse start, the step or tolerance loop, progress and stats.
#include "core/lb/lb_device.h"

#include <algorithm>
#include <chrono>
#include <cstdio>

#include <tbb/parallel_for.h>

#include "core/base/error.h"
#include "core/lb/lattice.h"
#include "core/lb/lb_slab.h"

namespace sylva::lb {

void LbDevice::refuseMemory(const std::string& message) const { throw Error(message); }

DensityGrid coarsen(const DensityGrid& fine)
{
    const glm::ivec3 fd = fine.geometry.dims;
    DensityGrid c;
    c.geometry.dims = fd / 2 + 1;
    c.geometry.origin = fine.geometry.origin;
    c.geometry.spacing = fine.geometry.spacing * 2.0;
    const glm::ivec3 cd = c.geometry.dims;
    c.density.assign(c.geometry.nodeCount(), 0.0f);
    const bool wood = !fine.woodFraction.empty();
    if (wood) c.woodFraction.assign(c.geometry.nodeCount(), 0.0f);
    tbb::parallel_for(1, cd.x - 1, [&](int I) {
        for (int J = 1; J < cd.y - 1; ++J)
            for (int K = 1; K < cd.z - 1; ++K) {
                double rho = 0.0, w = 0.0, sum = 0.0;
                for (int a = -1; a <= 1; ++a)
                    for (int b = -1; b <= 1; ++b)
                        for (int e = -1; e <= 1; ++e) {
                            const int i = 2 * I + a, j = 2 * J + b, k = 2 * K + e;
                            if (i < 0 || j < 0 || k < 0 || i >= fd.x || j >= fd.y || k >= fd.z) continue;
                            const double weight = (a ? 0.5 : 1.0) * (b ? 0.5 : 1.0) * (e ? 0.5 : 1.0);
                            const size_t n = fine.geometry.index(i, j, k);
                            rho += weight * fine.density[n];
                            if (wood) w += weight * fine.woodFraction[n];
                            sum += weight;
                        }
                const size_t n = c.geometry.index(I, J, K);
                c.density[n] = sum > 0.0 ? float(std::min(1.0, 2.0 * rho / sum)) : 0.0f;
                if (wood) c.woodFraction[n] = sum > 0.0 ? float(w / sum) : 0.0f;
            }
    });
    return c;
}

std::vector<ChannelParams> distinctSolves(const LbParams& params, int (&solveOf)[3])
{
    // Channels with equal optics share one solve: the result is linear in the sun intensity.
    std::vector<ChannelParams> solves;
    for (int c = 0; c < 3; ++c) {
        const ChannelParams& p = params.channels[size_t(c)];
        int found = -1;
        for (size_t s = 0; s < solves.size(); ++s)
            if (solves[s].sigmaA == p.sigmaA && solves[s].sigmaS == p.sigmaS && solves[s].g == p.g) found = int(s);
        if (found < 0) {
            found = int(solves.size());
            solves.push_back(p);
        }
        solveOf[c] = found;
    }
    return solves;
}

namespace {

struct StepResult {
    int steps = 0;
    bool converged = false;
};

// Advances a grid in blocks until the step budget is spent or (tolerance mode) the relative change
// per step falls under the tolerance. report(done) is called after each block.
template <typename Report>
StepResult runSteps(LbGrid& grid, const LbParams& params, int steps, SolveStats& stats, Report&& report)
{
    const bool tolMode = params.tolerance > 0.0;
    // Fixed steps run in blocks of the device's depth (the CPU: cache-sized wavefronts). In tolerance
    // mode the last two levels of a block measure the change per step; that check costs about a step,
    // so by default it runs on the last block of every ~16 steps rather than on every block.
    const int depth = params.blockSteps > 0 ? params.blockSteps : grid.autoLevels();
    const int block = tolMode && params.checkEvery > 0 ? std::max(2, params.checkEvery) : std::max(tolMode ? 2 : 1, depth);
    const int checkBlocks = tolMode && params.checkEvery <= 0 ? std::max(1, (16 + block - 1) / block) : 1;
    stats.blockSteps = block;
    StepResult r;
    int blocksRun = 0;
    while (r.steps < steps) {
        const int levels = std::min(block, steps - r.steps);
        ++blocksRun;
        const bool checkNow = tolMode && (blocksRun % checkBlocks == 0 || r.steps + levels >= steps);
        const int compare = checkNow && levels >= 2 ? levels - 1 : 0;
        const double change = grid.advanceBlock(levels, compare);
        r.steps += levels;
        if (compare > 0) {
            stats.changeHistory.emplace_back(r.steps, change);
            stats.lastChange = change;
            if (change < params.tolerance) {
                r.converged = true;
                break;
            }
        }
        report(r.steps);
    }
    return r;
}

// Coarse start: the same solves run to the tolerance on the coarsened grid, itself coarse-started
// while it has at least 32 nodes on its longest edge, then interpolated as the start of the fine
// solve. The levels' grids are made once and reused for every channel group.
class CoarseChain {
public:
    CoarseChain(LbDevice& device, const DensityGrid& fine, const LbParams& params) : m_device(device), m_params(params)
    {
        m_densities.push_back(coarsen(fine));
        while (m_densities.back().geometry.longestEdge() >= 32) m_densities.push_back(coarsen(m_densities.back()));
        m_grids.resize(m_densities.size());
    }

    // Sets the state of `fine` (whose interior is to be written) for `solves`; returns the steps run
    // on all coarse levels. The coarse solves check `progress` for cancel like the fine one.
    int start(LbGrid& fine, const std::vector<ChannelParams>& solves, Progress* progress)
    {
        int steps = 0;
        for (size_t l = m_densities.size(); l-- > 0;) {
            const bool fromCoarser = l + 1 < m_densities.size();
            if (!m_grids[l]) m_grids[l] = m_device.makeGrid(m_densities[l], m_params, solves, progress);
            else m_grids[l]->setSolves(solves, fromCoarser);
            if (fromCoarser) m_grids[l]->prolongateFrom(*m_grids[l + 1]);
            SolveStats levelStats;
            const int maxSteps = m_params.maxSteps > 0 ? m_params.maxSteps : 4 * m_densities[l].geometry.longestEdge();
            const StepResult r = runSteps(*m_grids[l], m_params, maxSteps, levelStats, [](int) {});
            steps += r.steps;
        }
        fine.prolongateFrom(*m_grids[0]);
        return steps;
    }

private:
    LbDevice& m_device;
    const LbParams& m_params;
    std::vector<DensityGrid> m_densities;   // [0] half the fine resolution, then coarser
    std::vector<std::unique_ptr<LbGrid>> m_grids;
};

LightingGrid runSolve(LbDevice& device, const DensityGrid& density, const LbParams& params, Progress* progress,
                      SolveStats& stats)
{
    int solveOf[3];
    const std::vector<ChannelParams> solves = distinctSolves(params, solveOf);
    stats.channelSolves = int(solves.size());

    // Memory: two copies of 19 values per node for each channel solve advanced together, plus an
    // eighth of that per level for a coarse start (1/8 + 1/64 + ... < 1/7). One solve at a time by
    // default: the channels are independent, so advancing them together saves nothing, and one at a
    // time needs a third of the memory and touches it once (the grid is reused). Refused when even
    // one does not fit in what the device has available.
    const size_t valueBytes = params.storage == Storage::Fp16 ? 2 : 4;
    const double nodes = double(density.geometry.nodeCount());
    const bool coarseWanted = params.coarseStart && params.tolerance > 0.0 && density.geometry.longestEdge() >= 32;
    const double perSolve = 2.0 * nodes * kDirections * double(valueBytes) * (coarseWanted ? 8.0 / 7.0 : 1.0);
    const double other = nodes * (4.0 * 3 + 8.0);   // output grid, padded density and brown mask
    const double available = device.availableBytes();
    size_t group = params.solvesPerPass > 0 ? std::min(solves.size(), size_t(params.solvesPerPass)) : 1;
    if (available > 0 && perSolve * double(group) + other > 0.8 * available) group = 1;
    if (available > 0 && perSolve + other > 0.8 * available) {
        const glm::ivec3 d = density.geometry.dims;
        char msg[320];
        std::snprintf(msg, sizeof msg,
                      "the %dx%dx%d grid needs %.1f GB for one channel's LB distributions (%s) but %.1f GB of %s is "
                      "available; use a smaller grid%s",
                      d.x, d.y, d.z, (perSolve + other) / 1e9, valueBytes == 2 ? "fp16" : "fp32", available / 1e9,
                      device.memoryName().c_str(), valueBytes == 2 ? "" : " or fp16 storage");
        device.refuseMemory(msg);
    }
    stats.bytesPerStep = 2.0 * nodes * kDirections * double(valueBytes) * double(solves.size());

    const int longest = density.geometry.longestEdge();
    const bool tolMode = params.tolerance > 0.0;
    const int steps = tolMode ? (params.maxSteps > 0 ? params.maxSteps : 4 * longest)
                              : fixedSteps(params, density.geometry.dims);
    LightingGrid out;
    out.geometry = density.geometry;
    out.rgb.assign(density.geometry.nodeCount() * 3, 0.0f);
    std::vector<float> tot;
    const size_t groups = (solves.size() + group - 1) / group;
    bool allConverged = true;
    // One grid (and one coarse chain) for all channel groups: their memory is reused.
    const bool coarse = params.coarseStart && tolMode && longest >= 32;
    std::unique_ptr<LbGrid> grid;
    std::unique_ptr<CoarseChain> chain;
    if (coarse) chain = std::make_unique<CoarseChain>(device, density, params);
    for (size_t g0 = 0; g0 < solves.size(); g0 += group) {
        const std::vector<ChannelParams> these(solves.begin() + long(g0), solves.begin() + long(std::min(solves.size(), g0 + group)));
        if (!grid) grid = device.makeGrid(density, params, these, progress);
        else grid->setSolves(these, coarse);
        if (coarse) stats.coarseSteps = std::max(stats.coarseSteps, chain->start(*grid, these, progress));
        const double groupIndex = double(g0 / group);
        const StepResult r = runSteps(*grid, params, steps, stats, [&](int done) {
            if (progress)
                progress->report((groupIndex + double(done) / double(steps)) / double(groups),
                                 "LB step " + std::to_string(done) + "/" + std::to_string(steps) +
                                     (groups > 1 ? (group == 1 ? " (channel solve " : " (channel group ") + std::to_string(g0 / group + 1) +
                                                       "/" + std::to_string(groups) + ")"
                                                 : ""));
        });
        stats.steps = std::max(stats.steps, r.steps);
        allConverged = allConverged && r.converged;
        for (size_t s = 0; s < these.size(); ++s) {
            grid->totals(s, tot);
            for (int c = 0; c < 3; ++c) {
                if (solveOf[c] != int(g0 + s)) continue;
                const float intensity = params.intensity[c];
                for (size_t n = 0; n < tot.size(); ++n) out.rgb[n * 3 + size_t(c)] = tot[n] * intensity;
            }
        }
    }
    stats.converged = tolMode && allConverged;
    return out;
}

} // namespace

LightingGrid solveOnDevice(LbDevice& device, const DensityGrid& density, const LbParams& params, Progress* progress,
                           SolveStats* stats)
{
    validate(params);
    validateDensity(density);
    device.checkSupported(params);
    SolveStats local;
    SolveStats& st = stats ? *stats : local;
    st = SolveStats{};
    const auto t0 = std::chrono::steady_clock::now();
    LightingGrid out = runSolve(device, density, params, progress, st);
    st.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    return out;
}

} // namespace sylva::lb
