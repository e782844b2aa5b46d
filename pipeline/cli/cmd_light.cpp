// sylva light: the LB lighting of a density grid (or of a mesh voxelized first), through the grid cache.
#include <cstdio>

#include "core/base/error.h"
#include "core/lb/lb_basis.h"
#include "pipeline/cli/cli_util.h"
#include "pipeline/cli/commands.h"
#include "pipeline/cli/common_options.h"
#include "pipeline/cli/grid_options.h"
#include "pipeline/io/grid_file.h"
#include "pipeline/io/output_path.h"
#include "pipeline/lighting_job.h"
#include "pipeline/services/grid_stats.h"

#if SYLVA_HAVE_MPI
#include "pipeline/mpi/mpi_lb.h"
#include "pipeline/mpi/mpi_render.h"
#endif

namespace sylva::cli {
namespace {

// sylva light's defaults on the measured front: fp16, 1 x the longest edge, unless
// --seed-steps (the seed's fp32, 2 x the longest edge), --steps/--tol or --fp32 say otherwise. Parameters
// fp16 cannot hold (a large intensity) fall back to fp32 with a note.
void applyLightDefaults(const Args& args, lb::LbParams& p)
{
    if (args.has("--seed-steps") && (args.has("--steps") || args.has("--tol")))
        throw UsageError("--seed-steps and --steps/--tol exclude each other");
    if (args.has("--fp32") && args.has("--fp16")) throw UsageError("--fp16 and --fp32 exclude each other");
    if (args.has("--seed-steps")) {
        p.stepsPerEdge = 2;
        if (!args.has("--fp16")) p.storage = lb::Storage::Fp32;
        return;
    }
    const lb::Storage asked = p.storage;
    lb::useFrontDefaults(p);
    if (args.has("--fp32")) p.storage = lb::Storage::Fp32;
    else if (asked == lb::Storage::Fp32 && !args.has("--fp16")) {
        try {
            lb::validate(p);
        } catch (const Error&) {
            p.storage = lb::Storage::Fp32;   // e.g. an intensity over fp16's range
            std::fprintf(stderr, "note: fp32 storage (these parameters do not fit the default fp16)\n");
        }
    }
}

int writeLight(const Args& args, const lb::LbParams& params, const DensityGrid& density, const LightingGrid& light, const JobLog& log,
               const std::string& part, const std::string& out, const PictureOptions& picture);

// --mpi: the checks before anything is loaded (usage errors on every rank alike).
void checkMpiLight(const Args& args, const lb::LbParams& params)
{
    if (!args.has("--mpi")) {
        if (args.has("--mpi-timeout")) throw UsageError("option --mpi-timeout: applies to --mpi only");
        return;
    }
#if SYLVA_HAVE_MPI
    if (!mpi::launchedByMpi())
        throw UsageError("option --mpi: this process was not started by mpirun; run: mpirun -np N sylva light --mpi ... "
                         "(docs/DISTRIBUTED.md), or drop --mpi");
    if (args.has("--basis")) throw UsageError("option --mpi: --basis is not distributed; drop one of them");
    if (params.tolerance > 0.0 || params.coarseStart)
        throw UsageError("option --mpi: the distributed grid runs a fixed step count; drop --tol and --coarse-start");
    if (backendName(args) == "cuda") std::fprintf(stderr, "note: --mpi solves each rank's slab on its CPU\n");
#else
    (void)params;
    throw UsageError("option --mpi: this sylva was built without MPI (configure with -DSYLVA_ENABLE_MPI=ON where an MPI "
                     "library is installed, e.g. Debian's libopenmpi-dev)");
#endif
}

int runLight(const Args& args)
{
    auto threads = threadLimit(args);
    const bool useMpi = args.has("--mpi");
    if (args.has("--density") == args.has("--mesh")) throw UsageError("'sylva light' needs exactly one of --density FILE or --mesh FILE");
    auto compute = openBackend(backendName(args));
    lb::LbParams params = lightParams(args);
    applyLightDefaults(args, params);
    checkMpiLight(args, params);
    auto cache = openCache(args);
    if (args.has("--basis") && !cache) throw UsageError("--basis stores the relighting basis in the grid cache; it cannot be used with --no-cache");
    if (args.has("--basis") && params.tolerance > 0.0)
        throw UsageError("--basis needs fixed steps (a tolerance solve is not linear in the boundary); drop --tol");
    const std::string part = args.get("--part", "all");
    if (part != "all" && part != "scattered" && part != "uncollided")
        throw UsageError("option --part: expected all, scattered or uncollided, got '" + part + "'");
    JobLog log;
    VoxelizeSettings voxel = voxelSettings(args);
    voxel.solid = args.has("--solid");   // plastics: the interior filled (winding numbers), as sylva voxelize --solid
    rejectMeshOptionsWithDensity(args);
    const PictureOptions picture = pictureOptions(args);
    const std::string out = outputFile(args, gridFileExtensions());
#if SYLVA_HAVE_MPI
    const bool writer = !useMpi || mpi::launchRank() == 0;   // --mpi: rank 0 writes
#else
    const bool writer = true;
#endif
    if (writer) requireReplaceableFile(out);
    const DensityGrid density = loadDensityInput(args, voxel, cache.get(), log);
    if (writer) printDensitySummary(density);
    ProgressPrinter bar("light", args.has("--quiet") || !writer);
    LightingGrid light;
    if (useMpi) {
#if SYLVA_HAVE_MPI
        // Every rank holds the density and one slab of the distributions; rank 0 gathers and writes.
        const double timeout = args.has("--mpi-timeout") ? double(parseInteger("--mpi-timeout", args.get("--mpi-timeout"), 1, 86400)) : 10.0;
        return mpi::runLightSession(
            [&](int rank, int ranks) {
                mpi::DistributedStats st;
                light = mpi::solveDistributed(density, params, rank == 0 ? &bar.progress() : nullptr, &st);
                if (part != "all") {
                    const LightingGrid uncollided = mpi::solveDistributed(density, lb::uncollidedParams(params), nullptr, nullptr);
                    if (rank == 0) light = part == "uncollided" ? uncollided : lb::scatteredPart(light, uncollided);
                }
                if (rank != 0) return int(kOk);
                char line[200];
                std::snprintf(line, sizeof line, "LB on %d %s, %d steps (%d planes and 2 halo planes of %.3g MB on rank 0), %.2f s", ranks,
                              ranks == 1 ? "rank" : "ranks", st.steps, st.ownedPlanes, double(st.planeBytes) / 1e6, st.seconds);
                bar.finish(line);
                return writeLight(args, params, density, light, log, part, out, picture);
            },
            timeout);
#endif
    }
    if (args.has("--basis")) {
        const LightingBasis basis = lightingBasisFor(density, params, cache.get(), &bar.progress(), &log, compute.get());
        light = relight(basis, params);
        bar.finish("relit from the basis");
        std::printf("relighting basis: %zu directions, %.1f MB in memory (fp32 grids), in the cache for later --sun\n",
                    basis.grids.size(), basisBytes(basis) / 1e6);
    } else {
        light = lightingFor(density, params, cache.get(), &bar.progress(), &log, compute.get());
        bar.finish(log.stages.back());
    }
    if (part != "all") {
        // The first collision separated: the same LB with scattering off is the uncollided light.
        ProgressPrinter ubar("uncollided", args.has("--quiet"));
        JobLog ulog;
        const LightingGrid uncollided = lightingFor(density, lb::uncollidedParams(params), cache.get(), &ubar.progress(), &ulog, compute.get());
        ubar.finish(ulog.stages.back());
        light = part == "uncollided" ? uncollided : lb::scatteredPart(light, uncollided);
    }
    return writeLight(args, params, density, light, log, part, out, picture);
}

// The lighting grid's file, its summary line and the picture.
int writeLight(const Args& args, const lb::LbParams& params, const DensityGrid& density, const LightingGrid& light, const JobLog& log,
               const std::string& part, const std::string& out, const PictureOptions& picture)
{
    for (const auto& w : log.warnings) std::fprintf(stderr, "warning: %s\n", w.c_str());
    // The sidecar records what produced the grid: the optics actually used (after any overrides).
    // A .vdb holds the density beside the lighting (one file for a renderer); .npy the lighting alone.
    std::string sidecar = lightingParamsJson(params, args.get("--preset", "leaf"), density.geometry.dims);
    if (part != "all") sidecar.insert(sidecar.size() - 1, ",\"part\":\"" + part + "\"");
    writeLightingFile(out, light, sidecar, &density);
    const ChannelStats s = channelStats(light);
    std::printf("lighting grid %s: mean RGB (%.4f, %.4f, %.4f), max RGB (%.4f, %.4f, %.4f)\nwrote %s\n",
                gridDimsText(light.geometry).c_str(), s.mean.x, s.mean.y, s.mean.z, s.max.x, s.max.y, s.max.z, out.c_str());
    writePicture(picture, &density, &light);
    return kOk;
}

} // namespace

Command lightCommand()
{
    return {"light", "(--density DENSITY.npy|.vdb | --mesh MESH) (--sun X,Y,Z | --sun-at DATE,TIME,ZONE,LAT,LON) -o LIGHT.npy|.vdb",
            "solve the lattice-Boltzmann lighting of a density grid",
            {{"--density", "FILE", "density grid: .npy from sylva voxelize, or .vdb (the float grid 'density', else the first float grid)"},
             {"--mesh", "FILE", "mesh to voxelize first (with --grid)"},
             kGrid, kSubcells, kLeafMaterials,
             {"--solid", "", "with --mesh: voxelize it as a solid (interior filled, as sylva voxelize --solid; e.g. --preset pmma)"},
             {"--preset", "NAME", "leaf (default), dogrose, cloud or pmma"},
             {"--sigma-a", "R,G,B", "absorption per lattice step (one number: all channels)"},
             {"--sigma-s", "R,G,B", "scattering per lattice step; sigma_a + sigma_s <= 1"},
             {"--g", "R,G,B", "Henyey-Greenstein asymmetry in [-1, 1]"},
             {"--keep-f0", "", "keep absorbed light (clouds, plastics)"},
             {"--zero-f0", "", "zero f_0 after each step (plants)"},
             {"--sun", "X,Y,Z", "direction toward the sun (any length)"},
             kSunAt,
             {"--intensity", "R,G,B", "sun intensity per channel (default 1)"},
             {"--steps", "N", "fixed step count (default 1 x the longest grid edge, fp16: a point on the measured front, "
                              "0.9% relative L2 from the seed's configuration on the 128^3 benchmark crown)"},
             {"--seed-steps", "", "the seed's configuration: 2 x the longest edge in fp32 (with --fp16: in fp16)"},
             {"--fp32", "", "store the distributions in single precision (the default is fp16)"},
             {"--basis", "", "solve (or load) the relighting basis (18 solves, one per lattice direction) into the cache and "
                             "compose --sun from it; later runs of any --sun on this grid and optics relight from it, no solve"},
             {"--part", "all|scattered|uncollided", "all light (default, the seed's), only the scattered part (the "
                                                    "renderer's shadow rays draw the direct sun), or only the uncollided sunlight"},
             {"--tol", "T", "stop when the relative change per step falls under T"},
             {"--fp16", "", "store the distributions in half precision (the default; with --seed-steps half the memory)"},
             {"--warm-start", "", "start from the unobstructed light field: same steady state, fewer steps"},
             {"--coarse-start", "", "with --tol: solve on half-resolution grids first and start from that (fastest to a given error)"},
             kBackend,
             {"--output", "FILE", "output file (also -o): .npy (+ sidecar), or .vdb (lighting, its channels, density and wood fraction)"},
             kPicture, kSlices, kAxis, kCache, kNoCache, kThreads, kQuiet,
             {"--mpi", "", "solve the grid in slabs along x across the ranks of an MPI job, halo planes exchanged every step, the "
                           "single-process result to the bit: mpirun -np N sylva light --mpi ... (fixed steps; docs/DISTRIBUTED.md)"},
             {"--mpi-timeout", "S", "with --mpi: end the job when a neighbour's halo is S seconds (plus 3 x the slowest step) late (default 10)"}},
            0, 0, &runLight};
}

} // namespace sylva::cli
