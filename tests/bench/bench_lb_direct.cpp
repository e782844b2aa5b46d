// Direct light counted once: the LB grid with its uncollided part (the seed's sum) and with
// only its scattered part, each added to the direct light drawn separately, against the Monte Carlo
// reference, which separates the uncollided light (maxBounces 0) from the rest. docs/ACCURACY.md records it.
//
// The renderer draws the sun's direct light with shadow rays and adds the grid. In grid terms the direct
// light is the reference's uncollided fluence U_mc; the picture's light is then U_mc + G with G the LB grid
// (all of it: the seed's sum, or its scattered part only), against the reference's full fluence F_mc.
#include <cmath>
#include <cstdio>
#include <string>

#include "core/grid/grid.h"
#include "core/lb/lb_basis.h"
#include "core/lb/lb_params.h"
#include "core/lb/lb_solver.h"
#include "core/reference/mc_reference.h"
#include "core/voxel/voxelize.h"
#include "pipeline/grow/tree_grower.h"

using namespace sylva;

namespace {

LightingGrid sum(const LightingGrid& a, const LightingGrid& b)
{
    LightingGrid o = a;
    for (size_t i = 0; i < o.rgb.size(); ++i) o.rgb[i] += b.rgb[i];
    return o;
}
LightingGrid diff(const LightingGrid& a, const LightingGrid& b)
{
    LightingGrid o = a;
    for (size_t i = 0; i < o.rgb.size(); ++i) o.rgb[i] -= b.rgb[i];
    return o;
}

} // namespace

int main(int argc, char** argv)
{
    int n = 48;
    uint64_t paths = 2000000;
    for (int a = 1; a < argc; ++a) {
        const std::string s = argv[a];
        if (s == "--grid" && a + 1 < argc) n = std::atoi(argv[++a]);
        else if (s == "--paths" && a + 1 < argc) paths = uint64_t(std::atoll(argv[++a]));
        else {
            std::printf("usage: bench_lb_direct [--grid N] [--paths P]\n");
            return s == "--help" ? 0 : 2;
        }
    }
    GrowOptions g;
    g.targetTriangles = 60000;
    VoxelizeSettings v;
    v.longestAxisNodes = n;
    const DensityGrid d = voxelize(growTree(g).mesh, v);
    lb::LbParams p = lb::paramsFromPreset(*lb::findPreset("leaf"));
    p.channels[0] = p.channels[2] = p.channels[1];   // the green channel's optics: one solve each
    p.sun = {0.3f, 1.0f, 0.2f};
    lb::LbParams seed = p;   // the seed's configuration (fp32, 2 x the longest edge)
    lb::LbParams front = p;
    lb::useFrontDefaults(front);
    const glm::ivec3 dd = d.geometry.dims;
    std::printf("direct light counted once: grown broadleaf (60k triangles) at %dx%dx%d, leaf green optics, sun (0.3,1,0.2), %llu paths\n",
                dd.x, dd.y, dd.z, static_cast<unsigned long long>(paths));

    ReferenceSettings rs;
    rs.paths = paths;
    ReferenceResult full = solveReference(d, p, rs);
    rs.maxBounces = 0;
    ReferenceResult uncol = solveReference(d, p, rs);
    normalizeToUnobstructed(full.mean, p, &full.standardError);
    normalizeToUnobstructed(uncol.mean, p, &uncol.standardError);
    const LightingGrid scatMc = diff(full.mean, uncol.mean);
    std::printf("reference: %.1f s + %.1f s, noise %.4f (full), %.4f (uncollided)\n", full.seconds, uncol.seconds,
                relativeNoiseInterior(full.mean, full.standardError), relativeNoiseInterior(uncol.mean, uncol.standardError));

    std::printf("%-22s %12s %12s %12s %12s\n", "LB configuration", "uncollided", "scattered", "sum: U+G", "split: U+S");
    std::printf("%-22s %12s %12s %12s %12s\n", "", "vs MC U", "vs MC F-U", "vs MC F", "vs MC F");
    for (const auto& [name, params] : {std::pair<const char*, lb::LbParams>{"seed (fp32, 2x edge)", seed}, {"front (fp16, 1x edge)", front}}) {
        LightingGrid lbFull = lb::solveLighting(d, params);
        LightingGrid lbUn = lb::solveLighting(d, lb::uncollidedParams(params));
        normalizeToUnobstructed(lbFull, params);
        normalizeToUnobstructed(lbUn, params);
        const LightingGrid lbScat = lb::scatteredPart(lbFull, lbUn);
        const double eU = relativeL2Interior(lbUn, uncol.mean, 1), eS = relativeL2Interior(lbScat, scatMc, 1);
        const double eSum = relativeL2Interior(sum(uncol.mean, lbFull), full.mean, 1);
        const double eSplit = relativeL2Interior(sum(uncol.mean, lbScat), full.mean, 1);
        const double eGrid = relativeL2Interior(lbFull, full.mean, 1);
        std::printf("%-22s %12.4f %12.4f %12.4f %12.4f   (LB grid alone vs MC F: %.4f)\n", name, eU, eS, eSum, eSplit, eGrid);
        const std::string tag = params.storage == lb::Storage::Fp16 ? "front" : "seed";
        std::printf("lb_direct_%s_uncollided_err=%.4f\nlb_direct_%s_scattered_err=%.4f\nlb_direct_%s_sum_err=%.4f\nlb_direct_%s_split_err=%.4f\n"
                    "lb_direct_%s_grid_err=%.4f\n",
                    tag.c_str(), eU, tag.c_str(), eS, tag.c_str(), eSum, tag.c_str(), eSplit, tag.c_str(), eGrid);
    }
    return 0;
}
