// Sky study: virtual lights N, interleaved subsets K and samples per pixel on the default forest
// under a Preetham sky and two HDR maps, against 1024 lights x 64 spp, with the sun-only frame's time beside
// them; and the LB with the sky in its boundary against Monte Carlo with the same boundary. Writes
// outDir/accuracy/sky.md, which the report includes.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>
#include <optional>
#include <sstream>

#include "core/base/error.h"
#include "core/reference/mc_reference.h"
#include "core/render/render_cpu.h"
#include "core/render/render_scene.h"
#include "core/render/tonemap.h"
#include "pipeline/io/atomic_file.h"
#include "pipeline/io/env_map_io.h"
#include "pipeline/lighting_job.h"
#include "pipeline/render/frame_build.h"
#include "pipeline/render/render_job.h"
#include "pipeline/study/study_parts.h"

namespace fs = std::filesystem;

namespace sylva::study {

namespace {

std::string f(const char* format, double v)
{
    char b[64];
    std::snprintf(b, sizeof b, format, v);
    return b;
}

struct Traced {
    std::vector<glm::vec3> image;
    double seconds = 0.0;   // wall clock, best of the runs
};

Traced trace(const RenderScene& rs, const Scene& s, int spp, int reps)
{
    RenderView v = rs.view();
    v.spp = spp;
    Traced t;
    t.seconds = 1e30;
    for (int r = 0; r < reps; ++r) {
        const double t0 = secondsNow();
        const Film film = renderFilm(v);
        t.seconds = std::min(t.seconds, secondsNow() - t0);
        if (r == 0) t.image = composeMode(film, RenderMode::Full, composeSky(s));
    }
    return t;
}

struct SkyCase {
    std::string key, title;
    SkyDesc desc;
};

struct Row {
    int lights = 0, interleave = 0, spp = 0;
    double seconds = 0.0, ratio = 0.0;   // frame time; / the sun-only frame's at the same spp
    double lightErr = 0.0;               // against 1024 lights, one subset, the same spp (the same camera rays)
    double refErr = 0.0;                 // against the reference (1024 lights x 64 spp)
    bool front = false;
};

// Marks the rows no other row beats in both time and reference error.
void markFront(std::vector<Row>& rows)
{
    for (Row& a : rows) {
        a.front = true;
        for (const Row& b : rows)
            if (&a != &b && b.seconds <= a.seconds && b.refErr <= a.refErr && (b.seconds < a.seconds || b.refErr < a.refErr)) a.front = false;
    }
}

} // namespace

bool measureSky(const Options& o)
{
    const double t0 = secondsNow();
    const std::string hdri = std::string(SYLVA_SOURCE_DIR) + "/resources/hdri/";
    std::vector<SkyCase> skies;
    {
        SkyCase p{"preetham", "Preetham, turbidity 3, the forest's sun", SkyDesc{}};
        p.desc.kind = sky::SkyKind::Preetham;
        p.desc.turbidity = 3.0;
        skies.push_back(p);
        if (!o.quick) {
            for (const char* name : {"park", "forest"}) {
                SkyCase m{std::string(name), std::string("HDR map `") + name + ".exr`", SkyDesc{}};
                m.desc.kind = sky::SkyKind::Map;
                m.desc.path = hdri + name + ".exr";
                if (!fs::exists(m.desc.path)) {
                    say(o, "sky study: " + m.desc.path + " not found, left out");
                    continue;
                }
                m.title += std::string(name) == "park" ? " (its sun taken out: 11% of its power)" : " (no sun disc: sky light only)";
                skies.push_back(m);
            }
        }
    }

    Scene base = defaultScene();
    base.render.width = o.quick ? 96 : 224;
    base.render.height = o.quick ? 48 : 112;
    const int refLights = o.quick ? 256 : 1024, refSpp = o.quick ? 16 : 64;
    const std::vector<int> spps = o.quick ? std::vector<int>{1, 4} : std::vector<int>{1, 4, 16};
    struct Pair {
        int n, k;
    };
    const std::vector<Pair> pairs = o.quick ? std::vector<Pair>{{16, 1}, {64, 8}, {64, 64}}
                                            : std::vector<Pair>{{16, 1},    {16, 4},   {16, 16},   {32, 8},   {32, 16},   {32, 32},  {64, 1},
                                                                {64, 4},    {64, 8},   {64, 16},   {64, 32},  {64, 64},   {128, 16}, {128, 64},
                                                                {128, 128}, {256, 16}, {256, 64},  {256, 256}, {1024, 64}, {1024, 256}, {1024, 1024}};
    // The light error's baseline: every pixel and sample with this many lights in one subset (256: its
    // irradiance within about 0.1% of the map's integral, tst_sky), at the same spp.
    const int baseLights = o.quick ? 64 : 256;
    // Best of two runs, one at 16 spp (the machine is shared; the sun-only frame is timed alike).
    auto repsFor = [&](int spp) { return o.quick || spp >= 16 ? 1 : 2; };

    std::ostringstream md;
    md << "## Sky light: virtual lights, interleaving and samples\n\n";
    md << "Measured by `sylva study sky`" << (o.quick ? " --quick" : "") << " on " << startRun(o).machine << ". The default forest ("
       << base.instances.size() << " instances) at " << base.render.width << " x " << base.render.height
       << ", its LB grids and render settings as in its file, under each sky below. For every N lights x K subsets x spp: the "
          "frame's trace time (best of 2 below 16 spp), that time over the **sun-only frame** (today's frame: the file's constant sky, the sun's one shadow ray) at "
          "the same spp, the **light error** (relative L2 of luminance against " << baseLights
       << " lights in one subset at the same spp: the same camera rays, so only the sky's sampling differs) and the **error** "
          "against the reference ("
       << refLights << " lights x " << refSpp << " spp, K " << std::min(refLights, refSpp)
       << ": every pixel sees every light). Rows on the Pareto front of time against error are marked *.\n\n";

    // The sun-only frame at each spp (the time base) and its own error against its many-sample picture.
    std::vector<double> sunSeconds(spps.size());
    std::vector<double> sunErr(spps.size());
    {
        const std::vector<SpeciesAssets> assets = loadSpeciesAssets(base, o.cache, true);
        const RenderScene rs = buildRenderScene(base, assets, sunRadiance(base.sun));
        const Traced ref = trace(rs, base, refSpp, 1);
        for (size_t k = 0; k < spps.size(); ++k) {
            const Traced t = trace(rs, base, spps[k], repsFor(spps[k]));
            sunSeconds[k] = t.seconds;
            sunErr[k] = imageError(t.image, ref.image);
            say(o, "sky study: sun-only frame " + std::to_string(spps[k]) + " spp " + f("%.3f", t.seconds) + " s, error against " +
                       std::to_string(refSpp) + " spp " + f("%.4f", sunErr[k]));
        }
        md << "The sun-only frame: ";
        for (size_t k = 0; k < spps.size(); ++k)
            md << (k ? "; " : "") << spps[k] << " spp " << f("%.3f", sunSeconds[k]) << " s, error " << f("%.3f", sunErr[k])
               << " against its own " << refSpp << " spp (pixel sampling alone)";
        md << ".\n\n";
    }

    // (N, K) -> per spp index: the worst light error and the worst time ratio over the skies.
    std::map<std::pair<int, int>, std::vector<std::pair<double, double>>> worst;
    for (const SkyCase& sc : skies) {
        Scene s = base;
        s.skyModel = sc.desc;
        s.skyModel.lights = refLights;
        s.skyModel.interleave = std::min(refLights, refSpp);
        loadSceneSky(s);
        const std::vector<SpeciesAssets> assets = loadSpeciesAssets(s, o.cache, true);
        RenderScene rs = buildRenderScene(s, assets, sunRadiance(s.sun));
        const double r0 = secondsNow();
        const Traced ref = trace(rs, s, refSpp, 1);
        say(o, "sky study " + sc.key + ": reference " + std::to_string(refLights) + " lights x " + std::to_string(refSpp) + " spp in " +
                   f("%.1f", secondsNow() - r0) + " s");
        // baseLights lights in one subset at each spp: what the light error is measured against.
        std::vector<std::vector<glm::vec3>> full(spps.size());
        SkyDesc d = s.skyModel;
        d.lights = baseLights;
        d.interleave = 1;
        setFrameSky(rs, d, groundPlaneShown(s));
        for (size_t k = 0; k < spps.size(); ++k) full[k] = trace(rs, s, spps[k], 1).image;
        std::vector<Row> rows;
        for (const Pair& p : pairs) {
            d.lights = p.n;
            d.interleave = p.k;
            setFrameSky(rs, d, groundPlaneShown(s));
            for (size_t k = 0; k < spps.size(); ++k) {
                const Traced t = trace(rs, s, spps[k], repsFor(spps[k]));
                Row r{p.n, p.k, spps[k], t.seconds, t.seconds / sunSeconds[k], imageError(t.image, full[k]), imageError(t.image, ref.image), false};
                rows.push_back(r);
                say(o, "sky study " + sc.key + ": N " + std::to_string(p.n) + " K " + std::to_string(p.k) + " spp " + std::to_string(spps[k]) +
                           ": " + f("%.3f", r.seconds) + " s (" + f("%.2f", r.ratio) + "x sun-only), light error " + f("%.4f", r.lightErr) +
                           ", error " + f("%.4f", r.refErr));
                auto& w = worst[{p.n, p.k}];
                w.resize(spps.size(), {0.0, 0.0});
                w[k].first = std::max(w[k].first, r.lightErr);
                w[k].second = std::max(w[k].second, r.ratio);
            }
        }
        markFront(rows);
        std::sort(rows.begin(), rows.end(), [](const Row& a, const Row& b) { return a.seconds < b.seconds; });
        md << "### " << sc.title << "\n\n";
        md << "| N lights | K subsets | spp | shadow rays / sample | time (s) | / sun-only | light error | error | front |\n";
        md << "| --- | --- | --- | --- | --- | --- | --- | --- | --- |\n";
        for (const Row& r : rows) {
            const bool isDefault = r.lights == SkyDesc{}.lights && r.interleave == SkyDesc{}.interleave;
            auto b = [&](const std::string& v) { return isDefault ? "**" + v + "**" : v; };
            md << "| " << b(std::to_string(r.lights)) << " | " << b(std::to_string(r.interleave)) << " | " << r.spp << " | "
               << (r.lights + r.interleave - 1) / r.interleave << " | " << f("%.3f", r.seconds) << " | " << f("%.2f", r.ratio) << " | "
               << f("%.4f", r.lightErr) << " | " << f("%.4f", r.refErr) << " | " << (r.front ? "*" : "") << " |\n";
        }
        md << "\n";
    }

    // The choice: per spp, the worst over the skies; the cheapest (N, K) within 2% light error on every sky and
    // the most accurate within 2x the sun-only frame.
    {
        const size_t last = spps.size() - 1;
        md << "**Worst over the skies**, light error and time over the sun-only frame, per N x K, at 1 and " << spps[last] << " spp:\n\n";
        md << "| N lights | K subsets | light error, 1 spp | time, 1 spp | light error, " << spps[last] << " spp | time, " << spps[last]
           << " spp |\n| --- | --- | --- | --- | --- | --- |\n";
        for (const auto& [nk, w] : worst) {
            const bool isDefault = nk.first == SkyDesc{}.lights && nk.second == SkyDesc{}.interleave;
            md << "| " << (isDefault ? "**" : "") << nk.first << " | " << nk.second << (isDefault ? "**" : "") << " | " << f("%.4f", w[0].first)
               << " | " << f("%.2f", w[0].second) << " | " << f("%.4f", w[last].first) << " | " << f("%.2f", w[last].second) << " |\n";
        }
        md << "\n";
        for (size_t k : {size_t(0), last}) {
            std::pair<int, int> cheapest{0, 0}, accurate{0, 0};
            double cheapRatio = 1e30, cheapErr = 0.0, accErr = 1e30, accRatio = 0.0;
            for (const auto& [nk, w] : worst) {
                if (w[k].first <= 0.02 && w[k].second < cheapRatio) cheapest = nk, cheapRatio = w[k].second, cheapErr = w[k].first;
                if (w[k].second <= 2.0 && w[k].first < accErr) accurate = nk, accErr = w[k].first, accRatio = w[k].second;
            }
            md << "- At " << spps[k] << " spp: ";
            if (cheapest.first > 0)
                md << "the cheapest within 2% light error on every sky is N " << cheapest.first << ", K " << cheapest.second << " ("
                   << f("%.4f", cheapErr) << " at " << f("%.2f", cheapRatio) << "x the sun-only frame)";
            else
                md << "no N x K measured comes within 2% light error on every sky";
            if (accurate.first > 0)
                md << "; the most accurate within 2x is N " << accurate.first << ", K " << accurate.second << " (" << f("%.4f", accErr)
                   << " at " << f("%.2f", accRatio) << "x)";
            else
                md << "; none stays within 2x";
            md << ".\n";
        }
        const auto def = worst.find({SkyDesc{}.lights, SkyDesc{}.interleave});
        if (def != worst.end())
            md << "- The default (`sky.lights` " << SkyDesc{}.lights << ", `sky.interleave` " << SkyDesc{}.interleave << "): "
               << f("%.4f", def->second[0].first) << " at " << f("%.2f", def->second[0].second) << "x at 1 spp, " << f("%.4f", def->second[last].first)
               << " at " << f("%.2f", def->second[last].second) << "x at " << spps[last] << " spp (the studio's still frame accumulates "
               << "max(spp, K) samples).\n";
        md << "\n";
    }

    // The LB with the sky in its boundary against Monte Carlo with the same boundary, on the real tree.
    {
        Scene t;
        SpeciesDesc sp;
        sp.name = "tree";
        sp.meshPath = fs::absolute(treeMeshPath(o)).string();
        sp.lighting = defaultSpeciesLighting(*lb::findPreset("leaf"));
        sp.grid = o.quick ? 16 : 32;
        t.species = {sp};
        t.instances = {InstanceDesc{}};
        t.sun.direction = base.sun.direction;
        t.skyModel = skies[0].desc;
        loadSceneSky(t);
        ReferenceSettings mcs;
        mcs.paths = o.quick ? 200000 : 2000000;
        md << "### The LB with the sky in its boundary against Monte Carlo (`lighting.boundary` sun_sky)\n\n";
        md << "The real tree (" << fs::path(sp.meshPath).filename().string() << ") at grid " << sp.grid
           << ", leaf preset, the product's default solve; the reference solver (" << mcs.paths
           << " paths per solve) takes the same boundary as lattice beams. Relative L2 over the interior nodes:\n\n";
        md << "| boundary | LB against Monte Carlo | reference noise | open-space value (luminance, renderer units) |\n| --- | --- | --- | --- |\n";
        for (LbBoundary b : {LbBoundary::Sun, LbBoundary::SunSky}) {
            t.lighting.boundary = b;
            const SpeciesGrids g = loadSpeciesGrids(t, 0, o.cache);
            const std::optional<lb::BoundaryWeights> w = speciesBoundary(t, g.params);
            const lb::BoundaryWeights weights = w ? *w : boundaryWeightsOf(g.params);
            LightingGrid mc;
            mc.geometry = g.lighting.geometry;
            mc.rgb.assign(g.lighting.rgb.size(), 0.0f);
            std::vector<float> se(mc.rgb.size(), 0.0f);
            for (const lb::WeightedSolve& ws : lb::weightedSolves(g.params, weights)) {
                const ReferenceResult r = solveReference(g.density, ws.params, mcs);
                for (int c = 0; c < 3; ++c)
                    if (ws.channels[size_t(c)])
                        for (size_t n = 0; n < mc.geometry.nodeCount(); ++n) {
                            mc.rgb[n * 3 + size_t(c)] = r.mean.rgb[n * 3 + size_t(c)];
                            se[n * 3 + size_t(c)] = r.standardError[n * 3 + size_t(c)];
                        }
            }
            const double err = relativeL2Interior(g.lighting, mc), noise = relativeNoiseInterior(mc, se);
            const FrameSun fsun = frameSun(t, sunRadiance(t.sun));
            const glm::vec3 open = weights.totals() / g.lightingNorm * lbRadiance(t, fsun);
            md << "| " << lbBoundaryName(b) << " | " << f("%.4f", err) << " | " << f("%.4f", noise) << " | "
               << f("%.3f", double(luminance(open))) << " |\n";
            say(o, std::string("sky study: LB boundary ") + lbBoundaryName(b) + " against Monte Carlo " + f("%.4f", err) + " (noise " +
                       f("%.4f", noise) + ")");
        }
        md << "\n";
    }
    md << "(Sky study: " << f("%.0f", secondsNow() - t0) << " s.)\n\n";
    AtomicFile file(o.outDir + "/accuracy/sky.md");
    file.write(md.str());
    file.commit();
    return true;
}

} // namespace sylva::study
