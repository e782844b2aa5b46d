// Solid voxelization: the surface voxelizer finds the cells triangles meet; winding numbers fill the rest.
#include "core/voxel/solid_voxelize.h"

#include <atomic>
#include <cmath>
#include <mutex>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "core/base/progress.h"
#include "core/voxel/winding_number.h"

namespace sylva {

DensityGrid voxelizeSolid(const TriangleMesh& mesh, const VoxelizeSettings& settings, Progress* progress)
{
    VoxelizeSettings surfaceSettings = settings;
    surfaceSettings.solid = false;
    SubProgress surfaceProgress(progress, 0.0, 0.1);
    Progress inner([&](double f, const std::string&) { surfaceProgress.report(f, "voxelizing (surface)"); });
    DensityGrid grid = voxelize(mesh, surfaceSettings, progress ? &inner : nullptr);
    const GridGeometry& g = grid.geometry;
    const WindingNumber winding(mesh);
    const int sc = settings.subcells;
    const double sub = g.spacing / double(sc);
    std::fill(grid.woodFraction.begin(), grid.woodFraction.end(), 0.0f);

    std::atomic<int> slabsDone{0};
    std::mutex reportMutex;
    int reported = 0;
    tbb::parallel_for(tbb::blocked_range<int>(1, g.dims.x - 1), [&](const tbb::blocked_range<int>& r) {
        for (int i = r.begin(); i != r.end(); ++i) {
            if (progress) progress->throwIfCancelled();
            for (int j = 1; j < g.dims.y - 1; ++j)
                for (int k = 1; k < g.dims.z - 1; ++k) {
                    const size_t n = g.index(i, j, k);
                    const glm::dvec3 centre = g.origin + g.spacing * glm::dvec3(i, j, k);
                    if (grid.density[n] == 0.0f) {
                        grid.density[n] = std::fabs(winding(centre)) >= kSolidInsideThreshold ? 1.0f : 0.0f;
                        continue;
                    }
                    int inside = 0;
                    for (int a = 0; a < sc; ++a)
                        for (int b = 0; b < sc; ++b)
                            for (int c = 0; c < sc; ++c) {
                                const glm::dvec3 p = centre + sub * (glm::dvec3(a, b, c) + 0.5 - 0.5 * double(sc));
                                if (std::fabs(winding(p)) >= kSolidInsideThreshold) ++inside;
                            }
                    grid.density[n] = float(inside) / float(sc * sc * sc);
                }
            if (progress) {
                const int done = ++slabsDone;
                std::lock_guard lock(reportMutex);
                const int step = int(50.0 * double(done) / double(g.dims.x - 2));
                if (step > reported) {
                    reported = step;
                    progress->report(0.1 + 0.9 * double(done) / double(g.dims.x - 2), "voxelizing (solid)");
                }
            }
        }
    });
    if (progress) progress->report(1.0, "voxelizing (solid)");
    return grid;
}

} // namespace sylva
