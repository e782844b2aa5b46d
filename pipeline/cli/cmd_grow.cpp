// sylva grow: a procedural tree written as OBJ + MTL + textures.
#include <cstdio>

#include "core/base/param_spec.h"
#include "pipeline/cli/cli_util.h"
#include "pipeline/cli/commands.h"
#include "pipeline/cli/common_options.h"
#include "pipeline/grow/obj_writer.h"
#include "pipeline/grow/tree_grower.h"
#include "pipeline/io/output_path.h"
#include "pipeline/services/mesh_stats.h"

namespace sylva::cli {
namespace {

int runGrow(const Args& args)
{
    auto threads = threadLimit(args);
    GrowOptions opt;
    opt.targetTriangles = 200000;
    if (args.has("--species") && !parseSpecies(args.get("--species"), &opt.species)) {
        std::string names;
        for (const auto& n : speciesNames()) names += (names.empty() ? "" : ", ") + n;
        throw UsageError("option --species: unknown species '" + args.get("--species") + "' (known: " + names + ")");
    }
    if (args.has("--seed")) opt.seed = uint64_t(parseInteger("--seed", args.get("--seed"), 0, (long long)kMaxSeed));
    if (args.has("--triangles"))
        opt.targetTriangles = size_t(parseInteger("--triangles", args.get("--triangles"), kMinGrowTriangles, kMaxGrowTriangles));
    if (args.has("--height")) {
        opt.height = float(parseNumber("--height", args.get("--height")));
        if (!(opt.height > 0.0f)) throw UsageError("option --height: must be > 0 metres");
    }
    const std::string out = outputFile(args, {".obj"}, speciesName(opt.species) + ".obj");
    requireReplaceableFile(out);
    ProgressPrinter bar("grow", args.has("--quiet"));
    GrownTree tree = growTree(opt, &bar.progress());
    writeObj(out, tree);
    const MeshStats s = meshStats(tree.mesh);
    bar.finish();
    std::printf("%s: %s tree, seed %llu, %zu triangles (%zu leaf, %zu wood), %.2f m tall, %.2f m wide\n", out.c_str(),
                speciesName(opt.species).c_str(), (unsigned long long)opt.seed, s.triangles, s.leafTriangles, s.woodTriangles,
                s.height(), s.width());
    return kOk;
}

} // namespace

Command growCommand()
{
    return {"grow", "[-o TREE.obj]", "grow a procedural tree; writes OBJ + MTL + leaf and bark textures",
            {{"--species", "NAME", "broadleaf (default), birch, conifer or shrub"},
             {"--seed", "N", "random seed (default 1); the same seed gives the same tree"},
             {"--triangles", "N", "target triangle count, 1000..1000000 (default 200000)"},
             {"--height", "M", "tree height in metres (default: by species)"},
             kOutput, kThreads, kQuiet},
            0, 0, &runGrow};
}

} // namespace sylva::cli
