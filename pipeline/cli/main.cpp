// sylva: the command line (grow, voxelize, light, reference, render, study, info). Exit codes: 0 ok, 1 bad input or failure, 2 bad usage.
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <map>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include <tbb/global_control.h>

#include "core/base/error.h"
#include "core/base/version.h"
#include "core/lb/lb_params.h"
#include "core/lb/lb_solver.h"
#include "core/reference/mc_reference.h"
#include "core/voxel/voxelize.h"
#include "pipeline/backend_info.h"
#include "pipeline/backend_select.h"
#include "pipeline/cache/grid_cache.h"
#include "pipeline/cli/cli_util.h"
#include "pipeline/grow/obj_writer.h"
#include "pipeline/grow/tree_grower.h"
#include "pipeline/import/mesh_import.h"
#include "pipeline/io/grid_picture.h"
#include "pipeline/io/npy.h"
#include "pipeline/io/output_path.h"
#include "pipeline/lighting_job.h"
#include "core/scene/quality.h"
#include "pipeline/render/render_job.h"
#include "pipeline/scene/scene_file.h"
#include "pipeline/study/study.h"

namespace fs = std::filesystem;
using namespace sylva;
using namespace sylva::cli;

namespace {

// One option of a subcommand: --name VALUE, or a flag when value is empty.
struct OptionSpec {
    std::string name;
    std::string value;   // placeholder shown in help; empty for flags
    std::string help;
};

struct Command {
    std::string name;
    std::string synopsis;
    std::string summary;
    std::vector<OptionSpec> options;
    int minPositional = 0, maxPositional = 0;
};

// Parsed arguments of one subcommand.
class Args {
public:
    Args(const Command& cmd, const std::vector<std::string>& argv) : m_cmd(cmd)
    {
        for (size_t a = 0; a < argv.size(); ++a) {
            std::string s = argv[a];
            if (s == "-h" || s == "--help") {
                m_help = true;
                continue;
            }
            if (s.size() > 1 && s[0] == '-' && !(s.size() > 1 && (std::isdigit((unsigned char)s[1]) || s[1] == '.'))) {
                std::string name = s, value;
                const size_t eq = s.find('=');
                const bool inlineValue = eq != std::string::npos;
                if (inlineValue) {
                    name = s.substr(0, eq);
                    value = s.substr(eq + 1);
                }
                if (name == "-o") name = "--output";
                const OptionSpec* spec = find(name);
                if (!spec) throw UsageError("unknown option " + name + " for 'sylva " + cmd.name + "' (see sylva " + cmd.name + " --help)");
                if (spec->value.empty()) {
                    if (inlineValue) throw UsageError("option " + name + " takes no value");
                    m_values[name] = "1";
                } else {
                    if (!inlineValue) {
                        if (a + 1 >= argv.size()) throw UsageError("option " + name + " needs a value (" + spec->value + ")");
                        value = argv[++a];
                    }
                    if (value.empty()) throw UsageError("option " + name + ": empty value");
                    m_values[name] = value;
                }
            } else {
                m_positional.push_back(s);
            }
        }
        if (m_help) return;
        if (int(m_positional.size()) < cmd.minPositional) throw UsageError("'sylva " + cmd.name + "' needs " + cmd.synopsis);
        if (int(m_positional.size()) > cmd.maxPositional)
            throw UsageError("unexpected argument '" + m_positional[size_t(cmd.maxPositional)] + "' for 'sylva " + cmd.name + "'");
    }
    bool help() const { return m_help; }
    bool has(const std::string& name) const { return m_values.count(name) != 0; }
    std::string get(const std::string& name, const std::string& fallback = {}) const
    {
        auto it = m_values.find(name);
        return it == m_values.end() ? fallback : it->second;
    }
    std::string require(const std::string& name) const
    {
        if (!has(name)) throw UsageError("'sylva " + m_cmd.name + "' needs " + name + " (see sylva " + m_cmd.name + " --help)");
        return get(name);
    }
    const std::vector<std::string>& positional() const { return m_positional; }

private:
    const OptionSpec* find(const std::string& name) const
    {
        for (const auto& o : m_cmd.options)
            if (o.name == name) return &o;
        return nullptr;
    }
    const Command& m_cmd;
    std::map<std::string, std::string> m_values;
    std::vector<std::string> m_positional;
    bool m_help = false;
};

const OptionSpec kQuiet{"--quiet", "", "no progress output"};
const OptionSpec kThreads{"--threads", "N", "worker threads (default: all cores)"};
const OptionSpec kOutput{"--output", "FILE", "output file (also -o)"};
const OptionSpec kCache{"--cache", "DIR", "grid cache folder (default $XDG_CACHE_HOME/sylva or ~/.cache/sylva)"};
const OptionSpec kNoCache{"--no-cache", "", "neither read nor write the grid cache"};
const OptionSpec kLeafMaterials{"--leaf-materials", "A,B", "names of the leaf materials (override the automatic leaf/wood split)"};
const OptionSpec kGrid{"--grid", "N|X,Y,Z", "grid nodes on the longest axis, or per axis (3..512; default 128)"};
const OptionSpec kSubcells{"--subcells", "N", "sub-cells per cell edge for the density (default 3)"};
const OptionSpec kPicture{"--picture", "PNG", "also write a PNG montage of slices"};
const OptionSpec kSlices{"--slices", "N", "slices in the picture (default 8)"};
const OptionSpec kAxis{"--axis", "x|y|z", "slicing axis of the picture (default z)"};

std::vector<Command> commands()
{
    std::vector<Command> list;
    list.push_back({"grow", "[-o TREE.obj]", "grow a procedural tree; writes OBJ + MTL + leaf and bark textures",
                    {{"--species", "NAME", "broadleaf (default), birch, conifer or shrub"},
                     {"--seed", "N", "random seed (default 1); the same seed gives the same tree"},
                     {"--triangles", "N", "target triangle count, 1000..1000000 (default 200000)"},
                     {"--height", "M", "tree height in metres (default: by species)"},
                     kOutput, kThreads, kQuiet},
                    0, 0});
    list.push_back({"voxelize", "MESH -o DENSITY.npy", "voxelize a mesh into a density grid (+ wood fraction)",
                    {kGrid, kSubcells, kLeafMaterials, kOutput, kPicture, kSlices, kAxis, kCache, kNoCache, kThreads, kQuiet},
                    1, 1});
    list.push_back({"light", "(--density DENSITY.npy | --mesh MESH) --sun X,Y,Z -o LIGHT.npy",
                    "solve the lattice-Boltzmann lighting of a density grid",
                    {{"--density", "FILE", "density grid (.npy from sylva voxelize)"},
                     {"--mesh", "FILE", "mesh to voxelize first (with --grid)"},
                     kGrid, kSubcells, kLeafMaterials,
                     {"--preset", "NAME", "leaf (default), dogrose, cloud or pmma"},
                     {"--sigma-a", "R,G,B", "absorption per lattice step (one number: all channels)"},
                     {"--sigma-s", "R,G,B", "scattering per lattice step; sigma_a + sigma_s <= 1"},
                     {"--g", "R,G,B", "Henyey-Greenstein asymmetry in [-1, 1]"},
                     {"--keep-f0", "", "keep absorbed light (clouds, plastics)"},
                     {"--zero-f0", "", "zero f_0 after each step (plants)"},
                     {"--sun", "X,Y,Z", "direction toward the sun (any length)"},
                     {"--intensity", "R,G,B", "sun intensity per channel (default 1)"},
                     {"--steps", "N", "fixed step count (default 2 x the longest grid edge)"},
                     {"--tol", "T", "stop when the relative change per step falls under T"},
                     {"--fp16", "", "store the distributions in half precision (half the memory)"},
                     {"--warm-start", "", "start from the unobstructed light field: same steady state, fewer steps"},
                     {"--coarse-start", "", "with --tol: solve on half-resolution grids first and start from that (fastest to a given error)"},
                     {"--backend", "auto|cpu|cuda", "compute backend (default auto)"},
                     kOutput, kPicture, kSlices, kAxis, kCache, kNoCache, kThreads, kQuiet},
                    0, 0});
    list.push_back({"reference", "(--density DENSITY.npy | --mesh MESH) --sun X,Y,Z -o REF.npy",
                    "Monte Carlo reference lighting (slow; measures the LB model): mean and standard error",
                    {{"--density", "FILE", "density grid (.npy from sylva voxelize)"},
                     {"--mesh", "FILE", "mesh to voxelize first (with --grid)"},
                     kGrid, kSubcells, kLeafMaterials,
                     {"--preset", "NAME", "leaf (default), dogrose, cloud or pmma (the optics of sylva light)"},
                     {"--sigma-a", "R,G,B", "absorption per lattice step (one number: all channels)"},
                     {"--sigma-s", "R,G,B", "scattering per lattice step; sigma_a + sigma_s <= 1"},
                     {"--g", "R,G,B", "Henyey-Greenstein asymmetry in [-1, 1]"},
                     {"--keep-f0", "", "absorbed light is re-emitted isotropically (clouds, plastics)"},
                     {"--zero-f0", "", "absorbed light is removed (plants)"},
                     {"--sun", "X,Y,Z", "direction toward the sun (any length)"},
                     {"--intensity", "R,G,B", "sun intensity per channel (default 1)"},
                     {"--paths", "N", "paths per channel (default 1000000); the error falls as 1/sqrt(N)"},
                     {"--seed", "S", "random seed (default 1); the same seed gives the same bits"},
                     {"--max-bounces", "K", "scattering events per path (default unlimited; 0: direct light only)"},
                     {"--collimated", "", "one beam along the sun instead of the LB's 18 lattice beams"},
                     {"--compare", "LIGHT.npy", "print the normalized error of this LB grid against the reference"},
                     kOutput, kCache, kNoCache, kThreads, kQuiet},
                    0, 0});
    list.push_back({"render", "[SCENE.sylva.json] [-o OUT.png|.exr|.tif]",
                    "render a scene (the bundled default forest when none is given)",
                    {{"--quality", "preview|final|reference", "quality preset: LB grid, steps and storage of every species, samples and distance knobs (docs/ACCURACY.md); the options below override it"},
                     {"--width", "W", "image width in pixels (default: the scene's)"},
                     {"--height", "H", "image height in pixels (default: the scene's)"},
                     {"--spp", "N", "samples per pixel, 1..4096 (default: the scene's)"},
                     {"--mode", "M", "full (LB indirect + sun), local (sun only), ambient (sun + matched constant), lb"},
                     {"--accel", "bvh|kdtree", "acceleration structure (default: the scene's, bvh)"},
                     {"--no-shadows", "", "no shadow rays"},
                     {"--alpha-distance", "M", "skip leaf cut-out tests beyond M metres from the camera (0: off, default)"},
                     {"--prune-distance", "M", "prune leaves of plants beyond M metres, area-preserving (0: off, default)"},
                     {"--backend", "auto|cpu|cuda", "compute backend (default auto)"},
                     {"--band-rows", "N", "trace and write the frame in bands of N rows (default: only when the whole frame does not fit in memory)"},
                     {"--stats", "", "print timings and acceleration structure sizes"},
                     kOutput, kCache, kNoCache, kThreads, kQuiet},
                    0, 1});
    list.push_back({"study", "lb|voxel|render|all|report [--out DIR] [--quick]",
                    "measure speed against accuracy; regenerate ACCURACY.md with tables and plots (report: from stored numbers)",
                    {{"--out", "DIR", "folder of ACCURACY.md; plots and numbers go to DIR/accuracy (default docs)"},
                     {"--quick", "", "small grids, fewer paths and samples: a few minutes"},
                     {"--tree", "MESH", "the real tree (default ../shared/data/trees/quaternius/OBJ/Tree_1.obj)"},
                     kCache, kNoCache, kThreads, kQuiet},
                    1, 1});
    list.push_back({"info", "FILE", "print what a scene (.json), mesh, grid (.npy) or cache file holds", {}, 1, 1});
    return list;
}

void printMainHelp()
{
    std::printf("sylva %s: forests with lattice-Boltzmann lighting\n\nusage: sylva COMMAND [options]\n\ncommands:\n",
                versionString());
    for (const auto& c : commands()) std::printf("  %-10s %s\n", c.name.c_str(), c.summary.c_str());
    std::printf("\n  sylva COMMAND --help   options of a command\n  sylva --version        version and compute backends\n");
}

void printHelp(const Command& c)
{
    std::printf("usage: sylva %s %s\n\n%s\n", c.name.c_str(), c.synopsis.c_str(), c.summary.c_str());
    if (!c.options.empty()) std::printf("\noptions:\n");
    for (const auto& o : c.options) {
        std::string left = o.name + (o.value.empty() ? "" : " " + o.value);
        std::printf("  %-24s %s\n", left.c_str(), o.help.c_str());
    }
    std::printf("  %-24s %s\n", "-h, --help", "this help");
}

std::unique_ptr<tbb::global_control> threadLimit(const Args& args)
{
    if (!args.has("--threads")) return nullptr;
    const long long n = parseInteger("--threads", args.get("--threads"), 1, 1024);
    return std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism, size_t(n));
}

std::unique_ptr<GridCache> openCache(const Args& args)
{
    if (args.has("--no-cache")) return nullptr;
    return std::make_unique<GridCache>(args.get("--cache"));
}

void requireReadable(const std::string& path, const char* what)
{
    std::error_code ec;
    if (!fs::exists(path, ec)) throw Error(path + ": no such " + std::string(what));
    if (fs::is_directory(path, ec)) throw Error(path + ": is a folder, not a " + std::string(what));
}

VoxelizeSettings voxelSettings(const Args& args)
{
    VoxelizeSettings v;
    if (args.has("--grid")) {
        const std::vector<std::string> parts = splitList(args.get("--grid"));
        if (parts.size() == 1) {
            v.longestAxisNodes = int(parseInteger("--grid", parts[0], 3, 512));
        } else if (parts.size() == 3) {
            v.dims = {int(parseInteger("--grid", parts[0], 3, 512)), int(parseInteger("--grid", parts[1], 3, 512)),
                      int(parseInteger("--grid", parts[2], 3, 512))};
        } else {
            throw UsageError("option --grid: expected N or X,Y,Z, got '" + args.get("--grid") + "'");
        }
    }
    if (args.has("--subcells")) v.subcells = int(parseInteger("--subcells", args.get("--subcells"), 1, 16));
    return v;
}

ImportOptions importOptions(const Args& args)
{
    ImportOptions o;
    if (args.has("--leaf-materials"))
        for (const auto& name : splitList(args.get("--leaf-materials")))
            if (!name.empty()) o.leafMaterials.push_back(name);
    return o;
}

struct PictureOptions {
    std::string path;   // empty: no picture
    int axis = 2;
    int slices = 8;
};

// Parsed and checked before any work, so a bad picture option does not cost a solve.
PictureOptions pictureOptions(const Args& args)
{
    PictureOptions o;
    if (!args.has("--picture")) {
        if (args.has("--axis") || args.has("--slices")) throw UsageError("--axis and --slices go with --picture");
        return o;
    }
    o.path = args.get("--picture");
    std::string ext = fs::path(o.path).extension().string();
    for (auto& ch : ext) ch = char(std::tolower((unsigned char)ch));
    if (ext != ".png" && ext != ".tif" && ext != ".tiff" && ext != ".exr" && ext != ".jpg")
        throw UsageError("option --picture: '" + o.path + "' needs an image extension (.png, .tif, .exr, .jpg)");
    if (args.has("--axis")) {
        const std::string a = args.get("--axis");
        if (a == "x") o.axis = 0;
        else if (a == "y") o.axis = 1;
        else if (a == "z") o.axis = 2;
        else throw UsageError("option --axis: expected x, y or z, got '" + a + "'");
    }
    if (args.has("--slices")) o.slices = int(parseInteger("--slices", args.get("--slices"), 1, 64));
    requireReplaceableFile(o.path);
    return o;
}

void writePicture(const PictureOptions& o, const DensityGrid* density, const LightingGrid* light)
{
    if (o.path.empty()) return;
    writeGridMontage(o.path, density, light, o.axis, o.slices, 256);
    std::printf("picture: %s\n", o.path.c_str());
}


std::string dimsText(const GridGeometry& g)
{
    return std::to_string(g.dims.x) + "x" + std::to_string(g.dims.y) + "x" + std::to_string(g.dims.z);
}

void printDensitySummary(const DensityGrid& d)
{
    double sum = 0;
    size_t occupied = 0, brown = 0;
    for (size_t n = 0; n < d.density.size(); ++n) {
        sum += d.density[n];
        occupied += d.density[n] > 0.0f;
        brown += !d.woodFraction.empty() && d.woodFraction[n] > 0.5f && d.density[n] > 0.0f;
    }
    std::printf("density grid %s, spacing %.4g m, origin (%.4g, %.4g, %.4g): %.1f%% of nodes occupied, mean density %.4f, "
                "%zu brown nodes\n",
                dimsText(d.geometry).c_str(), d.geometry.spacing, d.geometry.origin.x, d.geometry.origin.y, d.geometry.origin.z,
                100.0 * double(occupied) / double(d.density.size()), sum / double(d.density.size()), brown);
}

int cmdGrow(const Args& args)
{
    auto threads = threadLimit(args);
    GrowOptions opt;
    opt.targetTriangles = 200000;
    if (args.has("--species") && !parseSpecies(args.get("--species"), &opt.species)) {
        std::string names;
        for (const auto& n : speciesNames()) names += (names.empty() ? "" : ", ") + n;
        throw UsageError("option --species: unknown species '" + args.get("--species") + "' (known: " + names + ")");
    }
    if (args.has("--seed")) opt.seed = uint64_t(parseInteger("--seed", args.get("--seed"), 0, (1LL << 62)));
    if (args.has("--triangles"))
        opt.targetTriangles = size_t(parseInteger("--triangles", args.get("--triangles"), kMinGrowTriangles, kMaxGrowTriangles));
    if (args.has("--height")) {
        opt.height = float(parseNumber("--height", args.get("--height")));
        if (!(opt.height > 0.0f)) throw UsageError("option --height: must be > 0 metres");
    }
    const std::string out = args.get("--output", speciesName(opt.species) + ".obj");
    requireReplaceableFile(out);
    ProgressPrinter bar("grow", args.has("--quiet"));
    GrownTree tree = growTree(opt, &bar.progress());
    writeObj(out, tree);
    size_t leaf = 0;
    for (size_t t = 0; t < tree.mesh.triangleCount(); ++t) leaf += tree.mesh.isLeafTriangle(t);
    bar.finish();
    const Bounds3 b = meshBounds(tree.mesh);
    std::printf("%s: %s tree, seed %llu, %zu triangles (%zu leaf, %zu wood), %.2f m tall, %.2f m wide\n", out.c_str(),
                speciesName(opt.species).c_str(), (unsigned long long)opt.seed, tree.mesh.triangleCount(), leaf,
                tree.mesh.triangleCount() - leaf, b.extent().y, std::max(b.extent().x, b.extent().z));
    return kOk;
}

int cmdVoxelize(const Args& args)
{
    auto threads = threadLimit(args);
    const std::string mesh = args.positional()[0];
    const std::string out = args.require("--output");
    DensityJob job{mesh, importOptions(args), voxelSettings(args)};   // usage errors before file errors
    const PictureOptions picture = pictureOptions(args);
    requireReadable(mesh, "mesh file");
    requireReplaceableFile(out);
    auto cache = openCache(args);
    ProgressPrinter bar("voxelize", args.has("--quiet"));
    JobLog log;
    const DensityGrid grid = densityForMesh(job, cache.get(), &bar.progress(), &log);
    writeDensityGrid(out, grid);
    bar.finish(log.stages.empty() ? "" : log.stages.back());
    for (const auto& w : log.warnings) std::fprintf(stderr, "warning: %s\n", w.c_str());
    printDensitySummary(grid);
    std::printf("wrote %s (+ %s, %s)\n", out.c_str(), woodFractionPath(out).c_str(), gridSidecarPath(out).c_str());
    writePicture(picture, &grid, nullptr);
    return kOk;
}

lb::LbParams lightParams(const Args& args)
{
    const std::string presetName = args.get("--preset", "leaf");
    const lb::Preset* preset = lb::findPreset(presetName);
    if (!preset) {
        std::string names;
        for (const auto& p : lb::presets()) names += (names.empty() ? "" : ", ") + p.name;
        throw UsageError("option --preset: unknown preset '" + presetName + "' (known: " + names + ")");
    }
    lb::LbParams p = lb::paramsFromPreset(*preset);
    if (args.has("--sigma-a")) {
        const glm::vec3 v = parseTriple("--sigma-a", args.get("--sigma-a"));
        for (int c = 0; c < 3; ++c) p.channels[size_t(c)].sigmaA = v[c];
    }
    if (args.has("--sigma-s")) {
        const glm::vec3 v = parseTriple("--sigma-s", args.get("--sigma-s"));
        for (int c = 0; c < 3; ++c) p.channels[size_t(c)].sigmaS = v[c];
    }
    if (args.has("--g")) {
        const glm::vec3 v = parseTriple("--g", args.get("--g"));
        for (int c = 0; c < 3; ++c) p.channels[size_t(c)].g = v[c];
    }
    if (args.has("--keep-f0") && args.has("--zero-f0")) throw UsageError("--keep-f0 and --zero-f0 exclude each other");
    if (args.has("--keep-f0")) p.zeroF0 = false;
    if (args.has("--zero-f0")) p.zeroF0 = true;
    p.sun = parseTriple("--sun", args.require("--sun"));
    if (args.get("--sun").find(',') == std::string::npos) throw UsageError("option --sun: expected X,Y,Z");
    if (args.has("--intensity")) p.intensity = parseTriple("--intensity", args.get("--intensity"));
    if (args.has("--steps") && args.has("--tol")) throw UsageError("--steps and --tol exclude each other");
    if (args.has("--steps")) p.steps = int(parseInteger("--steps", args.get("--steps"), 1, 1000000));
    if (args.has("--tol")) {
        p.tolerance = parseNumber("--tol", args.get("--tol"));
        if (!(p.tolerance > 0.0)) throw UsageError("option --tol: must be > 0");
    }
    if (args.has("--fp16")) p.storage = lb::Storage::Fp16;
    if (args.has("--warm-start")) p.warmStart = true;
    if (args.has("--coarse-start")) {
        if (!args.has("--tol")) throw UsageError("--coarse-start applies to tolerance mode (--tol T)");
        p.coarseStart = true;
    }
    lb::validate(p);   // bad parameter values are bad input (exit 1) with a message naming the bound
    return p;
}

// The density grid of `light` and `reference`: --density FILE (checked), or --mesh voxelized through
// the cache with a progress bar.
DensityGrid loadDensityInput(const Args& args, const VoxelizeSettings& voxel, GridCache* cache, JobLog& log)
{
    if (args.has("--density")) {
        const std::string path = args.get("--density");
        requireReadable(path, "density grid");
        DensityGrid density = readDensityGrid(path);
        try {
            lb::validateDensity(density);
        } catch (const Error& e) {
            throw Error(path + ": " + e.what());
        }
        return density;
    }
    requireReadable(args.get("--mesh"), "mesh file");
    ProgressPrinter vbar("voxelize", args.has("--quiet"));
    DensityGrid density = densityForMesh({args.get("--mesh"), importOptions(args), voxel}, cache, &vbar.progress(), &log);
    vbar.finish(log.stages.back());
    return density;
}

int cmdLight(const Args& args)
{
    auto threads = threadLimit(args);
    if (args.has("--density") == args.has("--mesh")) throw UsageError("'sylva light' needs exactly one of --density FILE or --mesh FILE");
    const std::string out = args.require("--output");
    const std::string backend = args.get("--backend", "auto");
    if (backend != "auto" && backend != "cpu" && backend != "cuda")
        throw UsageError("option --backend: expected auto, cpu or cuda, got '" + backend + "'");
    auto compute = selectBackend(backend, [](const std::string& note) { std::fprintf(stderr, "note: %s\n", note.c_str()); });
    const lb::LbParams params = lightParams(args);
    auto cache = openCache(args);
    JobLog log;
    const VoxelizeSettings voxel = voxelSettings(args);
    if (args.has("--density"))
        for (const char* meshOnly : {"--grid", "--subcells", "--leaf-materials"})
            if (args.has(meshOnly)) throw UsageError(std::string(meshOnly) + " applies to --mesh, not to --density");
    const PictureOptions picture = pictureOptions(args);
    requireReplaceableFile(out);
    const DensityGrid density = loadDensityInput(args, voxel, cache.get(), log);
    printDensitySummary(density);
    ProgressPrinter bar("light", args.has("--quiet"));
    const LightingGrid light = lightingFor(density, params, cache.get(), &bar.progress(), &log, compute.get());
    bar.finish(log.stages.back());
    for (const auto& w : log.warnings) std::fprintf(stderr, "warning: %s\n", w.c_str());
    // The sidecar records what produced the grid: the optics actually used (after any overrides).
    writeLightingGrid(out, light, lightingParamsJson(params, args.get("--preset", "leaf"), density.geometry.dims));
    double maxV[3] = {0, 0, 0}, mean[3] = {0, 0, 0};
    for (size_t n = 0; n < light.rgb.size() / 3; ++n)
        for (int c = 0; c < 3; ++c) {
            maxV[c] = std::max(maxV[c], double(light.rgb[n * 3 + size_t(c)]));
            mean[c] += light.rgb[n * 3 + size_t(c)];
        }
    const double nodes = double(light.rgb.size() / 3);
    std::printf("lighting grid %s: mean RGB (%.4f, %.4f, %.4f), max RGB (%.4f, %.4f, %.4f)\nwrote %s\n",
                dimsText(light.geometry).c_str(), mean[0] / nodes, mean[1] / nodes, mean[2] / nodes, maxV[0], maxV[1], maxV[2],
                out.c_str());
    writePicture(picture, &density, &light);
    return kOk;
}

// "REF.npy" -> "REF.stderr.npy" (PATH + ".stderr.npy" when PATH does not end in ".npy").
std::string standardErrorPath(const std::string& meanPath)
{
    const std::string ext = ".npy";
    if (meanPath.size() > ext.size() && meanPath.compare(meanPath.size() - ext.size(), ext.size(), ext) == 0)
        return meanPath.substr(0, meanPath.size() - ext.size()) + ".stderr.npy";
    return meanPath + ".stderr.npy";
}

int cmdReference(const Args& args)
{
    auto threads = threadLimit(args);
    if (args.has("--density") == args.has("--mesh"))
        throw UsageError("'sylva reference' needs exactly one of --density FILE or --mesh FILE");
    const std::string out = args.require("--output");
    const lb::LbParams params = lightParams(args);
    ReferenceSettings settings;
    if (args.has("--paths"))
        settings.paths = uint64_t(parseInteger("--paths", args.get("--paths"), 2, (long long)kMaxReferencePaths));
    if (args.has("--seed")) settings.seed = uint64_t(parseInteger("--seed", args.get("--seed"), 0, (1LL << 62)));
    if (args.has("--max-bounces")) settings.maxBounces = int(parseInteger("--max-bounces", args.get("--max-bounces"), 0, 1000000000));
    if (args.has("--collimated")) settings.incidence = Incidence::Collimated;
    const VoxelizeSettings voxel = voxelSettings(args);
    if (args.has("--density"))
        for (const char* meshOnly : {"--grid", "--subcells", "--leaf-materials"})
            if (args.has(meshOnly)) throw UsageError(std::string(meshOnly) + " applies to --mesh, not to --density");
    const std::string errPath = standardErrorPath(out);
    for (const std::string& target : {out, gridSidecarPath(out), errPath, gridSidecarPath(errPath)}) requireReplaceableFile(target);
    std::optional<LightingGrid> compare;
    if (args.has("--compare")) {
        requireReadable(args.get("--compare"), "lighting grid");
        compare = readLightingGrid(args.get("--compare"));
    }
    auto cache = openCache(args);
    JobLog log;
    const DensityGrid density = loadDensityInput(args, voxel, cache.get(), log);
    if (compare && compare->geometry.dims != density.geometry.dims)
        throw Error(args.get("--compare") + ": grid " + dimsText(compare->geometry) + " differs from the density grid " +
                    dimsText(density.geometry));
    printDensitySummary(density);
    ProgressPrinter bar("reference", args.has("--quiet"));
    const ReferenceResult ref = solveReference(density, params, settings, &bar.progress());
    bar.finish();
    for (const auto& w : log.warnings) std::fprintf(stderr, "warning: %s\n", w.c_str());
    // The sidecars record what produced the grids.
    std::ostringstream extra;
    extra.precision(9);
    extra << "{\"solver\":\"reference\"," << opticsJsonMembers(params, args.get("--preset", "leaf")) << ",\"paths\":" << settings.paths
          << ",\"seed\":" << settings.seed << ",\"max_bounces\":" << settings.maxBounces << ",\"incidence\":\""
          << (settings.incidence == Incidence::Collimated ? "collimated" : "lattice") << "\"";
    const std::string common = extra.str();
    writeLightingGrid(out, ref.mean, common + ",\"quantity\":\"mean fluence\"}");
    const LightingGrid seGrid{ref.mean.geometry, ref.standardError};
    writeLightingGrid(errPath, seGrid, common + ",\"quantity\":\"standard error of the mean\"}");

    LightingGrid norm = ref.mean;
    std::vector<float> normErr = ref.standardError;
    normalizeToUnobstructed(norm, params, &normErr);
    double mean[3] = {0, 0, 0};
    for (size_t n = 0; n < norm.rgb.size() / 3; ++n)
        for (int c = 0; c < 3; ++c) mean[c] += norm.rgb[n * 3 + size_t(c)];
    const double nodes = double(norm.rgb.size() / 3);
    std::printf("reference %s: %llu paths x %d channel solves in %.1f s, %.2f collisions per path; mean RGB / unobstructed "
                "(%.4f, %.4f, %.4f), relative noise %.4f (interior nodes)\nwrote %s (+ %s)\n",
                dimsText(norm.geometry).c_str(), (unsigned long long)ref.paths, ref.channelSolves, ref.seconds,
                ref.collisionsPerPath, mean[0] / nodes, mean[1] / nodes, mean[2] / nodes, relativeNoiseInterior(norm, normErr),
                out.c_str(), errPath.c_str());
    if (compare) {
        normalizeToUnobstructed(*compare, params);
        double sumLb = 0.0, sumRef = 0.0;
        for (int i = 1; i < norm.geometry.dims.x - 1; ++i)
            for (int j = 1; j < norm.geometry.dims.y - 1; ++j)
                for (int k = 1; k < norm.geometry.dims.z - 1; ++k)
                    for (int c = 0; c < 3; ++c) {
                        sumLb += compare->at(i, j, k, c);
                        sumRef += norm.at(i, j, k, c);
                    }
        const double err = relativeL2Interior(*compare, norm), noise = relativeNoiseInterior(norm, normErr);
        std::printf("%s against the reference (both / unobstructed value, interior nodes): relative L2 error %.4f "
                    "(R %.4f, G %.4f, B %.4f), reference noise %.4f, without the noise ~%.4f; mean LB / mean reference %.4f\n",
                    args.get("--compare").c_str(), err, relativeL2Interior(*compare, norm, 0), relativeL2Interior(*compare, norm, 1),
                    relativeL2Interior(*compare, norm, 2), noise, std::sqrt(std::max(0.0, err * err - noise * noise)),
                    sumRef > 0.0 ? sumLb / sumRef : 0.0);
    }
    return kOk;
}

std::string lowerExtension(const std::string& path)
{
    std::string ext = fs::path(path).extension().string();
    for (auto& ch : ext) ch = char(std::tolower((unsigned char)ch));
    return ext;
}

int cmdRender(const Args& args)
{
    auto threads = threadLimit(args);
    const std::string backend = args.get("--backend", "auto");
    if (backend != "auto" && backend != "cpu" && backend != "cuda")
        throw UsageError("option --backend: expected auto, cpu or cuda, got '" + backend + "'");
    Scene scene;
    std::string stem = "default_forest";
    if (args.positional().empty()) {
        scene = defaultScene();
    } else {
        const std::string path = args.positional()[0];
        requireReadable(path, "scene file");
        scene = readSceneFile(path);
        stem = fs::path(path).stem().string();
        if (stem.size() > 6 && stem.substr(stem.size() - 6) == ".sylva") stem.resize(stem.size() - 6);
    }
    RenderSettings& r = scene.render;
    if (args.has("--quality")) {
        const QualityPreset* q = findQualityPreset(args.get("--quality"));
        if (!q) throw UsageError("option --quality: expected preview, final or reference, got '" + args.get("--quality") + "'");
        applyQuality(scene, *q);
    }
    if (args.has("--width")) r.width = int(parseInteger("--width", args.get("--width"), 1, 32768));
    if (args.has("--height")) r.height = int(parseInteger("--height", args.get("--height"), 1, 32768));
    if (args.has("--spp")) r.spp = int(parseInteger("--spp", args.get("--spp"), 1, 4096));
    if (args.has("--mode") && !parseRenderMode(args.get("--mode"), &r.mode))
        throw UsageError("option --mode: expected full, local, ambient or lb, got '" + args.get("--mode") + "'");
    if (args.has("--accel") && !parseAccel(args.get("--accel"), &r.accel))
        throw UsageError("option --accel: expected bvh or kdtree, got '" + args.get("--accel") + "'");
    if (args.has("--no-shadows")) r.shadows = false;
    for (auto [option, field] : {std::pair{"--alpha-distance", &r.alphaDistance}, std::pair{"--prune-distance", &r.pruneDistance}}) {
        if (!args.has(option)) continue;
        const double m = parseNumber(option, args.get(option));
        if (m < 0.0 || m > 1e30) throw UsageError(std::string("option ") + option + ": expected metres >= 0 (0: off), got " + args.get(option));
        *field = float(m);
    }
    const std::string out = args.get("--output", stem + ".png");
    const std::string ext = lowerExtension(out);
    if (ext != ".png" && ext != ".exr" && ext != ".tif" && ext != ".tiff")
        throw UsageError("output " + out + ": unknown image extension (use .png, .exr, .tif or .tiff)");
    requireReplaceableFile(out);
    int bandRows = 0;   // 0: the whole frame at once
    if (args.has("--band-rows")) bandRows = int(parseInteger("--band-rows", args.get("--band-rows"), 1, 32768));
    else if (!frameFitsMemory(r)) bandRows = bandRowsFor(r);
    if (bandRows >= r.height) bandRows = 0;
    auto compute = selectBackend(backend, [](const std::string& note) { std::fprintf(stderr, "note: %s\n", note.c_str()); });
    auto cache = openCache(args);
    JobLog log;
    AccelStats st;
    RenderTimings timings;
    float ambient = 0.0f;
    std::string device = compute->name();
    if (bandRows > 0) {
        const int bands = (r.height + bandRows - 1) / bandRows;
        std::fprintf(stderr, "note: tracing the %dx%d frame in %d bands of %d rows%s\n", r.width, r.height, bands, bandRows,
                     args.has("--band-rows") ? "" : " (the whole frame does not fit in the available memory)");
        if (device != "cpu") std::fprintf(stderr, "note: a frame in bands is traced on the CPU (the LB solves still run on %s)\n", device.c_str());
        ProgressPrinter bar("render", args.has("--quiet"));
        const BandedRender result = renderSceneInBands(scene, out, bandRows, cache.get(), &bar.progress(), &log, compute.get());
        bar.finish();
        st = result.stats;
        timings = result.timings;
        ambient = result.ambient;
        device = "cpu, " + std::to_string(bands) + " bands";
    } else {
        ProgressPrinter bar("render", args.has("--quiet"));
        const RenderOutput result = renderScene(scene, cache.get(), &bar.progress(), &log, compute.get());
        bar.finish();
        const std::vector<glm::vec3> linear = composeMode(result.film, r.mode, scene.sky, &ambient);
        writeRender(out, linear, r.width, r.height, r.exposureKey);
        st = result.stats;
        timings = result.timings;
    }
    for (const auto& w : log.warnings) std::fprintf(stderr, "warning: %s\n", w.c_str());
    std::printf("rendered %dx%d, %d spp, mode %s, %zu instances of %zu species (%.0f instanced triangles) on %s\nwrote %s\n",
                r.width, r.height, r.spp, renderModeName(r.mode), st.instances, scene.species.size(), st.instancedTriangles,
                device.c_str(), out.c_str());
    if (args.has("--stats")) {
        std::printf("time: assets %.3f s, build %.3f s, trace %.3f s\n", timings.assets, timings.build, timings.trace);
        const double accelBytes =
            double(st.tlasBytes + st.instanceBytes + st.blasBytes + st.triangleBytes + st.wideTlasBytes + st.wideBlasBytes);
        std::printf("acceleration structures: %.1f MB (tlas %zu B, instances %zu B, blas %zu B, triangles %zu B, the CPU's "
                    "8-wide copies: tlas %zu B, blas %zu B); %.4f B per instanced triangle, %.1f B per instance; depth tlas %d, "
                    "blas %d\n",
                    accelBytes / 1e6, st.tlasBytes, st.instanceBytes, st.blasBytes, st.triangleBytes, st.wideTlasBytes, st.wideBlasBytes,
                    accelBytes / std::max(1.0, st.instancedTriangles), double(st.tlasBytes + st.instanceBytes) / double(std::max<size_t>(1, st.instances)),
                    st.tlasDepth, st.maxBlasDepth);
        if (st.prunedLevels > 0) {
            std::printf("pruning from %g m: %zu pruned levels built (%.1f MB); instances per level (kept 1, 1/2, 1/4, ...):",
                        double(r.pruneDistance), st.prunedLevels, double(st.pruneBytes) / 1e6);
            for (size_t n : st.instancesPerLevel) std::printf(" %zu", n);
            std::printf("\n");
        }
        if (r.mode == RenderMode::Ambient) std::printf("ambient constant %.4f\n", ambient);
    }
    return kOk;
}

int cmdStudy(const Args& args)
{
    auto threads = threadLimit(args);
    study::Options o;
    const std::string what = args.positional()[0];
    if (what == "all") {
        o.parts = {study::Part::Lb, study::Part::Voxel, study::Part::Render};
    } else if (what != "report") {
        study::Part part;
        if (!study::parsePart(what, &part)) throw UsageError("expected lb, voxel, render, all or report, got '" + what + "'");
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

int cmdInfo(const Args& args)
{
    const std::string path = args.positional()[0];
    requireReadable(path, "file");
    if (isCacheFile(path)) {
        std::printf("%s", describeCacheFile(path).c_str());
        return kOk;
    }
    if (lowerExtension(path) == ".npy") {
        const NpyArray a = readNpy(path);
        std::string shape;
        for (size_t s : a.shape) shape += (shape.empty() ? "" : ", ") + std::to_string(s);
        double lo = 1e300, hi = -1e300, sum = 0;
        for (float v : a.data) {
            lo = std::min(lo, double(v));
            hi = std::max(hi, double(v));
            sum += v;
        }
        std::printf("%s: NumPy float32 array, shape (%s), %zu values, min %.6g, max %.6g, mean %.6g\n", path.c_str(),
                    shape.c_str(), a.data.size(), lo, hi, a.data.empty() ? 0.0 : sum / double(a.data.size()));
        const std::string sidecar = gridSidecarPath(path);
        if (fs::exists(sidecar)) {
            std::FILE* f = std::fopen(sidecar.c_str(), "rb");
            if (f) {
                char buf[4096];
                const size_t n = std::fread(buf, 1, sizeof buf - 1, f);
                std::fclose(f);
                buf[n] = 0;
                std::printf("placement (%s): %s\n", sidecar.c_str(), buf);
            }
        }
        return kOk;
    }
    const std::string ext = lowerExtension(path);
    if (ext == ".json" && path.size() > 11 && path.substr(path.size() - 11) != ".npy.json") {
        const Scene scene = readSceneFile(path);
        std::printf("%s: scene\n%s", path.c_str(), describeScene(scene).c_str());
        return kOk;
    }
    for (const char* notMesh : {".json", ".png", ".jpg", ".jpeg", ".tif", ".tiff", ".exr", ".txt", ".mtl"})
        if (ext == notMesh)
            throw Error(path + ": not a scene, mesh, .npy grid or cache entry (sylva info reads those; a .npy.json sidecar is "
                               "shown with its .npy)");
    ImportReport report;
    TriangleMesh mesh;
    try {
        mesh = importMesh(path, {}, &report);
    } catch (const Error& e) {
        throw Error(std::string(e.what()) + " (sylva info reads meshes, .npy grids and cache entries)");
    }
    std::printf("%s: mesh\n%s", path.c_str(), describeMesh(mesh).c_str());
    for (const auto& w : report.warnings) std::printf("warning: %s\n", w.c_str());
    return kOk;
}

} // namespace

int main(int argc, char** argv)
{
    std::vector<std::string> argsv(argv + 1, argv + argc);
    if (argsv.empty() || argsv[0] == "-h" || argsv[0] == "--help" || argsv[0] == "help") {
        printMainHelp();
        return argsv.empty() ? kUsage : kOk;
    }
    if (argsv[0] == "--version") {
        std::printf("sylva %s\nbackends: %s\n", versionString(), backendSummary().c_str());
        return kOk;
    }
    const std::vector<Command> cmds = commands();
    const Command* cmd = nullptr;
    for (const auto& c : cmds)
        if (c.name == argsv[0]) cmd = &c;
    if (!cmd) {
        std::fprintf(stderr, "sylva: unknown command '%s' (see sylva --help)\n", argsv[0].c_str());
        return kUsage;
    }
    try {
        Args args(*cmd, std::vector<std::string>(argsv.begin() + 1, argsv.end()));
        if (args.help()) {
            printHelp(*cmd);
            return kOk;
        }
        if (cmd->name == "grow") return cmdGrow(args);
        if (cmd->name == "voxelize") return cmdVoxelize(args);
        if (cmd->name == "light") return cmdLight(args);
        if (cmd->name == "reference") return cmdReference(args);
        if (cmd->name == "render") return cmdRender(args);
        if (cmd->name == "study") return cmdStudy(args);
        if (cmd->name == "info") return cmdInfo(args);
    } catch (const UsageError& e) {
        std::fprintf(stderr, "sylva %s: %s\n", cmd->name.c_str(), e.what());
        return kUsage;
    } catch (const std::bad_alloc&) {
        std::fprintf(stderr, "sylva %s: error: out of memory (try a smaller --grid or --fp16)\n", cmd->name.c_str());
        return kFailure;
    } catch (const Cancelled&) {
        std::fprintf(stderr, "sylva %s: cancelled\n", cmd->name.c_str());
        return kFailure;
    } catch (const std::exception& e) {
        std::fprintf(stderr, "sylva %s: error: %s\n", cmd->name.c_str(), e.what());
        return kFailure;
    }
    return kFailure;
}
