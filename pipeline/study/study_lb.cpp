// LB study: grid resolution x steps x storage, time against the error to the Monte Carlo reference.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <optional>

#include <sys/resource.h>

#include "core/base/error.h"
#include "core/lb/lb_params.h"
#include "core/lb/lb_solver.h"
#include "core/reference/mc_reference.h"
#include "core/voxel/voxelize.h"
#include "pipeline/cache/grid_cache.h"
#include "pipeline/grow/tree_grower.h"
#include "pipeline/import/mesh_import.h"
#include "pipeline/lighting_job.h"
#include "core/scene/scene.h"
#include "pipeline/study/study_parts.h"

namespace sylva::study {

double secondsNow()
{
    return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

double cpuNow()
{
    rusage u{};
    getrusage(RUSAGE_SELF, &u);
    return double(u.ru_utime.tv_sec + u.ru_stime.tv_sec) + 1e-6 * double(u.ru_utime.tv_usec + u.ru_stime.tv_usec);
}

RunInfo startRun(const Options& o)
{
    RunInfo r;
    r.quick = o.quick;
    r.date = today();
    r.machine = machineDescription();
    r.loadBefore = loadAverage();
    r.seconds = secondsNow();
    return r;
}

void finishRun(RunInfo& run)
{
    run.seconds = secondsNow() - run.seconds;
    run.loadAfter = loadAverage();
}

std::string treeMeshPath(const Options& options)
{
    if (!options.treeMesh.empty()) return options.treeMesh;
    return std::string(SYLVA_SOURCE_DIR) + "/resources/trees/quaternius/OBJ/Tree_1.obj";
}

float sampleWorld(const LightingGrid& g, const glm::dvec3& world, int c)
{
    const glm::dvec3 p = (world - g.geometry.origin) / g.geometry.spacing;
    const glm::ivec3 d = g.geometry.dims;
    const glm::dvec3 cl = glm::clamp(p, glm::dvec3(0.0), glm::dvec3(d - 1) - 1e-9);
    const glm::ivec3 i = glm::ivec3(glm::floor(cl));
    const glm::dvec3 f = cl - glm::dvec3(i);
    double v = 0.0;
    for (int corner = 0; corner < 8; ++corner) {
        const int dx = corner >> 2, dy = (corner >> 1) & 1, dz = corner & 1;
        const double w = (dx ? f.x : 1.0 - f.x) * (dy ? f.y : 1.0 - f.y) * (dz ? f.z : 1.0 - f.z);
        if (w == 0.0) continue;
        v += w * double(g.at(std::min(i.x + dx, d.x - 1), std::min(i.y + dy, d.y - 1), std::min(i.z + dz, d.z - 1), c));
    }
    return float(v);
}

namespace {

constexpr int kChannel = 1;                      // errors are of the green channel (one reference solve)
const glm::vec3 kSun{0.3f, 1.0f, 0.2f};          // the sun of the ACCURACY.md examples

std::string dimsText(const GridGeometry& g)
{
    return std::to_string(g.dims.x) + "x" + std::to_string(g.dims.y) + "x" + std::to_string(g.dims.z);
}

// A cumulus-like blob in a unit cube: an ellipsoid with a smooth edge and puffs. Its density is scaled
// by the node spacing, so the optical depth across it (sigma is per node spacing) is the same at every
// resolution: the same cloud, resolved more finely. Peak density 0.45 at 32 nodes.
DensityGrid cloudGrid(int n)
{
    DensityGrid g;
    g.geometry.dims = {n, n, n};
    g.geometry.spacing = 1.0 / double(n - 2);
    g.geometry.origin = glm::dvec3(-0.5 * double(n - 1) * g.geometry.spacing);
    g.density.assign(g.geometry.nodeCount(), 0.0f);
    g.woodFraction.assign(g.geometry.nodeCount(), 0.0f);
    const double scale = 0.45 * (g.geometry.spacing * 30.0);
    for (int i = 1; i < n - 1; ++i)
        for (int j = 1; j < n - 1; ++j)
            for (int k = 1; k < n - 1; ++k) {
                const glm::dvec3 p = g.geometry.origin + g.geometry.spacing * glm::dvec3(i, j, k);
                const glm::dvec3 q = p / glm::dvec3(0.42, 0.32, 0.38);
                const double r2 = glm::dot(q, q);
                if (r2 >= 1.0) continue;
                const double puff = 1.0 + 0.35 * std::sin(7.0 * p.x + 1.0) * std::sin(9.0 * p.y + 2.0) * std::sin(8.0 * p.z + 0.5);
                g.density[g.geometry.index(i, j, k)] = float(std::min(1.0, scale * std::pow(1.0 - r2, 1.5) * puff));
            }
    return g;
}

struct CaseSpec {
    std::string name, title, preset;
    std::function<DensityGrid(int)> density;
};

// The reference of one density grid (green-channel optics on all channels: one solve), normalized,
// through the cache when there is one.
struct Reference {
    LightingGrid mean;
    std::vector<float> se;
    LbReference info;
};

Reference solveOrLoadReference(const Options& o, const DensityGrid& density, const lb::LbParams& lbParams, uint64_t paths,
                               const std::string& what)
{
    lb::LbParams p = lbParams;
    p.channels = {p.channels[kChannel], p.channels[kChannel], p.channels[kChannel]};
    ReferenceSettings rs;
    rs.paths = paths;
    rs.seed = 1;
    Reference r;
    r.info.grid = density.geometry.longestEdge();
    r.info.dims = dimsText(density.geometry);
    r.info.paths = double(paths);
    CacheKey key;
    if (o.cache) {
        key.add("study reference", int64_t(1)).add("density", densityHash(density));
        const lb::ChannelParams& c = p.channels[0];
        key.add("sigma_a", double(c.sigmaA)).add("sigma_s", double(c.sigmaS)).add("g", double(c.g));
        key.add("zero f0", int64_t(p.zeroF0)).add("brown", double(p.brownThreshold));
        for (int a = 0; a < 3; ++a) key.add("sun", double(p.sun[a])).add("intensity", double(p.intensity[a]));
        key.add("paths", int64_t(rs.paths)).add("seed", int64_t(rs.seed)).add("incidence", int64_t(int(rs.incidence)));
        CacheKey meanKey = key, seKey = key;
        meanKey.add("quantity", "mean");
        seKey.add("quantity", "standard error");
        auto mean = o.cache->loadLighting(meanKey);
        auto se = o.cache->loadLighting(seKey);
        if (mean && se && mean->geometry == density.geometry && se->rgb.size() == mean->rgb.size()) {
            r.mean = std::move(*mean);
            r.se = std::move(se->rgb);
            r.info.cached = true;
            std::ifstream secondsFile(o.cache->entryPath(meanKey, 'l') + ".seconds");   // the first solve's time
            if (!(secondsFile >> r.info.seconds)) r.info.seconds = 0.0;
        }
    }
    if (!r.info.cached) {
        const ReferenceResult res = solveReference(density, p, rs);
        r.mean = res.mean;
        r.se = res.standardError;
        r.info.seconds = res.seconds;
        if (o.cache) {
            try {
                CacheKey meanKey = key, seKey = key;
                meanKey.add("quantity", "mean");
                seKey.add("quantity", "standard error");
                o.cache->storeLighting(meanKey, r.mean);
                o.cache->storeLighting(seKey, LightingGrid{r.mean.geometry, r.se});
                std::ofstream(o.cache->entryPath(meanKey, 'l') + ".seconds") << r.info.seconds << "\n";
            } catch (const Error& e) {
                say(o, std::string("warning: reference not cached: ") + e.what());
            }
        }
    }
    normalizeToUnobstructed(r.mean, p, &r.se);
    r.info.noise = relativeNoiseInterior(r.mean, r.se);
    char line[256];
    std::snprintf(line, sizeof line, "%s: reference %s, %.0fM paths, noise %.4f, %s", what.c_str(), r.info.dims.c_str(),
                  double(paths) / 1e6, r.info.noise,
                  (std::string(r.info.cached ? "from the cache, solved in " : "") + std::to_string(int(r.info.seconds + 0.5)) + " s").c_str());
    say(o, line);
    return r;
}

// The LB grid's channel sampled at the interior nodes of `fine` (world positions), as a grid of fine's geometry.
LightingGrid resampled(const LightingGrid& lb, const GridGeometry& fine)
{
    LightingGrid out{fine, std::vector<float>(fine.nodeCount() * 3, 0.0f)};
    for (int i = 0; i < fine.dims.x; ++i)
        for (int j = 0; j < fine.dims.y; ++j)
            for (int k = 0; k < fine.dims.z; ++k) {
                const glm::dvec3 w = fine.origin + fine.spacing * glm::dvec3(i, j, k);
                const size_t n = fine.index(i, j, k);
                for (int c = 0; c < 3; ++c) out.rgb[n * 3 + size_t(c)] = sampleWorld(lb, w, c);
            }
    return out;
}

} // namespace

LbData measureLb(const Options& o)
{
    LbData data;
    data.run = startRun(o);
    const std::vector<int> grids = o.quick ? std::vector<int>{32, 64} : std::vector<int>{32, 64, 128};
    const int fine = grids.back();
    const uint64_t pathsAt32 = o.quick ? 2'000'000 : 8'000'000;   // paths grow with the grid: noise ~ flat

    std::optional<TriangleMesh> treeMesh, denseMesh;
    const std::string treePath = treeMeshPath(o);
    std::vector<CaseSpec> cases;
    cases.push_back({"tree", "real tree: " + std::filesystem::path(treePath).filename().string() + " (Quaternius), leaf preset",
                     "leaf", [&](int n) {
                         if (!treeMesh) treeMesh = importMesh(treePath);
                         VoxelizeSettings v;
                         v.longestAxisNodes = n;
                         return voxelize(*treeMesh, v);
                     }});
    cases.push_back({"dense", "generated dense tree: growTree broadleaf, seed 1, 200k triangles, leaf preset", "leaf", [&](int n) {
                         if (!denseMesh) {
                             GrowOptions g;
                             g.targetTriangles = 200000;
                             denseMesh = growTree(g).mesh;
                         }
                         VoxelizeSettings v;
                         v.longestAxisNodes = n;
                         return voxelize(*denseMesh, v);
                     }});
    cases.push_back({"cloud", "cloud: synthetic blob (ellipsoid with puffs, optical depth ~5 through the centre at every grid), "
                              "cloud preset", "cloud", [](int n) { return cloudGrid(n); }});

    const char* stepModes[] = {"default", "half", "tol 1e-3", "tol 1e-4"};
    bool ran256 = false;
    std::string note256;
    for (const CaseSpec& spec : cases) {
        LbCase c;
        c.name = spec.name;
        c.title = spec.title;
        c.preset = spec.preset;
        c.fineGrid = fine;
        if (spec.name == "tree" && !std::filesystem::exists(treePath)) {
            c.skipped = "mesh not found: " + treePath + " (sylva study --tree FILE)";
            say(o, "lb tree: skipped, " + c.skipped);
            data.cases.push_back(c);
            continue;
        }
        lb::LbParams params = lb::paramsFromPreset(*lb::findPreset(spec.preset));
        params.sun = kSun;
        // The finest reference first: every run's errFine is measured against it.
        const DensityGrid fineDensity = spec.density(fine);
        const Reference fineRef = solveOrLoadReference(o, fineDensity, params, pathsAt32 * uint64_t(fine / 32),
                                                       "lb " + spec.name + " " + std::to_string(fine));
        std::vector<int> runGrids = grids;
        double fp16DefaultAtFine = 0.0;
        for (size_t gi = 0; gi <= runGrids.size(); ++gi) {
            int n;
            if (gi < runGrids.size()) {
                n = runGrids[gi];
            } else {
                // 256: only in the full study, only fp16 (half the memory: 3.8 GB for a 256^3 RGB solve)
                // with the default steps and tol 1e-3, and only when the fp16 default-step solve at 128
                // took under 40 CPU seconds (256 costs about 16x: 8x the nodes, 2x the steps).
                if (o.quick) break;
                if (fp16DefaultAtFine > 40.0) {
                    note256 += spec.name + ": 256 left out (the fp16 default-step solve at 128 took " +
                               std::to_string(int(fp16DefaultAtFine)) + " CPU s). ";
                    break;
                }
                n = 256;
                ran256 = true;
            }
            const DensityGrid density = n == fine ? fineDensity : spec.density(n);
            std::optional<Reference> own;
            if (n == fine) own = fineRef;
            else if (n < fine) own = solveOrLoadReference(o, density, params, pathsAt32 * uint64_t(n / 32), "lb " + spec.name + " " + std::to_string(n));
            if (own) c.references.push_back(own->info);
            for (const char* mode : stepModes) {
                for (bool fp16 : {false, true}) {
                    if (n == 256 && (!fp16 || std::string(mode) == "half" || std::string(mode) == "tol 1e-4")) continue;
                    lb::LbParams p = params;
                    p.storage = fp16 ? lb::Storage::Fp16 : lb::Storage::Fp32;
                    const std::string m = mode;
                    if (m == "half") p.steps = std::max(1, lb::defaultSteps(density.geometry.dims) / 2);
                    if (m == "tol 1e-3") p.tolerance = 1e-3;
                    if (m == "tol 1e-4") p.tolerance = 1e-4;
                    lb::SolveStats st;
                    double c0 = cpuNow();
                    LightingGrid out = lb::solveLighting(density, p, nullptr, &st);
                    double cpu = cpuNow() - c0;
                    // The machine is shared: the best of three under 5 s, of two under 30 s.
                    double seconds = st.seconds;
                    const int reps = seconds < 5.0 ? 2 : (seconds < 30.0 ? 1 : 0);
                    for (int rep = 0; rep < reps; ++rep) {
                        lb::SolveStats again;
                        c0 = cpuNow();
                        lb::solveLighting(density, p, nullptr, &again);
                        cpu = std::min(cpu, cpuNow() - c0);
                        seconds = std::min(seconds, again.seconds);
                    }
                    normalizeToUnobstructed(out, p);
                    LbRow row;
                    row.grid = n;
                    row.dims = dimsText(density.geometry);
                    row.steps = m;
                    row.fp16 = fp16;
                    row.seconds = seconds;
                    row.cpuSeconds = cpu;
                    row.stepsTaken = st.steps;
                    row.errSame = own ? relativeL2Interior(out, own->mean, kChannel) : -1.0;
                    row.errFine = n == fine ? row.errSame : relativeL2Interior(resampled(out, fineDensity.geometry), fineRef.mean, kChannel);
                    if (n == fine && m == "default" && fp16) fp16DefaultAtFine = cpu;
                    char line[256];
                    std::snprintf(line, sizeof line, "lb %s %s %s %s: %.3f s (CPU %.3f s), %d steps, error %.4f (same grid) %.4f (vs %d)",
                                  spec.name.c_str(), row.dims.c_str(), fp16 ? "fp16" : "fp32", mode, seconds, cpu, st.steps,
                                  row.errSame, row.errFine, fine);
                    say(o, line);
                    c.rows.push_back(row);
                }
            }
        }
        data.cases.push_back(std::move(c));
    }
    if (o.quick) data.note = "Quick run (--quick): grids 32 and 64, references with a quarter of the full study's paths; 128 and 256 left out.";
    else if (!ran256) data.note = "256 left out: " + note256;
    else data.note = "256 (fp16 with the default steps and tol 1e-3 only; no reference at 256: its error is against 128) " +
                     std::string(note256.empty() ? "ran for every case." : "ran where it fits: " + note256);
    finishRun(data.run);
    markDefaults(data);
    return data;
}

void markDefaults(LbData& data)
{
    const SpeciesDesc defaultSpecies;
    const lb::LbParams def = defaultSpeciesLighting(*lb::findPreset("leaf"));
    std::string steps = "?";
    if (def.tolerance == 1e-3) steps = "tol 1e-3";
    else if (def.tolerance == 1e-4) steps = "tol 1e-4";
    else if (def.tolerance == 0.0 && def.steps == 0 && def.stepsPerEdge == 2) steps = "default";
    else if (def.tolerance == 0.0 && def.steps == 0 && def.stepsPerEdge == 1) steps = "half";
    const bool fp16 = def.storage == lb::Storage::Fp16;
    data.defaultConfig = "grid " + std::to_string(defaultSpecies.grid) + ", " + steps + ", " + (fp16 ? "fp16" : "fp32");
    for (LbCase& c : data.cases)
        for (LbRow& row : c.rows) row.isDefault = row.grid == defaultSpecies.grid && row.steps == steps && row.fp16 == fp16;
}

} // namespace sylva::study
