// Voxelization study: sub-cells per cell edge against a fine sampling, for the density and the LB result.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>

#include "core/lb/lb_params.h"
#include "core/lb/lb_solver.h"
#include "core/reference/mc_reference.h"
#include "core/voxel/voxelize.h"
#include "pipeline/grow/tree_grower.h"
#include "pipeline/import/mesh_import.h"
#include "pipeline/study/study_parts.h"

namespace sylva::study {
namespace {

double densityError(const DensityGrid& a, const DensityGrid& ref)
{
    const GridGeometry& g = ref.geometry;
    double diff = 0.0, norm = 0.0;
    for (int i = 1; i < g.dims.x - 1; ++i)
        for (int j = 1; j < g.dims.y - 1; ++j)
            for (int k = 1; k < g.dims.z - 1; ++k) {
                const size_t n = g.index(i, j, k);
                const double d = double(a.density[n]) - double(ref.density[n]);
                diff += d * d;
                norm += double(ref.density[n]) * double(ref.density[n]);
            }
    return norm > 0.0 ? std::sqrt(diff / norm) : 0.0;
}

double interiorTotal(const DensityGrid& d)
{
    const GridGeometry& g = d.geometry;
    double sum = 0.0;
    for (int i = 1; i < g.dims.x - 1; ++i)
        for (int j = 1; j < g.dims.y - 1; ++j)
            for (int k = 1; k < g.dims.z - 1; ++k) sum += d.density[g.index(i, j, k)];
    return sum;
}

} // namespace

VoxelData measureVoxel(const Options& o)
{
    VoxelData data;
    data.run = startRun(o);
    data.referenceSubcells = 12;
    const int grid = o.quick ? 32 : 64;
    const std::vector<int> subcells{3, 4, 6, 8};

    std::vector<std::pair<std::string, TriangleMesh>> meshes;
    const std::string tree = treeMeshPath(o);
    if (std::filesystem::exists(tree)) meshes.emplace_back("tree", importMesh(tree));
    else say(o, "voxel: real tree skipped, mesh not found: " + tree);
    GrowOptions g;
    g.targetTriangles = 200000;
    meshes.emplace_back("dense", growTree(g).mesh);

    lb::LbParams params = lb::paramsFromPreset(*lb::findPreset("leaf"));
    params.sun = {0.3f, 1.0f, 0.2f};
    auto lit = [&](const DensityGrid& d) {
        LightingGrid l = lb::solveLighting(d, params);
        normalizeToUnobstructed(l, params);
        return l;
    };
    for (const auto& [name, mesh] : meshes) {
        VoxelizeSettings vs;
        vs.longestAxisNodes = grid;
        vs.subcells = data.referenceSubcells;
        const DensityGrid fine = voxelize(mesh, vs);
        const double fineTotal = interiorTotal(fine);
        double total3 = 0.0;
        for (int s : subcells) {
            vs.subcells = s;
            double best = 1e30;
            DensityGrid d;
            for (int rep = 0; rep < 3; ++rep) {   // voxelizing is quick: the best of three
                const double v0 = secondsNow();
                d = voxelize(mesh, vs);
                best = std::min(best, secondsNow() - v0);
            }
            const double total = interiorTotal(d);
            if (s == 3) total3 = total;
            // The finest density with this run's total: the same leaves, the same optical depth overall.
            DensityGrid ref = fine;
            const double scale = fineTotal > 0.0 ? total / fineTotal : 1.0;
            for (float& v : ref.density) v = float(std::min(1.0, double(v) * scale));
            VoxelRow row;
            row.caseName = name;
            row.grid = grid;
            row.subcells = s;
            row.voxelSeconds = best;
            row.meanVs3 = total3 > 0.0 ? total / total3 : 0.0;
            row.densityErr = densityError(d, ref);
            row.lbErr = relativeL2Interior(lit(d), lit(ref));
            char line[220];
            std::snprintf(line, sizeof line,
                          "voxel %s grid %d, %d^3 sub-cells: %.3f s, total density x %.3f of 3^3, density error %.4f, LB error %.4f",
                          name.c_str(), grid, s, best, row.meanVs3, row.densityErr, row.lbErr);
            say(o, line);
            data.rows.push_back(row);
        }
    }
    finishRun(data.run);
    return data;
}

} // namespace sylva::study
