// Species assets (grow/import, textures, grids), acceleration structures and the CPU frame for `sylva render`.
#include "pipeline/render/render_job.h"

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <numeric>
#include <memory>

#include <stdlib.h>
#include <unistd.h>

#include <QFile>

#include "core/base/memory.h"
#include "core/backend/backend.h"
#include "core/base/error.h"
#include "core/lb/lb_solver.h"
#include "core/sky/sky_light.h"
#include "core/render/tonemap.h"
#include "pipeline/cache/grid_cache.h"
#include "pipeline/grow/tree_grower.h"
#include "pipeline/import/mesh_import.h"
#include "pipeline/io/image_io.h"
#include "pipeline/render/frame_build.h"
#include "pipeline/scene/scene_file.h"
#include "pipeline/render/volume_job.h"

namespace sylva {

bool frameFitsMemory(const RenderSettings& r)
{
    const double needed = double(r.width) * double(r.height) * double(kFrameBytesPerPixel);
    const double available = availableMemoryBytes();
    return !(available > 0.0 && needed > 0.8 * available);
}

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
    if (!frameFitsMemory(r)) {
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
    vs.solid = sp.solid;
    SubProgress densityPart(progress, 0.0, 0.2);
    Progress densityProgress([&](double f, const std::string& msg) { densityPart.report(f, msg); });
    if (progress && progress->isCancelled()) densityProgress.cancel();
    g.density = densityForTriangles(mesh, vs, cache, &densityProgress, log);
    g.params = sp.lighting;
    g.params.sun = lbSunDirection(scene);
    const std::optional<lb::BoundaryWeights> weights = speciesBoundary(scene, g.params);
    // Progress 20-100% over the solves: one, or with direct light once two of equal size (so it never runs back).
    const bool once = gridDirectLight(scene.lighting) == DirectLight::Once;
    auto solve = [&](const lb::LbParams& p, double begin, double end) {
        SubProgress part(progress, begin, end);
        Progress sub([&](double f, const std::string& msg) { part.report(f, msg); });
        if (progress && progress->isCancelled()) sub.cancel();
        return weights ? lightingForWeights(g.density, p, *weights, cache, &sub, log, backend)
                       : lightingFor(g.density, p, cache, &sub, log, backend);
    };
    g.lighting = solve(g.params, 0.2, once ? 0.6 : 1.0);
    if (once) {
        // Direct light counted once: the same LB with scattering off is the uncollided sunlight the
        // renderer's shadow rays already draw; the grid keeps the scattered rest (cached like any solve).
        g.lighting = lb::scatteredPart(g.lighting, solve(lb::uncollidedParams(g.params), 0.6, 1.0));
    }
    g.lightingNorm = sunFreeField(g.params);
    return g;
}

} // namespace

glm::vec3 sunFreeField(const lb::LbParams& params)
{
    const std::vector<float> f = lb::boundaryDistribution(params.sun);
    return params.intensity * std::accumulate(f.begin(), f.end(), 0.0f);
}

std::optional<lb::BoundaryWeights> speciesBoundary(const Scene& scene, const lb::LbParams& params)
{
    if (scene.lighting.boundary == LbBoundary::Sun) return std::nullopt;
    const SkyDesc& d = scene.skyModel;
    if (d.analytic() && !d.built) throw Error("lighting.boundary sun_sky: the scene's sky is not built (loadSceneSky)");
    const sky::Sky constant = sky::constantSky(scene.sky, sky::SkySun{});
    const sky::Sky& sky = d.analytic() ? *d.built : constant;
    const FrameSun sun = frameSun(scene, sunRadiance(scene.sun));
    const glm::vec3 unit = lbRadiance(scene, sun);
    const glm::vec3 free = sunFreeField(params);
    lb::BoundaryWeights w = lb::sunWeights(params.sun, params.intensity * (sun.radiance / unit));
    w += lb::skyWeights(sky, float(sky::kPi) * unit / free);
    return w;
}

std::string speciesLightingKey(const Scene& scene)
{
    char buf[512];
    const glm::vec3 d = glm::normalize(lbSunDirection(scene));
    std::snprintf(buf, sizeof buf, "sun %.9g %.9g %.9g|direct %s", double(d.x), double(d.y), double(d.z), directLightName(gridDirectLight(scene.lighting)));
    std::string key = buf;
    if (scene.lighting.boundary == LbBoundary::Sun) return key;
    const SkyDesc& k = scene.skyModel;
    const glm::vec3 r = frameSun(scene, sunRadiance(scene.sun)).radiance;
    std::snprintf(buf, sizeof buf, "|boundary %s|sky %d %.9g %.9g %.9g T %.9g scale %.9g rot %.9g int %.9g from map %d|radiance %.9g %.9g %.9g|",
                  lbBoundaryName(scene.lighting.boundary), int(k.kind), double(scene.sky.x), double(scene.sky.y),
                  double(scene.sky.z), k.turbidity, double(k.scale), double(k.rotationDeg), double(k.intensity), int(k.sunFromMap),
                  double(r.x), double(r.y), double(r.z));
    return key + buf + k.path;
}

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
        if (!needLighting || !sp.lit) continue;   // unlit: no grid, the open-space value (conventional ambient)
        Progress sub([&](double f, const std::string& msg) { part.report(0.05 + 0.95 * f, sp.name + ": " + msg); });
        if (progress && progress->isCancelled()) sub.cancel();
        SpeciesGrids grids = gridsForMesh(scene, sp, out[s].mesh, cache, &sub, log, backend);
        out[s].lighting = std::move(grids.lighting);
        out[s].lightingNorm = grids.lightingNorm;
        out[s].forest = lb::forestSpecies(grids.density);   // its share of the forest-level grid (lighting.forest_grid)
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

RenderScene prepareRenderScene(const Scene& scene, GridCache* cache, Progress* progress, JobLog* log, Backend* backend,
                               RenderTimings& timings)
{
    auto t0 = std::chrono::steady_clock::now();
    SubProgress assetsPart(progress, 0.0, 0.6);
    Progress assetsProgress([&](double f, const std::string& m) { assetsPart.report(f, m); });
    if (progress && progress->isCancelled()) assetsProgress.cancel();
    const std::vector<SpeciesAssets> assets =
        loadSpeciesAssets(scene, cache, modeNeedsLighting(scene.render.mode), &assetsProgress, log, backend);
    timings.assets = secondsSince(t0);

    t0 = std::chrono::steady_clock::now();
    SubProgress buildPart(progress, 0.6, 0.7);
    Progress buildProgress([&](double f, const std::string& m) { buildPart.report(f, m); });
    // Volumes: their LB lighting through the cache, like a species' (pipeline/render/volume_job.h).
    const Scene lit = scene.volumes.empty() ? Scene{} : lightSceneVolumes(scene, cache, modeNeedsLighting(scene.render.mode), nullptr, log, backend);
    RenderScene rs = buildRenderScene(scene.volumes.empty() ? scene : lit, assets, sunRadiance(scene.sun), &buildProgress);
    const ForestGridStats& fg = rs.stats().forestGrid;
    if (log && fg.solved) log->stages.push_back(fg.applied ? "forest grid" : "forest grid skipped (exposure uniform)");
    const LandscapeLightStats& lg = rs.stats().landscapeLight;
    if (log && lg.solved) log->stages.push_back(lg.applied ? "landscape forest grid" : "landscape forest grid skipped (exposure uniform)");
    if (log) log->stages.push_back("build");
    timings.build = secondsSince(t0);
    return rs;
}

RenderOutput renderScene(const Scene& scene, GridCache* cache, Progress* progress, JobLog* log, Backend* backend,
                         const FilmRowsTracer& tracer, bool mattes)
{
    checkFrameMemory(scene.render);
    RenderOutput out;
    const RenderScene rs = prepareRenderScene(scene, cache, progress, log, backend, out.timings);
    out.stats = rs.stats();

    const auto t0 = std::chrono::steady_clock::now();
    SubProgress tracePart(progress, 0.7, 1.0);
    Progress traceProgress([&](double f, const std::string& m) { tracePart.report(f, m); });
    if (progress && progress->isCancelled()) traceProgress.cancel();
    out.film = tracer    ? tracer(rs, 0, scene.render.height, &traceProgress)
               : backend ? backend->render(rs, &traceProgress)
                         : renderFilm(rs.view(), &traceProgress);
    if (mattes) out.mattes = renderMatteFilm(rs.view());
    if (log) log->stages.push_back("trace");
    out.timings.trace = secondsSince(t0);
    return out;
}

int bandRowsFor(const RenderSettings& r)
{
    // A band's film, composed picture and tone-mapped rows: the parts plus two RGB floats per pixel.
    const double rowBytes = double(r.width) * double(sizeof(SampleParts) + 2 * sizeof(glm::vec3));
    const double available = availableMemoryBytes();
    const double budget = std::min(256e6, available > 0.0 ? 0.25 * available : 256e6);
    const int rows = int(std::clamp(budget / rowBytes, 8.0, double(std::max(8, r.height))));
    return rows / 8 * 8;
}

namespace {

struct FileCloser {
    void operator()(std::FILE* f) const { std::fclose(f); }
};

} // namespace

BandedRender renderSceneInBands(const Scene& scene, const std::string& outPath, int bandRows, GridCache* cache,
                                Progress* progress, JobLog* log, Backend* backend, const FilmRowsTracer& tracer)
{
    const RenderSettings& r = scene.render;
    if (bandRows < 1) throw Error("render: rows per band must be at least 1, got " + std::to_string(bandRows));
    std::string ext = std::filesystem::path(outPath).extension().string();
    for (char& c : ext) c = char(std::tolower(static_cast<unsigned char>(c)));
    if (ext != ".png" && ext != ".tif" && ext != ".tiff" && ext != ".exr")
        throw Error(outPath + ": unknown image extension '" + ext + "' (use .png, .tif, .tiff or .exr)");
    const bool linearOut = ext == ".exr";
    const DisplayTransform display = linearOut ? DisplayTransform() : displayTransformOf(r);   // an unknown view fails before the work
    const bool ambientMode = r.mode == RenderMode::Ambient;
    // Between the passes each pixel waits on disk: its composed linear RGB, or for ambient (whose
    // constant needs the whole frame) local, albedo and sky cover.
    const size_t floatsPerPixel = ambientMode ? 10 : 3;
    const size_t width = size_t(r.width), height = size_t(r.height);
    const double tempBytes = double(width * height * floatsPerPixel * sizeof(float));
    std::filesystem::path dir = std::filesystem::absolute(outPath).parent_path();
    std::filesystem::create_directories(dir);
    std::error_code ec;
    const std::filesystem::space_info space = std::filesystem::space(dir, ec);
    if (!ec && double(space.available) < 1.05 * tempBytes + double(width * height * (linearOut ? 6 : 3))) {
        char msg[400];
        std::snprintf(msg, sizeof msg,
                      "render: the %dx%d frame is rendered in bands through a temporary file of %.1f GB in %s, but only "
                      "%.1f GB is free there",
                      r.width, r.height, tempBytes / 1e9, dir.string().c_str(), double(space.available) / 1e9);
        throw Error(msg);
    }
    std::string tmpl = (dir / ".sylva-bands-XXXXXX").string();
    const int fd = mkstemp(tmpl.data());
    if (fd < 0) throw Error(dir.string() + ": cannot create a temporary file for the bands");
    std::filesystem::remove(tmpl, ec);   // unlinked at once: the data goes when the file closes, crash or not
    std::unique_ptr<std::FILE, FileCloser> temp(fdopen(fd, "w+b"));
    if (!temp) {
        ::close(fd);
        throw Error(dir.string() + ": cannot open the temporary file for the bands");
    }
    auto io = [&](bool write, float* data, size_t count) {
        const size_t done = write ? std::fwrite(data, sizeof(float), count, temp.get()) : std::fread(data, sizeof(float), count, temp.get());
        if (done != count)
            throw Error(dir.string() + (write ? ": cannot write the temporary band file (disk full?)" : ": cannot read the temporary band file back"));
    };

    BandedRender out;
    const RenderScene rs = prepareRenderScene(scene, cache, progress, log, backend, out.timings);
    out.stats = rs.stats();
    const RenderView view = rs.view();
    const int bands = (r.height + bandRows - 1) / bandRows;
    out.bands = bands;
    out.bandRows = bandRows;

    // Pass 1: trace each band (70-95%), keep what pass 2 needs, sum what the whole frame decides.
    auto t0 = std::chrono::steady_clock::now();
    SubProgress tracePart(progress, 0.7, 0.95);
    double indirectSum = 0.0, albedoSum = 0.0;
    LogAverageAccumulator logAverage;
    std::vector<float> buf;
    for (int b = 0; b < bands; ++b) {
        const int y0 = b * bandRows, y1 = std::min(r.height, y0 + bandRows);
        Progress bandProgress([&](double f, const std::string&) {
            tracePart.report((double(b) + f) / double(bands), "tracing band " + std::to_string(b + 1) + "/" + std::to_string(bands));
        });
        if (progress && progress->isCancelled()) bandProgress.cancel();
        const Film film = tracer ? tracer(rs, y0, y1, &bandProgress) : renderFilmRows(view, y0, y1, &bandProgress);
        buf.resize(film.pixels.size() * floatsPerPixel);
        if (ambientMode) {
            addAmbientSums(film, &indirectSum, &albedoSum);
            for (size_t p = 0; p < film.pixels.size(); ++p) {
                const SampleParts& s = film.pixels[p];
                float* d = &buf[p * 10];
                for (int c = 0; c < 3; ++c) {
                    d[c] = s.local[c];
                    d[3 + c] = s.albedo[c];
                    d[7 + c] = s.background[c];
                }
                d[6] = s.skyCover;
            }
        } else {
            for (size_t p = 0; p < film.pixels.size(); ++p) {
                const glm::vec3 c = composeSample(film.pixels[p], r.mode, composeSky(scene), 0.0f);
                for (int k = 0; k < 3; ++k) buf[p * 3 + size_t(k)] = c[k];
            }
            if (!linearOut) logAverage.add(buf.data(), film.pixels.size(), 3);
        }
        io(true, buf.data(), buf.size());
    }
    if (log) log->stages.push_back("trace");
    out.timings.trace = secondsSince(t0);
    out.ambient = ambientMode ? ambientConstant(indirectSum, albedoSum) : 0.0f;

    // Reads band b back as composed linear RGB into rgb.
    std::vector<float> rgb;
    auto readBand = [&](int b) {
        const int y0 = b * bandRows, y1 = std::min(r.height, y0 + bandRows);
        const size_t pixels = size_t(y1 - y0) * width;
        buf.resize(pixels * floatsPerPixel);
        io(false, buf.data(), buf.size());
        rgb.resize(pixels * 3);
        if (!ambientMode) {
            rgb = buf;
            return pixels;
        }
        for (size_t p = 0; p < pixels; ++p) {
            const float* d = &buf[p * 10];
            SampleParts s{};
            s.local = glm::vec3(d[0], d[1], d[2]);
            s.albedo = glm::vec3(d[3], d[4], d[5]);
            s.skyCover = d[6];
            s.background = glm::vec3(d[7], d[8], d[9]);
            const glm::vec3 c = composeSample(s, RenderMode::Ambient, composeSky(scene), out.ambient);
            for (int k = 0; k < 3; ++k) rgb[p * 3 + size_t(k)] = c[k];
        }
        return pixels;
    };
    // Ambient to a tone-mapped file: the log-average needs the composed frame, one more read.
    if (ambientMode && !linearOut) {
        std::rewind(temp.get());
        for (int b = 0; b < bands; ++b) {
            const size_t pixels = readBand(b);
            logAverage.add(rgb.data(), pixels, 3);
        }
    }
    // Pass 2 (95-100%): compose, tone map, write the rows.
    const float scale = linearOut ? 1.0f : toneMapScale(logAverage.value(), ToneMapParams{r.exposureKey});
    std::rewind(temp.get());
    SubProgress writePart(progress, 0.95, 1.0);
    RowImageWriter writer(outPath, r.width, r.height);
    std::vector<float> mapped;
    for (int b = 0; b < bands; ++b) {
        if (progress) progress->throwIfCancelled();
        const size_t pixels = readBand(b);
        if (linearOut) {
            writer.writeRows(rgb.data(), int(pixels / width));
        } else {
            mapped.resize(pixels * 3);
            display.apply(rgb.data(), pixels, mapped.data(), scale);
            writer.writeRows(mapped.data(), int(pixels / width));
        }
        writePart.report(double(b + 1) / double(bands), "writing");
    }
    writer.finish();
    return out;
}

ImageRgba toneMapped(const std::vector<glm::vec3>& linear, int width, int height, float key)
{
    return toneMapped(linear, width, height, key, DisplayTransform());
}

ImageRgba toneMapped(const std::vector<glm::vec3>& linear, int width, int height, float key, const DisplayTransform& view)
{
    std::vector<float> srgb(linear.size() * 3);
    displayEncode(reinterpret_cast<const float*>(linear.data()), linear.size(), srgb.data(), key, view);
    ImageRgba img(width, height, glm::vec4(1.0f));
    for (size_t p = 0; p < linear.size(); ++p)
        for (int c = 0; c < 3; ++c) img.pixels[p * 4 + size_t(c)] = srgb[p * 3 + size_t(c)];
    return img;
}

DisplayTransform displayTransformOf(const RenderSettings& r) { return DisplayTransform::find(r.display, r.view); }

void writeRender(const std::string& path, const std::vector<glm::vec3>& linear, int width, int height, float key,
                 const DisplayTransform& view)
{
    std::string ext = std::filesystem::path(path).extension().string();
    for (char& c : ext) c = char(std::tolower(static_cast<unsigned char>(c)));
    if (ext == ".exr") {
        ImageRgba img(width, height, glm::vec4(1.0f));
        for (size_t p = 0; p < linear.size(); ++p)
            for (int c = 0; c < 3; ++c) img.pixels[p * 4 + size_t(c)] = linear[p][c];
        writeImage(path, img, 3);
    } else if (ext == ".png" || ext == ".tif" || ext == ".tiff") {
        writeImage(path, toneMapped(linear, width, height, key, view), 3);
    } else {
        throw Error(path + ": unknown image extension '" + ext + "' (use .png, .tif, .tiff or .exr)");
    }
}

} // namespace sylva
