// sylva study: speed knobs against accuracy; regenerates ACCURACY.md (pipeline/study does the work).
#include <cstdio>

#include "pipeline/cli/cli_util.h"
#include "pipeline/cli/commands.h"
#include "pipeline/cli/common_options.h"
#include "pipeline/study/study.h"

namespace sylva::cli {
namespace {

int runStudy(const Args& args)
{
    auto threads = threadLimit(args);
    study::Options o;
    const std::string what = args.positional()[0];
    if (what == "all") {
        o.parts = {study::Part::Lb, study::Part::Voxel, study::Part::Render, study::Part::Scene, study::Part::Truth, study::Part::Sky};
    } else if (what != "report") {
        study::Part part;
        if (!study::parsePart(what, &part)) throw UsageError("expected lb, voxel, render, scene, truth, sky, all or report, got '" + what + "'");
        o.parts = {part};
    }
    o.outDir = args.get("--out", "docs");
    o.quick = args.has("--quick");
    o.treeMesh = args.get("--tree");
    auto cache = openCache(args);
    o.cache = cache.get();
    const bool quiet = args.has("--quiet");
    o.log = [quiet](const std::string& line) {
        if (!quiet) std::fprintf(stderr, "%s\n", line.c_str());
    };
    const study::Result r = study::run(o);
    std::printf("wrote %s and %zu plots in %.0f s\n", r.markdown.c_str(), r.plots.size(), r.seconds);
    if (!r.plotNote.empty()) std::printf("plots skipped: %s\n", r.plotNote.c_str());
    return kOk;
}

} // namespace

Command studyCommand()
{
    return {"study", "lb|voxel|render|scene|truth|sky|all|report [--out DIR] [--quick]",
            "measure speed against accuracy; regenerate ACCURACY.md with tables and plots (report: from stored numbers; scene: the forest-level grid against per-instance solves and the relighting basis against direct solves; truth: against Blender's Cycles, skipped without `blender` or with --quick; sky: virtual lights x subsets x spp under three skies, the LB with the sky in its boundary against Monte Carlo)",
            {{"--out", "DIR", "folder of ACCURACY.md; plots and numbers go to DIR/accuracy (default docs)"},
             {"--quick", "", "small grids, fewer paths and samples: a few minutes"},
             {"--tree", "MESH", "the real tree (default resources/trees/quaternius/OBJ/Tree_1.obj)"},
             kCache, kNoCache, kThreads, kQuiet},
            1, 1, &runStudy};
}

} // namespace sylva::cli
