// Scene-scale study: the forest-level grid's resolution against the picture a per-instance
// solve gives on a stand of trees, and the relighting basis against direct solves.
//
// The reference lights every instance of the stand by its own LB grid, cut out of one LB solve over the whole
// stand at the species grid's spacing (every tree's density at its place): what a solve per instance with
// its neighbours around it gives, at the species' resolution. The trees stand at whole multiples of that
// spacing and are neither rotated nor scaled, so the cut-outs are the stand grid's nodes themselves (no
// resampling). Both the species grid and the reference are converged solves (tolerance 1e-4, fp32), so a
// lone tree's cut-out differs from its species grid only by the larger domain (the floor, reported).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>

#include "core/base/error.h"
#include "core/grid/grid_compare.h"
#include "core/render/render_cpu.h"
#include "core/render/render_scene.h"
#include "pipeline/lighting_job.h"
#include "pipeline/render/frame_build.h"
#include "pipeline/render/render_job.h"
#include "pipeline/study/study_parts.h"

namespace sylva::study {
namespace {

constexpr int kSide = 4;   // kSide x kSide trees in the stand, and one tree alone beside it

std::string dimsText(const glm::ivec3& d)
{
    return std::to_string(d.x) + "x" + std::to_string(d.y) + "x" + std::to_string(d.z);
}

struct Stand {
    Scene scene;                  // one species, the stand's instances (instance kSide^2 is the lone tree)
    std::vector<glm::ivec3> node; // per instance: its species grid's offset in the stand grid, nodes
    glm::ivec3 dims{0};           // the stand grid
    SpeciesGrids species;         // the species' density and lighting grids, its solve's parameters
};

bool edgeTree(size_t i) { return i / kSide == 0 || i / kSide == kSide - 1 || i % kSide == 0 || i % kSide == kSide - 1; }

// The stand of one grown broadleaf at the species grid `grid`: trees 0.8 crown widths apart (crowns just
// touching), the lone tree 1.5 crown widths beyond the stand's +x side, every position a whole multiple of
// the species grid's spacing.
Stand makeStand(int grid, int width, int height, GridCache* cache)
{
    Stand st;
    Scene& s = st.scene;
    s.species.resize(1);
    s.species[0].name = "broadleaf";
    s.species[0].grow = GrowSpec{"broadleaf", 3, 30000, 8.0f};
    // Converged solves (relative change per step under 1e-4, fp32) for the species grid and the reference
    // alike: the species grid's step count is the LB section's knob, not the forest grid's.
    s.species[0].lighting = defaultSpeciesLighting(*lb::findPreset("leaf"));
    s.species[0].lighting.tolerance = 1e-4;
    s.species[0].lighting.storage = lb::Storage::Fp32;
    s.species[0].grid = grid;
    s.sun.direction = sunDirection(40.0, 120.0);
    s.render.width = width;
    s.render.height = height;
    s.render.spp = 4;
    s.render.mode = RenderMode::Lb;
    st.species = loadSpeciesGrids(s, 0, cache);
    const GridGeometry& sg = st.species.density.geometry;
    const double h = sg.spacing;
    const lb::ForestSpecies f = lb::forestSpecies(st.species.density);
    const double crown = std::max(f.boxMax.x - f.boxMin.x, f.boxMax.z - f.boxMin.z);
    const int step = std::max(1, int(std::lround(0.8 * crown / h)));
    const int alone = (kSide - 1) * step + int(std::lround(1.5 * crown / h)) + step;
    for (int a = 0; a < kSide; ++a)
        for (int b = 0; b < kSide; ++b) st.node.push_back({a * step, 0, b * step});
    st.node.push_back({alone, 0, (kSide - 1) * step / 2});
    for (const glm::ivec3& n : st.node) {
        InstanceDesc d;
        d.position = glm::dvec3(n) * h;
        s.instances.push_back(d);
    }
    st.dims = sg.dims + glm::ivec3(alone, 0, (kSide - 1) * step);
    const glm::dvec3 mid = glm::dvec3(0.5 * (kSide - 1) * step * h, 0.0, 0.5 * (kSide - 1) * step * h);
    const double across = double(alone) * h;
    s.camera.position = mid + glm::dvec3(-0.1 * across, 0.62 * across, -0.78 * across);
    s.camera.target = mid + glm::dvec3(0.12 * across, 0.3 * f.boxMax.y, 0.0);
    s.camera.fovY = 40.0f;
    s.ground.enabled = false;   // the error is the plants' alone (no ground pixels to dilute it)
    return st;
}

// Every tree's density at its place in the stand grid (sums capped at 1; wood fraction the density-weighted
// mean).
DensityGrid standDensity(const Stand& st, const DensityGrid& species)
{
    DensityGrid out;
    out.geometry.dims = st.dims;
    out.geometry.spacing = species.geometry.spacing;
    out.geometry.origin = species.geometry.origin;
    const size_t n = out.geometry.nodeCount();
    out.density.assign(n, 0.0f);
    const bool wood = !species.woodFraction.empty();
    std::vector<float> woodSum(wood ? n : 0, 0.0f);
    const glm::ivec3 d = species.geometry.dims;
    for (const glm::ivec3& o : st.node)
        for (int i = 0; i < d.x; ++i)
            for (int j = 0; j < d.y; ++j)
                for (int k = 0; k < d.z; ++k) {
                    const size_t from = species.geometry.index(i, j, k);
                    const float rho = species.density[from];
                    if (rho <= 0.0f) continue;
                    const size_t to = out.geometry.index(i + o.x, j + o.y, k + o.z);
                    out.density[to] += rho;
                    if (wood) woodSum[to] += rho * species.woodFraction[from];
                }
    if (wood) out.woodFraction.assign(n, 0.0f);
    for (size_t i = 0; i < n; ++i) {
        if (wood && out.density[i] > 0.0f) out.woodFraction[i] = std::min(1.0f, woodSum[i] / out.density[i]);
        out.density[i] = std::min(1.0f, out.density[i]);
    }
    return out;
}

// Instance `o`'s lighting grid cut out of the stand's solve: the species grid's geometry, the stand's values.
LightingGrid cutOut(const LightingGrid& stand, const GridGeometry& species, const glm::ivec3& o)
{
    LightingGrid g;
    g.geometry = species;
    g.rgb.reserve(species.nodeCount() * 3);
    for (int i = 0; i < species.dims.x; ++i)   // storage order: z fastest, then the channel
        for (int j = 0; j < species.dims.y; ++j)
            for (int k = 0; k < species.dims.z; ++k)
                for (int c = 0; c < 3; ++c) g.rgb.push_back(stand.at(i + o.x, j + o.y, k + o.z, c));
    return g;
}

// The density-weighted mean of a lighting channel over a crown, and the relative L2 of a against b there.
double crownMean(const LightingGrid& g, const DensityGrid& d, int c)
{
    double sum = 0.0, w = 0.0;
    for (size_t n = 0; n < d.density.size(); ++n) {
        sum += double(d.density[n]) * double(g.rgb[n * 3 + size_t(c)]);
        w += double(d.density[n]);
    }
    return w > 0.0 ? sum / w : 0.0;
}

double crownError(const LightingGrid& a, const LightingGrid& b, const DensityGrid& d)
{
    double diff = 0.0, norm = 0.0;
    for (size_t n = 0; n < d.density.size(); ++n) {
        if (d.density[n] <= 0.0f) continue;
        for (size_t c = 0; c < 3; ++c) {
            const double x = a.rgb[n * 3 + c], y = b.rgb[n * 3 + c];
            diff += (x - y) * (x - y);
            norm += y * y;
        }
    }
    return norm > 0.0 ? std::sqrt(diff / norm) : 0.0;
}

// The LB pass over a black background: the error counts the plants' pixels alone.
std::vector<glm::vec3> lbPass(const RenderScene& rs)
{
    return composeMode(renderFilm(rs.view()), RenderMode::Lb, glm::vec3(0.0f));
}

double median(std::vector<double> v)
{
    if (v.empty()) return 0.0;
    std::sort(v.begin(), v.end());
    return v[v.size() / 2];
}

} // namespace

SceneData measureScene(const Options& o)
{
    SceneData data;
    data.run = startRun(o);
    char line[300];

    // ---- the forest-level grid against per-instance lighting on a stand ----
    const int grid = o.quick ? 32 : 64;
    Stand st = makeStand(grid, o.quick ? 192 : 384, o.quick ? 96 : 192, o.cache);
    Scene& s = st.scene;
    const size_t trees = s.instances.size(), lone = trees - 1;
    data.width = s.render.width;
    data.height = s.render.height;
    data.spp = s.render.spp;
    data.speciesGrid = grid;
    const SpeciesGrids& species = st.species;
    data.speciesDims = dimsText(species.density.geometry.dims);
    {
        const lb::ForestSpecies f = lb::forestSpecies(species.density);
        data.crownWidth = std::max(f.boxMax.x - f.boxMin.x, f.boxMax.z - f.boxMin.z);
    }
    data.standScene = std::to_string(kSide) + " x " + std::to_string(kSide) + " grown broadleaf trees (8 m, 30k triangles, species grid " +
                      data.speciesDims + ") with crowns just touching, and one tree alone 1.5 crown widths beside the stand; sun at 40 "
                      "degrees elevation; the LB pass (`render.mode` lb) at " + std::to_string(data.width) + "x" + std::to_string(data.height) +
                      ", " + std::to_string(data.spp) + " spp";
    const DensityGrid standD = standDensity(st, species.density);
    data.referenceDims = dimsText(standD.geometry.dims);
    JobLog refLog;
    double r0 = secondsNow();
    const LightingGrid standL = lightingFor(standD, species.params, o.cache, nullptr, &refLog);
    const bool refCached = !refLog.stages.empty() && refLog.stages.back().find("cache hit") != std::string::npos;
    data.referenceSeconds = refCached ? 0.0 : secondsNow() - r0;
    std::snprintf(line, sizeof line, "scene: stand reference LB grid %s, %.1f s%s", data.referenceDims.c_str(), data.referenceSeconds,
                  refCached ? " (from the cache)" : "");
    say(o, line);

    // The reference: one species per instance, each lit by its cut-out.
    std::vector<SpeciesAssets> assets = loadSpeciesAssets(s, o.cache, true);
    Scene refScene = s;
    refScene.species.assign(trees, s.species[0]);
    std::vector<SpeciesAssets> refAssets(trees, assets[0]);
    std::vector<double> refFactor(trees);              // green
    std::vector<glm::vec3> refFactorRgb(trees);
    glm::dvec3 alone;
    for (int c = 0; c < 3; ++c) alone[c] = crownMean(assets[0].lighting, species.density, c);
    for (size_t i = 0; i < trees; ++i) {
        refScene.species[i].name = "broadleaf " + std::to_string(i);
        refScene.instances[i].species = uint32_t(i);
        refAssets[i].lighting = cutOut(standL, assets[0].lighting.geometry, st.node[i]);
        for (int c = 0; c < 3; ++c) refFactorRgb[i][c] = float(crownMean(refAssets[i].lighting, species.density, c) / alone[c]);
        refFactor[i] = refFactorRgb[i].y;
    }
    {   // the floor: the lone tree alone in the stand's domain against its species grid
        Stand one = st;
        one.node = {st.node[lone]};
        const LightingGrid aloneL = lightingFor(standDensity(one, species.density), species.params, o.cache);
        data.floorErr = crownError(cutOut(aloneL, assets[0].lighting.geometry, st.node[lone]), assets[0].lighting, species.density);
    }
    data.isolatedFactor = refFactor[lone];
    auto meanOver = [&](const std::vector<double>& v, bool edge) {
        double sum = 0.0;
        int n = 0;
        for (size_t i = 0; i < lone; ++i)
            if (edgeTree(i) == edge) sum += v[i], ++n;
        return n ? sum / n : 0.0;
    };
    data.referenceInterior = meanOver(refFactor, false);
    data.referenceEdge = meanOver(refFactor, true);
    const RenderScene refRs = buildRenderScene(refScene, refAssets, sunRadiance(refScene.sun));
    const std::vector<glm::vec3> refImage = lbPass(refRs);
    // The pictures of the report: the reference, the forest grid off, at the default resolution.
    const std::string pictures = (o.outDir.empty() ? std::string(".") : o.outDir) + "/accuracy/";
    const float exposure = exposureOf(refImage);
    auto picture = [&](const std::string& name, const std::vector<glm::vec3>& image) {
        writePng(pictures + name, toneMap(image, exposure), data.width, data.height);
    };
    picture("scene_stand_reference.png", refImage);
    {   // the best one factor per instance can do: the species grid scaled by each instance's reference factor
        Scene c = s;
        c.lighting.forestGrid = ForestGridMode::On;
        RenderScene rs = buildRenderScene(c, assets, sunRadiance(c.sun));
        if (rs.instanceLights.size() != trees) throw Error("study scene: the forest grid gave no factor per instance");
        for (size_t i = 0; i < trees; ++i) {
            rs.instanceLights[i].factor = glm::vec4(refFactorRgb[i], 1.0f);
            for (glm::vec4& face : rs.instanceLights[i].face) face = glm::vec4(refFactorRgb[i], 1.0f);
        }
        data.oracleErr = imageError(lbPass(rs), refImage);
    }
    std::snprintf(line, sizeof line, "scene: reference factors interior %.3f, edge %.3f, lone tree %.3f; floor %.4f; image error with the "
                  "reference's factor per instance %.4f", data.referenceInterior, data.referenceEdge, data.isolatedFactor, data.floorErr,
                  data.oracleErr);
    say(o, line);

    // Settings: -1 = the forest grid off, 0 = the automatic resolution (the scene default), else nodes along the extent.
    const int defaultResolution = LightingDesc{}.forestGridResolution;
    std::vector<int> settings = o.quick ? std::vector<int>{-1, 8, 16, 32} : std::vector<int>{-1, 4, 8, 12, 16, 24, 32, 48};
    settings.push_back(defaultResolution);
    const int reps = o.quick ? 1 : 2;
    for (int setting : settings) {
        ForestGridRow row;
        row.automatic = setting == lb::kAutoResolution;
        row.isDefault = setting == defaultResolution;
        Scene c = s;
        c.lighting.forestGrid = setting >= 0 ? ForestGridMode::On : ForestGridMode::Off;
        c.lighting.forestGridResolution = setting >= 0 ? setting : defaultResolution;
        std::vector<glm::vec3> image;
        std::vector<double> factor(trees, 1.0);
        row.seconds = 1e30;
        for (int r = 0; r < reps; ++r) {
            const RenderScene rs = buildRenderScene(c, assets, sunRadiance(c.sun));
            const ForestGridStats& fg = rs.stats().forestGrid;
            row.resolution = setting >= 0 ? fg.resolution : 0;
            row.seconds = std::min(row.seconds, setting >= 0 ? fg.seconds : 0.0);
            row.dims = setting >= 0 ? dimsText(fg.dims) : "-";
            row.cellsPerCrown = setting >= 0 ? data.crownWidth / fg.spacing : 0.0;
            if (r > 0) continue;
            image = lbPass(rs);
            if (rs.instanceLights.size() == trees)
                for (size_t i = 0; i < trees; ++i) factor[i] = rs.instanceLights[i].factor.y;
        }
        row.imageErr = imageError(image, refImage);
        if (setting < 0) picture("scene_stand_off.png", image);
        if (row.isDefault) picture("scene_stand_default.png", image);
        double sq = 0.0;
        for (size_t i = 0; i < trees; ++i) {
            const double e = std::fabs(factor[i] - refFactor[i]);
            sq += e * e;
            row.factorMax = std::max(row.factorMax, e);
        }
        row.factorRms = std::sqrt(sq / double(trees));
        row.interior = meanOver(factor, false);
        row.edge = meanOver(factor, true);
        const std::string label = setting < 0 ? std::string("off") : std::string(row.automatic ? "auto " : "") + std::to_string(row.resolution);
        std::snprintf(line, sizeof line, "scene: forest grid %s (%s, %.1f cells a crown): %.3f s, image error %.4f, factor error rms %.3f max %.3f, interior %.3f edge %.3f",
                      label.c_str(), row.dims.c_str(), row.cellsPerCrown, row.seconds, row.imageErr, row.factorRms,
                      row.factorMax, row.interior, row.edge);
        say(o, line);
        data.forest.push_back(row);
    }

    // ---- the relighting basis against direct solves, on the stand's species ----
    data.suns = o.quick ? 3 : 8;
    std::mt19937 rng(18);
    std::uniform_real_distribution<double> elevation(5.0, 85.0), azimuth(0.0, 360.0);
    std::vector<glm::vec3> suns;
    for (int k = 0; k < data.suns; ++k) suns.push_back(sunDirection(elevation(rng), azimuth(rng)));
    for (const lb::Storage storage : {lb::Storage::Fp16, lb::Storage::Fp32}) {
        BasisRow row;
        row.fp16 = storage == lb::Storage::Fp16;
        lb::LbParams p = defaultSpeciesLighting(*lb::findPreset("leaf"));   // the product's fixed-step default
        row.isDefault = storage == p.storage;
        p.sun = s.sun.direction;
        p.storage = storage;
        double b0 = secondsNow(), c0 = cpuNow();
        const LightingBasis basis = lightingBasisFor(species.density, p, nullptr);
        row.basisSeconds = secondsNow() - b0;
        row.basisCpu = cpuNow() - c0;
        row.directions = int(basis.directions.size());
        row.megabytes = basisBytes(basis) / 1e6;
        std::vector<double> direct, directCpu, relit, errs;
        for (const glm::vec3& sun : suns) {
            lb::LbParams q = p;
            q.sun = sun;
            b0 = secondsNow();
            c0 = cpuNow();
            const LightingGrid solved = lightingFor(species.density, q, nullptr);
            direct.push_back(secondsNow() - b0);
            directCpu.push_back(cpuNow() - c0);
            b0 = secondsNow();
            const LightingGrid composed = relight(basis, q);
            relit.push_back(secondsNow() - b0);
            errs.push_back(relativeL2(composed, solved));
        }
        row.directSeconds = median(direct);
        row.directCpu = median(directCpu);
        row.relightMs = 1e3 * median(relit);
        row.errMedian = median(errs);
        row.errMax = *std::max_element(errs.begin(), errs.end());
        std::snprintf(line, sizeof line, "scene: basis %s, %d solves: %.2f s (CPU %.2f s), %.1f MB; direct solve %.3f s; relight %.1f ms; error median %.1e max %.1e",
                      row.fp16 ? "fp16" : "fp32", row.directions, row.basisSeconds, row.basisCpu, row.megabytes, row.directSeconds,
                      row.relightMs, row.errMedian, row.errMax);
        say(o, line);
        data.basis.push_back(row);
    }
    finishRun(data.run);
    return data;
}

} // namespace sylva::study
