// Rendering study: samples per pixel on a small scene; adaptive transparency and stochastic pruning on the forest.
#include <cmath>
#include <cstdio>
#include <optional>

#include "core/render/render_cpu.h"
#include "core/render/render_scene.h"
#include "core/render/tonemap.h"
#include "pipeline/render/frame_build.h"
#include "pipeline/render/render_job.h"
#include "pipeline/study/study_parts.h"

namespace sylva::study {

double imageError(const std::vector<glm::vec3>& a, const std::vector<glm::vec3>& b)
{
    double diff = 0.0, norm = 0.0;
    for (size_t i = 0; i < a.size() && i < b.size(); ++i) {
        const double la = luminance(a[i]), lb = luminance(b[i]);
        diff += (la - lb) * (la - lb);
        norm += lb * lb;
    }
    return norm > 0.0 ? std::sqrt(diff / norm) : 0.0;
}

namespace {

struct Traced {
    std::vector<glm::vec3> image;
    double seconds = 0.0;               // wall clock, best of the runs
    double cpu = 0.0;                   // CPU time, all threads, best of the runs
};

// Traces a built scene with `spp` samples: the best of `reps` runs (the machine is shared).
Traced trace(const RenderScene& rs, const Scene& scene, int spp, float alphaDistance, int reps)
{
    RenderView v = rs.view();
    v.spp = spp;
    v.alphaDistance = alphaDistance;
    Traced t;
    t.seconds = 1e30;
    t.cpu = 1e30;
    for (int r = 0; r < reps; ++r) {
        const double t0 = secondsNow(), c0 = cpuNow();
        Film film = renderFilm(v);
        t.seconds = std::min(t.seconds, secondsNow() - t0);
        t.cpu = std::min(t.cpu, cpuNow() - c0);
        if (r == 0) t.image = composeMode(film, RenderMode::Full, scene.sky);
    }
    return t;
}

// A few grown trees on the ground, seen from 14 m.
Scene smallScene(int width, int height)
{
    Scene s;
    s.species.resize(2);
    s.species[0].name = "broadleaf";
    s.species[0].grow = GrowSpec{"broadleaf", 3, 30000, 8.0f};
    s.species[1].name = "birch";
    s.species[1].grow = GrowSpec{"birch", 4, 30000, 9.0f};
    for (SpeciesDesc& sp : s.species) sp.lighting = lb::paramsFromPreset(*lb::findPreset("leaf"));
    InstanceDesc a, b, c, d;
    a.position = {-3.0, 0.0, 4.0};
    b.species = 1;
    b.position = {3.0, 0.0, 6.0};
    b.rotationDeg = {0.0f, 40.0f, 0.0f};
    c.position = {0.5, 0.0, 12.0};
    c.scale = 1.2f;
    c.rotationDeg = {0.0f, 200.0f, 0.0f};
    d.species = 1;
    d.position = {-6.0, 0.0, 14.0};
    d.rotationDeg = {0.0f, 110.0f, 0.0f};
    s.instances = {a, b, c, d};
    s.camera.position = {0.0, 3.0, -9.0};
    s.camera.target = {0.0, 4.5, 6.0};
    s.sun.direction = sunDirection(40.0, 120.0);
    s.render.width = width;
    s.render.height = height;
    return s;
}

} // namespace

RenderData measureRender(const Options& o)
{
    RenderData data;
    data.run = startRun(o);
    const int reps = o.quick ? 1 : 2;

    // Samples per pixel against a many-sample render of a small scene.
    {
        const Scene s = o.quick ? smallScene(160, 80) : smallScene(320, 160);
        data.sppScene = "2 grown species (broadleaf, birch, 30k triangles each), 4 instances on the ground, camera at 13-23 m";
        data.sppWidth = s.render.width;
        data.sppHeight = s.render.height;
        data.sppReference = o.quick ? 64 : 256;
        const std::vector<SpeciesAssets> assets = loadSpeciesAssets(s, o.cache, true);
        const RenderScene rs = buildRenderScene(s, assets, sunRadiance(s.sun));
        const Traced ref = trace(rs, s, data.sppReference, 0.0f, 1);
        char line[200];
        std::snprintf(line, sizeof line, "render spp: reference %d spp at %dx%d, %.1f s", data.sppReference, s.render.width,
                      s.render.height, ref.seconds);
        say(o, line);
        const std::vector<int> spps = o.quick ? std::vector<int>{1, 4, 16} : std::vector<int>{1, 4, 16, 64};
        for (int spp : spps) {
            const Traced t = trace(rs, s, spp, 0.0f, reps);
            SppRow row{spp, t.seconds, t.cpu, imageError(t.image, ref.image)};
            std::snprintf(line, sizeof line, "render spp %d: %.3f s (CPU %.3f s), error %.4f", spp, row.traceSeconds, row.traceCpu, row.err);
            say(o, line);
            data.spp.push_back(row);
        }
    }

    // Adaptive transparency and stochastic pruning on the default forest at reduced size.
    {
        Scene s = defaultScene();
        s.render.width = o.quick ? 224 : 448;
        s.render.height = o.quick ? 112 : 224;
        data.lodWidth = s.render.width;
        data.lodHeight = s.render.height;
        data.lodSpps = o.quick ? std::vector<int>{1, 4} : std::vector<int>{1, 4, 16};
        data.lodReferenceSpp = o.quick ? 32 : 128;
        data.lodScene = "the default forest (5 grown species, " + std::to_string(s.instances.size()) +
                        " instances at 39-270 m from the camera)";
        const std::vector<SpeciesAssets> assets = loadSpeciesAssets(s, o.cache, true);
        double b0 = secondsNow();
        const RenderScene base = buildRenderScene(s, assets, sunRadiance(s.sun));
        const double baseBuild = secondsNow() - b0;
        const Traced ref = trace(base, s, data.lodReferenceSpp, 0.0f, 1);
        data.lodReferenceSeconds = ref.seconds;
        char line[240];
        std::snprintf(line, sizeof line, "render forest: reference %d spp at %dx%d, %.1f s", data.lodReferenceSpp, s.render.width,
                      s.render.height, ref.seconds);
        say(o, line);
        const size_t ns = data.lodSpps.size();
        std::vector<Traced> off(ns);
        for (size_t k = 0; k < ns; ++k) off[k] = trace(base, s, data.lodSpps[k], 0.0f, reps);

        struct Config {
            float alpha, prune;
        };
        std::vector<Config> configs{{0.0f, 0.0f}};
        for (float d : {200.0f, 100.0f, 50.0f, 25.0f}) configs.push_back({d, 0.0f});
        for (float d : {100.0f, 50.0f, 25.0f, 12.5f}) configs.push_back({0.0f, d});
        configs.push_back({100.0f, 50.0f});
        configs.push_back({50.0f, 25.0f});
        auto metres = [](float m) {
            char b[32];
            std::snprintf(b, sizeof b, "%g m", double(m));
            return std::string(b);
        };
        for (const Config& c : configs) {
            LodRow row;
            row.alphaDistance = c.alpha;
            row.pruneDistance = c.prune;
            if (c.alpha == 0.0f && c.prune == 0.0f) row.label = "off";
            else if (c.prune == 0.0f) row.label = "alpha " + metres(c.alpha);
            else if (c.alpha == 0.0f) row.label = "prune " + metres(c.prune);
            else row.label = "alpha " + metres(c.alpha) + " + prune " + metres(c.prune);
            row.isDefault = c.alpha == 0.0f && c.prune == 0.0f;
            std::optional<RenderScene> pruned;
            if (c.prune > 0.0f) {
                Scene p = s;
                p.render.pruneDistance = c.prune;
                b0 = secondsNow();
                pruned = buildRenderScene(p, assets, sunRadiance(p.sun));
                row.buildSeconds = secondsNow() - b0;
                row.instancedTriangles = pruned->stats().instancedTriangles;
                row.pruneMegabytes = double(pruned->stats().pruneBytes) / 1e6;
            } else {
                row.buildSeconds = baseBuild;
                row.instancedTriangles = base.stats().instancedTriangles;
            }
            std::string text = "render forest " + row.label + ": build " + std::to_string(row.buildSeconds).substr(0, 5) + " s, " +
                               std::to_string(int(row.instancedTriangles / 1e6)) + "M triangles;";
            for (size_t k = 0; k < ns; ++k) {
                const Traced t = row.isDefault ? off[k] : trace(pruned ? *pruned : base, s, data.lodSpps[k], c.alpha, reps);
                row.traceSeconds.push_back(t.seconds);
                row.traceCpu.push_back(t.cpu);
                row.err.push_back(imageError(t.image, ref.image));
                row.errOff.push_back(imageError(t.image, off[k].image));
                std::snprintf(line, sizeof line, " %d spp %.3f s (CPU %.3f s), error %.4f (vs off %.4f);", data.lodSpps[k], t.seconds, t.cpu,
                              row.err.back(), row.errOff.back());
                text += line;
            }
            say(o, text);
            data.lod.push_back(row);
        }
    }

    // The quality presets end to end on the forest: each preset's LB settings for every species (through
    // the cache), its render settings and integrator; against the reference preset (the path tracer) with many samples.
    {
        const std::vector<QualityPreset>& presets = qualityPresets();
        auto presetScene = [&](const QualityPreset& q) {
            Scene s = defaultScene();
            s.render.width = o.quick ? 224 : 448;
            s.render.height = o.quick ? 112 : 224;
            applyQuality(s, q);
            return s;
        };
        const QualityPreset& refPreset = presets.back();
        Scene rs = presetScene(refPreset);
        rs.render.alphaDistance = 0.0f;
        rs.render.pruneDistance = 0.0f;
        data.presetReferenceSpp = 128;
        const std::vector<SpeciesAssets> refAssets = loadSpeciesAssets(rs, o.cache, true);
        const RenderScene refScene = buildRenderScene(rs, refAssets, sunRadiance(rs.sun));
        const Traced ref = trace(refScene, rs, data.presetReferenceSpp, 0.0f, 1);
        data.presetReferenceSeconds = ref.seconds;
        char line[200];
        std::snprintf(line, sizeof line, "render presets: reference %d spp, %.1f s", data.presetReferenceSpp, ref.seconds);
        say(o, line);
        for (const QualityPreset& q : presets) {
            const Scene s = presetScene(q);
            const std::vector<SpeciesAssets> assets = loadSpeciesAssets(s, o.cache, true);
            const double b0 = secondsNow();
            const RenderScene scene = buildRenderScene(s, assets, sunRadiance(s.sun));
            PresetRow row;
            row.name = q.name;
            row.settings = qualityPresetSettings(q);
            row.buildSeconds = secondsNow() - b0;
            const Traced t = trace(scene, s, q.spp, q.alphaDistance, reps);
            row.traceSeconds = t.seconds;
            row.traceCpu = t.cpu;
            row.err = imageError(t.image, ref.image);
            std::snprintf(line, sizeof line, "render preset %s: build %.2f s, trace %.3f s, error %.4f", q.name, row.buildSeconds,
                          row.traceSeconds, row.err);
            say(o, line);
            data.presets.push_back(row);
        }
    }
    finishRun(data.run);
    return data;
}

} // namespace sylva::study
