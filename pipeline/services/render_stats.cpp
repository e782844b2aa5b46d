// Acceleration structure sizes per triangle and per instance (render_stats.h).
#include "pipeline/services/render_stats.h"

#include <algorithm>
#include <cstdio>

namespace sylva {

AccelSummary summarizeAccel(const AccelStats& st)
{
    AccelSummary s;
    s.totalBytes = double(st.tlasBytes + st.instanceBytes + st.blasBytes + st.triangleBytes + st.wideTlasBytes + st.wideBlasBytes);
    s.bytesPerInstancedTriangle = s.totalBytes / std::max(1.0, st.instancedTriangles);
    s.bytesPerInstance = double(st.tlasBytes + st.instanceBytes) / double(std::max<size_t>(1, st.instances));
    return s;
}

std::string forestGridLine(const ForestGridStats& f, const LandscapeLightStats& l)
{
    if (std::string(f.mode) == "off") return "";
    char line[400];
    std::string landscape;
    if (l.solved) {
        std::snprintf(line, sizeof line,
                      "forest grid over the landscape (%s): resolution %d, %dx%dx%d nodes of %.3g m, %.3g plants growing in %zu cells "
                      "(%.3g tested%s), built and solved in %.3f s; factors %.3f / %.3f / %.3f (min / median / max over cells), spread "
                      "%.1f%%; %s\n",
                      f.mode, l.resolution, l.dims.x, l.dims.y, l.dims.z, l.spacing, l.plantsGrowing, l.cells, l.plantsTested,
                      l.stride > 1 ? (": 1 in " + std::to_string(l.stride) + " of each tile's plants").c_str() : "", l.seconds, double(l.minFactor),
                      double(l.medianFactor), double(l.maxFactor), 100.0 * double(l.spread),
                      l.applied ? "applied" : "skipped (exposure uniform: spread under 2%)");
        landscape = line;
    } else if (l.skipped) {
        landscape = std::string("forest grid over the landscape (") + f.mode + "): no growing plant of a species with a density grid, skipped\n";
    }
    if (!f.solved && !landscape.empty()) return landscape;   // a landscape without top-level instances
    if (!f.solved) {
        std::snprintf(line, sizeof line, "forest grid (%s): no instance of a species with a density grid, %s\n", f.mode,
                      f.skipped ? "skipped" : "not built");
        return line;
    }
    std::snprintf(line, sizeof line,
                  "forest grid (%s): resolution %d, %dx%dx%d nodes of %.3g m, %zu instances, built and solved in %.3f s; factors "
                  "%.3f / %.3f / %.3f (min / median / max over instances), per face %.3f-%.3f, spread %.1f%%; %s\n",
                  f.mode, f.resolution, f.dims.x, f.dims.y, f.dims.z, f.spacing, f.plants, f.seconds, double(f.minFactor),
                  double(f.medianFactor), double(f.maxFactor), double(f.minFaceFactor), double(f.maxFaceFactor), 100.0 * double(f.spread),
                  f.applied ? "applied" : "skipped (exposure uniform: spread under 2%)");
    return line + landscape;
}

} // namespace sylva
