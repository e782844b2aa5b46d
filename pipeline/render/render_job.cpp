// Species assets (grow/import, textures, grids), acceleration structures and the CPU frame for `sylva render`.
#include "pipeline/render/render_job.h"

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <numeric>

#include <QFile>

#include "core/base/memory.h"
#include "core/backend/backend.h"
#include "core/base/error.h"
#include "core/lb/lb_solver.h"
#include "core/render/tonemap.h"
#include "pipeline/cache/grid_cache.h"
#include "pipeline/grow/tree_grower.h"
#include "pipeline/import/mesh_import.h"
#include "pipeline/io/image_io.h"
#include "pipeline/scene/scene_file.h"

namespace sylva {
namespace {

std::string readResource(const char* name)
{
    QFile f(QString(":/sylva/") + name);
    if (!f.open(QIODevice::ReadOnly)) throw Error(std::string("bundled resource missing: ") + name);
    const QByteArray bytes = f.readAll();
    return std::string(bytes.constData(), size_t(bytes.size()));
}

double secondsSince(std::chrono::steady_clock::time_point t0)
{
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

// Refuses, before any work, a frame whose film and composed picture would not fit in memory (the
// film holds every pixel's shading parts until the picture is composed): better a message than the
// out-of-memory killer halfway through.
void checkFrameMemory(const RenderSettings& r)
{
    const double pixels = double(r.width) * double(r.height);
    const double needed = pixels * double(kFrameBytesPerPixel);
    const double available = availableMemoryBytes();
    if (available > 0.0 && needed > 0.8 * available) {
        char msg[320];
        std::snprintf(msg, sizeof msg,
                      "render: a %dx%d image needs %.1f GB for its film and composed picture (%d bytes per pixel) but "
                      "%.1f GB of memory is available; render at most about %.0f megapixels",
                      r.width, r.height, needed / 1e9, int(kFrameBytesPerPixel), available / 1e9,
                      0.8 * available / double(kFrameBytesPerPixel) / 1e6);
        throw Error(msg);
    }
}

// Coverage in the alpha channel from an opacity map: its alpha when it has one below 1, else its red channel.
ImageRgba coverageFromOpacityMap(ImageRgba img)
{
    bool hasAlpha = false;
    for (size_t p = 0; p < size_t(img.width) * size_t(img.height) && !hasAlpha; ++p) hasAlpha = img.pixels[p * 4 + 3] < 1.0f;
    if (!hasAlpha)
        for (size_t p = 0; p < size_t(img.width) * size_t(img.height); ++p) img.pixels[p * 4 + 3] = img.pixels[p * 4];
    return img;
}

SpeciesAssets loadGeometry(const SpeciesDesc& sp, JobLog* log)
{
    SpeciesAssets a;
    if (sp.grow) {
        GrowOptions o;
        o.species = speciesFromName(sp.grow->species);
        o.seed = sp.grow->seed;
        o.targetTriangles = size_t(sp.grow->triangles);
        o.height = sp.grow->height;
        GrownTree tree = growTree(o);
        a.mesh = std::move(tree.mesh);
        a.diffuse.assign(a.mesh.materials.size(), ImageRgba());
        a.cutout.assign(a.mesh.materials.size(), ImageRgba());
        for (size_t m = 0; m < a.mesh.materials.size(); ++m) {
            if (a.mesh.materials[m].isLeaf) {
                a.diffuse[m] = tree.leafTexture;
                a.cutout[m] = tree.leafTexture;
            } else {
                a.diffuse[m] = tree.barkTexture;
            }
        }
        if (log) log->stages.push_back(sp.name + ": grow");
        return a;
    }
    ImportOptions io;
    io.leafMaterials = sp.leafMaterials;
    ImportReport report;
    a.mesh = importMesh(sp.meshPath, io, &report);
    if (log) {
        log->stages.push_back(sp.name + ": import");
        for (const auto& w : report.warnings) log->warnings.push_back(sp.name + ": " + w);
    }
    a.diffuse.assign(a.mesh.materials.size(), ImageRgba());
    a.cutout.assign(a.mesh.materials.size(), ImageRgba());
    for (size_t m = 0; m < a.mesh.materials.size(); ++m) {
        const Material& mat = a.mesh.materials[m];
        try {
            if (!mat.diffuseTexture.empty()) a.diffuse[m] = readImage(mat.diffuseTexture);
            if (!mat.alphaTexture.empty()) a.cutout[m] = coverageFromOpacityMap(readImage(mat.alphaTexture));
            else if (!a.diffuse[m].empty()) a.cutout[m] = a.diffuse[m];
        } catch (const Error& e) {
            if (log) log->warnings.push_back(sp.name + ": texture left out: " + e.what());
        }
    }
    return a;
}

// Voxelizes (or loads) and lights (or loads) one species' mesh; progress 0-20% density, then lighting.
SpeciesGrids gridsForMesh(const Scene& scene, const SpeciesDesc& sp, const TriangleMesh& mesh, GridCache* cache,
                          Progress* progress, JobLog* log, Backend* backend)
{
    SpeciesGrids g;
    VoxelizeSettings vs;
    vs.longestAxisNodes = sp.grid;
    SubProgress densityPart(progress, 0.0, 0.2);
    Progress densityProgress([&](double f, const std::string& msg) { densityPart.report(f, msg); });
    if (progress && progress->isCancelled()) densityProgress.cancel();
    g.density = densityForTriangles(mesh, vs, cache, &densityProgress, log);
    g.params = sp.lighting;
    g.params.sun = scene.sun.direction;
    SubProgress lightPart(progress, 0.2, 1.0);
    Progress lightProgress([&](double f, const std::string& msg) { lightPart.report(f, msg); });
    if (progress && progress->isCancelled()) lightProgress.cancel();
    g.lighting = lightingFor(g.density, g.params, cache, &lightProgress, log, backend);
    const std::vector<float> f = lb::boundaryDistribution(g.params.sun);
    const float free = std::accumulate(f.begin(), f.end(), 0.0f);
    g.lightingNorm = g.params.intensity * free;
    return g;
}

} // namespace

const CieTable& bundledCieTable()
{
    static const CieTable table = parseCieCsv(readResource("color/cie1931_2deg_xyz_cmf_360-830_1nm.csv"));
    return table;
}

glm::vec3 sunRadiance(const SunDesc& sun) { return sunColor(sun.temperature, bundledCieTable()) * sun.intensity; }

Scene defaultScene() { return parseScene(readResource("default_forest.sylva.json"), ".", "default_forest.sylva.json"); }

bool modeNeedsLighting(RenderMode mode) { return mode != RenderMode::Local; }

std::vector<SpeciesAssets> loadSpeciesAssets(const Scene& scene, GridCache* cache, bool needLighting, Progress* progress,
                                             JobLog* log, Backend* backend)
{
    const size_t n = scene.species.size();
    std::vector<SpeciesAssets> out(n);
    for (size_t s = 0; s < n; ++s) {
        const SpeciesDesc& sp = scene.species[s];
        SubProgress part(progress, double(s) / double(n), double(s + 1) / double(n));
        part.report(0.0, sp.name + ": geometry");
        out[s] = loadGeometry(sp, log);
        if (!needLighting) continue;
        Progress sub([&](double f, const std::string& msg) { part.report(0.05 + 0.95 * f, sp.name + ": " + msg); });
        if (progress && progress->isCancelled()) sub.cancel();
        SpeciesGrids grids = gridsForMesh(scene, sp, out[s].mesh, cache, &sub, log, backend);
        out[s].lighting = std::move(grids.lighting);
        out[s].lightingNorm = grids.lightingNorm;
    }
    return out;
}

SpeciesGrids loadSpeciesGrids(const Scene& scene, size_t species, GridCache* cache, Progress* progress, JobLog* log,
                              const TriangleMesh* mesh, Backend* backend)
{
    if (species >= scene.species.size())
        throw Error("species " + std::to_string(species) + " does not exist (the scene has " +
                    std::to_string(scene.species.size()) + ")");
    const SpeciesDesc& sp = scene.species[species];
    if (mesh) return gridsForMesh(scene, sp, *mesh, cache, progress, log, backend);
    if (progress) progress->report(0.0, sp.name + ": geometry");
    const SpeciesAssets geometry = loadGeometry(sp, log);
    return gridsForMesh(scene, sp, geometry.mesh, cache, progress, log, backend);
}

RenderOutput renderScene(const Scene& scene, GridCache* cache, Progress* progress, JobLog* log, Backend* backend)
{
    checkFrameMemory(scene.render);
    RenderOutput out;
    auto t0 = std::chrono::steady_clock::now();
    SubProgress assetsPart(progress, 0.0, 0.6);
    Progress assetsProgress([&](double f, const std::string& m) { assetsPart.report(f, m); });
    if (progress && progress->isCancelled()) assetsProgress.cancel();
    const std::vector<SpeciesAssets> assets =
        loadSpeciesAssets(scene, cache, modeNeedsLighting(scene.render.mode), &assetsProgress, log, backend);
    out.timings.assets = secondsSince(t0);

    t0 = std::chrono::steady_clock::now();
    SubProgress buildPart(progress, 0.6, 0.7);
    Progress buildProgress([&](double f, const std::string& m) { buildPart.report(f, m); });
    const RenderScene rs = buildRenderScene(scene, assets, sunRadiance(scene.sun), &buildProgress);
    if (log) log->stages.push_back("build");
    out.stats = rs.stats();
    out.timings.build = secondsSince(t0);

    t0 = std::chrono::steady_clock::now();
    SubProgress tracePart(progress, 0.7, 1.0);
    Progress traceProgress([&](double f, const std::string& m) { tracePart.report(f, m); });
    if (progress && progress->isCancelled()) traceProgress.cancel();
    out.film = backend ? backend->render(rs, &traceProgress) : renderFilm(rs.view(), &traceProgress);
    if (log) log->stages.push_back("trace");
    out.timings.trace = secondsSince(t0);
    return out;
}

ImageRgba toneMapped(const std::vector<glm::vec3>& linear, int width, int height, float key)
{
    std::vector<float> srgb(linear.size() * 3);
    ToneMapParams tp;
    tp.key = key;
    toneMapToSrgb(reinterpret_cast<const float*>(linear.data()), linear.size(), srgb.data(), tp);
    ImageRgba img(width, height, glm::vec4(1.0f));
    for (size_t p = 0; p < linear.size(); ++p)
        for (int c = 0; c < 3; ++c) img.pixels[p * 4 + size_t(c)] = srgb[p * 3 + size_t(c)];
    return img;
}

void writeRender(const std::string& path, const std::vector<glm::vec3>& linear, int width, int height, float key)
{
    std::string ext = std::filesystem::path(path).extension().string();
    for (char& c : ext) c = char(std::tolower(static_cast<unsigned char>(c)));
    if (ext == ".exr") {
        ImageRgba img(width, height, glm::vec4(1.0f));
        for (size_t p = 0; p < linear.size(); ++p)
            for (int c = 0; c < 3; ++c) img.pixels[p * 4 + size_t(c)] = linear[p][c];
        writeImage(path, img, 3);
    } else if (ext == ".png" || ext == ".tif" || ext == ".tiff") {
        writeImage(path, toneMapped(linear, width, height, key), 3);
    } else {
        throw Error(path + ": unknown image extension '" + ext + "' (use .png, .tif, .tiff or .exr)");
    }
}

} // namespace sylva
