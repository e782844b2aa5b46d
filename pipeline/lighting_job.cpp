// Lighting pipeline for one species, with cache keys that cover everything that determines the result.
#include "pipeline/lighting_job.h"

#include "core/backend/backend.h"

#include <array>
#include <span>
#include <sstream>

#include "core/base/error.h"
#include "core/lb/lb_solver.h"
#include "core/mesh/triangle_mesh.h"
#include "core/voxel/solid_voxelize.h"
#include "pipeline/cache/grid_cache.h"

namespace sylva {

namespace {

template <typename T>
std::span<const std::byte> bytesOf(const std::vector<T>& v)
{
    return std::as_bytes(std::span<const T>(v.data(), v.size()));
}

CacheKey meshKey(const TriangleMesh& mesh, const VoxelizeSettings& voxel)
{
    CacheKey key;
    key.add("cache format", int64_t(kCacheFormatVersion));
    key.add("stage", "density");
    key.add("voxelizer version", kVoxelizerVersion);
    key.add("positions", bytesOf(mesh.positions));
    key.add("triangles", bytesOf(mesh.triangles));
    key.add("triangle materials", bytesOf(mesh.triangleMaterial));
    for (const Material& m : mesh.materials) key.add("material leaf", int64_t(m.isLeaf ? 1 : 0));
    key.add("dims x", voxel.dims.x).add("dims y", voxel.dims.y).add("dims z", voxel.dims.z);
    key.add("longest axis nodes", voxel.longestAxisNodes);
    key.add("subcells", voxel.subcells);
    if (voxel.solid) key.add("solid voxelizer version", kSolidVoxelizerVersion);   // surface keys unchanged
    return key;
}

CacheKey lightKey(const std::string& densityHex, const DensityGrid& density, const lb::LbParams& p)
{
    CacheKey key;
    key.add("cache format", int64_t(kCacheFormatVersion));
    key.add("stage", "lighting");
    key.add("lb algorithm version", lb::kAlgorithmVersion);
    key.add("density", densityHex);
    for (int c = 0; c < 3; ++c) {
        const lb::ChannelParams& ch = p.channels[size_t(c)];
        key.add("sigma_a", double(ch.sigmaA)).add("sigma_s", double(ch.sigmaS)).add("g", double(ch.g));
        key.add("intensity", double(p.intensity[c]));
    }
    const glm::dvec3 sun = glm::normalize(glm::dvec3(p.sun));   // in double: a float length can overflow
    key.add("sun x", sun.x).add("sun y", sun.y).add("sun z", sun.z);
    key.add("zero f0", int64_t(p.zeroF0));
    if (!p.boundary.empty()) key.add("boundary", bytesOf(p.boundary));   // else the sun's, keyed above
    key.add("brown threshold", double(p.brownThreshold));
    key.add("storage", int64_t(p.storage == lb::Storage::Fp16 ? 16 : 32));
    key.add("warm start", int64_t(p.warmStart));
    if (p.coarseStart && p.tolerance > 0.0) key.add("coarse start", int64_t(1));
    if (p.tolerance > 0.0) {
        // Where the tolerance check falls depends on the block depth, so it is part of the key here.
        key.add("tolerance", p.tolerance).add("check every", p.checkEvery).add("max steps", p.maxSteps);
        key.add("block steps", p.blockSteps);
    } else {
        key.add("steps", lb::fixedSteps(p, density.geometry.dims));
    }
    return key;
}

// The basis solve parameters of direction m as keyed: the sun does not matter (the boundary is e_m).
lb::LbParams keyedBasisParams(const lb::LbParams& params, int m)
{
    lb::LbParams p = lb::basisParams(params, m);
    p.sun = glm::vec3(0.0f, 1.0f, 0.0f);
    return p;
}

std::optional<LightingBasis> loadBasis(const std::string& densityHex, const DensityGrid& density, const lb::LbParams& params,
                                       GridCache& cache, JobLog* log)
{
    if (params.tolerance > 0.0) return std::nullopt;
    LightingBasis b;
    b.directions = lb::basisDirections(lb::BasisSet::All);
    for (int m : b.directions) {
        std::string why;
        auto hit = cache.loadLighting(lightKey(densityHex, density, keyedBasisParams(params, m)), &why);
        if (!hit) {
            if (log && why.find("no cache entry") == std::string::npos) log->warnings.push_back(why);
            return std::nullopt;
        }
        b.grids.push_back(std::move(*hit));
    }
    return b;
}

} // namespace

lb::BoundaryWeights boundaryWeightsOf(const lb::LbParams& params)
{
    if (params.boundary.empty()) return lb::sunWeights(params.sun, params.intensity);
    lb::BoundaryWeights w;
    for (int c = 0; c < 3; ++c)
        for (int m = 1; m < lb::kDirections; ++m) w.w[size_t(c)][size_t(m)] = params.intensity[c] * params.boundary[size_t(m)];
    return w;
}

LightingGrid relight(const LightingBasis& basis, const lb::BoundaryWeights& weights)
{
    std::vector<const LightingGrid*> grids;
    for (const LightingGrid& g : basis.grids) grids.push_back(&g);
    return lb::composeLighting(basis.directions, grids, weights);
}

LightingGrid relight(const LightingBasis& basis, const lb::LbParams& params) { return relight(basis, boundaryWeightsOf(params)); }

LightingBasis lightingBasisFor(const DensityGrid& density, const lb::LbParams& params, GridCache* cache, Progress* progress,
                               JobLog* log, Backend* backend)
{
    lb::validate(params);
    if (params.tolerance > 0.0)
        throw Error("a relighting basis needs a fixed step count: a tolerance solve is not linear in the boundary");
    LightingBasis b;
    b.directions = lb::basisDirections(lb::BasisSet::All);
    const size_t n = b.directions.size();
    for (size_t k = 0; k < n; ++k) {
        SubProgress part(progress, double(k) / double(n), double(k + 1) / double(n));
        Progress sub([&](double f, const std::string& msg) {
            part.report(f, "basis direction " + std::to_string(k + 1) + "/" + std::to_string(n) + ": " + msg);
        });
        if (progress && progress->isCancelled()) sub.cancel();
        JobLog one;
        b.grids.push_back(lightingFor(density, keyedBasisParams(params, b.directions[k]), cache, progress ? &sub : nullptr, &one, backend));
        if (log) {
            log->warnings.insert(log->warnings.end(), one.warnings.begin(), one.warnings.end());
            if (!one.stages.empty() && one.stages.back() != "light (cache hit)") log->stages.push_back("basis light");
        }
    }
    if (log) log->stages.push_back("basis");
    return b;
}

std::optional<LightingBasis> cachedLightingBasis(const DensityGrid& density, const lb::LbParams& params, GridCache& cache,
                                                 JobLog* log)
{
    return loadBasis(densityHash(density), density, params, cache, log);
}

double basisBytes(const LightingBasis& basis)
{
    double bytes = 0.0;
    for (const LightingGrid& g : basis.grids) bytes += double(g.rgb.size()) * sizeof(float);
    return bytes;
}

std::string densityHash(const DensityGrid& density)
{
    CacheKey key;
    const GridGeometry& g = density.geometry;
    key.add("dims x", g.dims.x).add("dims y", g.dims.y).add("dims z", g.dims.z);
    key.add("origin x", g.origin.x).add("origin y", g.origin.y).add("origin z", g.origin.z).add("spacing", g.spacing);
    key.add("density", bytesOf(density.density));
    key.add("wood", bytesOf(density.woodFraction));
    return key.hex();
}

DensityGrid densityForMesh(const DensityJob& job, GridCache* cache, Progress* progress, JobLog* log)
{
    SubProgress importProgress(progress, 0.0, 0.1);
    importProgress.report(0.0, "importing " + job.meshPath);
    ImportReport report;
    const TriangleMesh mesh = importMesh(job.meshPath, job.import, &report);
    if (log) {
        log->stages.push_back("import");
        for (const auto& w : report.warnings)
            log->warnings.push_back(w.find(job.meshPath) == std::string::npos ? job.meshPath + ": " + w : w);
    }
    SubProgress rest(progress, 0.1, 1.0);
    Progress sub([&](double f, const std::string& msg) { rest.report(f, msg); });
    if (progress && progress->isCancelled()) sub.cancel();
    return densityForTriangles(mesh, job.voxel, cache, progress ? &sub : nullptr, log);
}

DensityGrid densityForTriangles(const TriangleMesh& mesh, const VoxelizeSettings& voxel, GridCache* cache,
                                Progress* progress, JobLog* log)
{
    const CacheKey key = meshKey(mesh, voxel);
    if (cache) {
        std::string why;
        std::optional<DensityGrid> hit = cache->loadDensity(key, &why);
        if (!hit && cache->beforeCompute()) hit = cache->loadDensity(key, &why);   // a hook may have filled it
        if (hit) {
            if (log) log->stages.push_back("voxelize (cache hit)");
            if (progress) progress->report(1.0, "density grid from the cache");
            return std::move(*hit);
        }
        if (log && why.find("no cache entry") == std::string::npos) log->warnings.push_back(why);
    }
    DensityGrid grid = voxelize(mesh, voxel, progress);
    if (log) log->stages.push_back("voxelize");
    if (cache) {
        try {
            cache->storeDensity(key, grid);
        } catch (const std::exception& e) {
            if (log) log->warnings.push_back(std::string("cannot write the cache: ") + e.what());
        }
    }
    return grid;
}

LightingGrid lightingFor(const DensityGrid& density, const lb::LbParams& params, GridCache* cache, Progress* progress,
                         JobLog* log, Backend* backend)
{
    lb::validate(params);
    const std::string densityHex = cache ? densityHash(density) : std::string();   // hashing the grid costs time
    const CacheKey key = cache ? lightKey(densityHex, density, params) : CacheKey{};
    // The entry, or a cached relighting basis of the same grid and optics (the weighted sum, no solve).
    auto fromCache = [&]() -> std::optional<LightingGrid> {
        std::string why;
        if (auto hit = cache->loadLighting(key, &why)) {
            if (log) log->stages.push_back("light (cache hit)");
            if (progress) progress->report(1.0, "lighting grid from the cache");
            return hit;
        }
        if (log && why.find("no cache entry") == std::string::npos) log->warnings.push_back(why);
        if (auto basis = loadBasis(densityHex, density, params, *cache, log)) {
            if (log) log->stages.push_back("light (relit from the cached basis)");
            if (progress) progress->report(1.0, "lighting grid relit from the cached basis");
            return relight(*basis, params);
        }
        return std::nullopt;
    };
    if (cache) {
        std::optional<LightingGrid> hit = fromCache();
        if (!hit && cache->beforeCompute()) hit = fromCache();   // a hook may have filled it
        if (hit) return std::move(*hit);
    }
    LightingGrid grid = backend ? backend->solveLighting(density, params, progress, nullptr)
                                : lb::solveLighting(density, params, progress);
    if (log) log->stages.push_back("light");
    if (cache) {
        try {
            cache->storeLighting(key, grid);
        } catch (const std::exception& e) {
            if (log) log->warnings.push_back(std::string("cannot write the cache: ") + e.what());
        }
    }
    return grid;
}

LightingGrid lightingForWeights(const DensityGrid& density, const lb::LbParams& params, const lb::BoundaryWeights& w,
                                GridCache* cache, Progress* progress, JobLog* log, Backend* backend)
{
    const std::vector<lb::WeightedSolve> solves = lb::weightedSolves(params, w);
    if (solves.size() == 1 && solves[0].channels == std::array<bool, 3>{true, true, true})
        return lightingFor(density, solves[0].params, cache, progress, log, backend);
    LightingGrid out;
    out.geometry = density.geometry;
    out.rgb.assign(density.geometry.nodeCount() * 3, 0.0f);
    for (size_t k = 0; k < solves.size(); ++k) {
        SubProgress part(progress, double(k) / double(solves.size()), double(k + 1) / double(solves.size()));
        Progress sub([&](double f, const std::string& msg) { part.report(f, msg); });
        if (progress && progress->isCancelled()) sub.cancel();
        const LightingGrid g = lightingFor(density, solves[k].params, cache, &sub, log, backend);
        for (int c = 0; c < 3; ++c)
            if (solves[k].channels[size_t(c)])
                for (size_t n = 0; n < density.geometry.nodeCount(); ++n) out.rgb[n * 3 + size_t(c)] = g.rgb[n * 3 + size_t(c)];
    }
    if (solves.empty() && progress) progress->report(1.0, "no light on the boundary");
    return out;
}

std::string opticsJsonMembers(const lb::LbParams& params, const std::string& preset)
{
    std::ostringstream extra;
    extra.precision(9);
    auto triple = [&](auto get) { extra << "[" << get(0) << "," << get(1) << "," << get(2) << "]"; };
    std::string name;
    for (char c : preset)
        if (c != '"' && c != '\\' && static_cast<unsigned char>(c) >= 0x20) name += c;
    extra << "\"preset\":\"" << name << "\",\"sigma_a\":";
    triple([&](int c) { return params.channels[size_t(c)].sigmaA; });
    extra << ",\"sigma_s\":";
    triple([&](int c) { return params.channels[size_t(c)].sigmaS; });
    extra << ",\"g\":";
    triple([&](int c) { return params.channels[size_t(c)].g; });
    extra << ",\"sun\":";
    triple([&](int c) { return params.sun[c]; });
    extra << ",\"intensity\":";
    triple([&](int c) { return params.intensity[c]; });
    extra << ",\"zero_f0\":" << (params.zeroF0 ? "true" : "false");
    return extra.str();
}

std::string lightingParamsJson(const lb::LbParams& params, const std::string& preset, const glm::ivec3& dims)
{
    std::ostringstream extra;
    extra.precision(9);
    extra << "{" << opticsJsonMembers(params, preset) << ",\"storage\":\"" << (params.storage == lb::Storage::Fp16 ? "fp16" : "fp32")
          << "\"";
    if (params.tolerance > 0.0) extra << ",\"tolerance\":" << params.tolerance;
    else extra << ",\"steps\":" << lb::fixedSteps(params, dims);
    extra << ",\"warm_start\":" << (params.warmStart ? "true" : "false");
    if (params.coarseStart) extra << ",\"coarse_start\":true";
    extra << "}";
    return extra.str();
}

} // namespace sylva
