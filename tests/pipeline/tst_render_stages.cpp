// "Only what the scene requires", read from the JobLog of renderScene: grids are
// computed per species, not per instance; a rerun recomputes only what the change invalidates (a camera,
// instance or render-settings change no grid, a sun move no voxelization, an unchanged scene nothing);
// local mode solves nothing.
#include <QDir>
#include <QTest>

#include <algorithm>

#include "core/base/error.h"
#include "pipeline/cache/grid_cache.h"
#include "pipeline/render/render_job.h"
#include "tests/common/files.h"

using namespace sylva;

namespace {

using Stages = std::vector<std::string>;

int countOf(const Stages& s, const std::string& what) { return int(std::count(s.begin(), s.end(), what)); }

QString joined(const Stages& s)
{
    QStringList l;
    for (const std::string& x : s) l << QString::fromStdString(x);
    return l.join(", ");
}

// `species` grown species (shrub and birch, 1500 triangles, grid 12), `perSpecies` instances of each
// on a grid, a small image.
Scene forest(int species, int perSpecies)
{
    Scene s;
    const char* kinds[2] = {"shrub", "birch"};
    for (int i = 0; i < species; ++i) {
        SpeciesDesc sp;
        sp.name = std::string(kinds[i % 2]) + std::to_string(i);
        sp.grow = GrowSpec{kinds[i % 2], uint64_t(10 + i), 1500, 0.0f};
        sp.lighting = lb::paramsFromPreset(*lb::findPreset("leaf"));
        sp.grid = 12;
        s.species.push_back(sp);
        for (int k = 0; k < perSpecies; ++k) {
            InstanceDesc in;
            in.species = uint32_t(i);
            in.position = {double(k % 10) * 3.0 - 13.5, 0.0, double(k / 10) * 3.0 + double(i) * 1.5};
            in.rotationDeg = {0.0f, float(37 * k % 360), 0.0f};
            in.scale = 0.8f + 0.04f * float(k % 10);
            s.instances.push_back(in);
        }
    }
    s.camera.position = {0.0, 6.0, -25.0};
    s.camera.target = {0.0, 1.0, 10.0};
    s.render.width = 32;
    s.render.height = 24;
    return s;
}

} // namespace

class TestRenderStages : public QObject {
    Q_OBJECT

    QString m_dir;

    Stages run(const Scene& s, const QString& cacheName)
    {
        GridCache cache((m_dir + "/" + cacheName).toStdString());
        JobLog log;
        renderScene(s, &cache, nullptr, &log);
        return log.stages;
    }

private Q_SLOTS:
    void initTestCase()
    {
        m_dir = test::outputDir("render_stages");
    }

    // One species with 100 instances grows, voxelizes and solves once; two species with 50 each, twice.
    void perSpeciesNotPerInstance()
    {
        const Stages one = run(forest(1, 100), "per-species-1");
        QCOMPARE(one, (Stages{"shrub0: grow", "voxelize", "light", "build", "trace"}));
        const Stages two = run(forest(2, 50), "per-species-2");
        QCOMPARE(countOf(two, "voxelize"), 2);
        QCOMPARE(countOf(two, "light"), 2);
        QCOMPARE(countOf(two, "shrub0: grow") + countOf(two, "birch1: grow"), 2);
        QCOMPARE(int(two.size()), 2 * 3 + 2);
    }

    // Changes on one cache, each against the scene before it.
    void rerunsOnlyWhatChanged()
    {
        const QString cache = "reruns";
        Scene s = forest(2, 6);
        const Stages first = run(s, cache);
        QCOMPARE(countOf(first, "voxelize"), 2);
        QCOMPARE(countOf(first, "light"), 2);
        const Stages hits{"shrub0: grow", "voxelize (cache hit)", "light (cache hit)",
                          "birch1: grow", "voxelize (cache hit)", "light (cache hit)", "build", "trace"};
        auto expectHits = [&](const Scene& changed, const char* what) {
            const Stages st = run(changed, cache);
            QVERIFY2(st == hits, qPrintable(QString("%1: %2").arg(what, joined(st))));
        };

        expectHits(s, "unchanged scene");
        // Nothing that a grid depends on: camera, instances, image, render settings, sun colour and
        // intensity, sky and ground.
        Scene c = s;
        c.camera.position = {4.0, 2.0, -12.0};
        c.camera.target = {1.0, 2.0, 0.0};
        c.camera.fovY = 70.0f;
        expectHits(c, "camera moved");
        c = s;
        c.instances[0].position += glm::dvec3(5.0, 0.0, 2.0);
        c.instances[3].rotationDeg = {10.0f, 200.0f, -5.0f};
        c.instances[4].scale = 2.5f;
        c.instances.push_back(c.instances[1]);
        c.instances.back().position.x += 40.0;
        c.instances.erase(c.instances.begin() + 2);
        expectHits(c, "instances moved, turned, scaled, added, removed");
        for (RenderMode m : {RenderMode::Full, RenderMode::Ambient, RenderMode::Lb}) {
            c = s;
            c.render.mode = m;
            c.render.width = 40;
            c.render.height = 17;
            c.render.spp = 5;
            expectHits(c, "render size, spp and mode");
        }
        c = s;
        c.render.accel = AccelKind::KdTree;
        c.render.shadows = false;
        c.render.indirectScale = 0.3f;
        c.render.exposureKey = 0.5f;
        expectHits(c, "accel, shadows, indirect scale, exposure");
        c = s;
        c.sun.intensity = 3.0f;
        c.sun.temperature = 3500.0;
        c.sky = {0.1f, 0.2f, 0.9f};
        c.ground.color = {0.5f, 0.4f, 0.1f};
        c.ground.height = -1.0;
        expectHits(c, "sun colour and intensity, sky, ground");

        // A sun move relights every species but voxelizes none.
        c = s;
        c.sun.direction = sunDirection(20.0, 250.0);
        const Stages sunMoved = run(c, cache);
        QVERIFY2(sunMoved == (Stages{"shrub0: grow", "voxelize (cache hit)", "light", "birch1: grow", "voxelize (cache hit)", "light", "build",
                                     "trace"}),
                 qPrintable(joined(sunMoved)));
        expectHits(s, "back to the first sun");   // the first sun's grids are still cached

        // Optics of one species: that species relights; its grid resolution: it revoxelizes and relights.
        c = s;
        c.species[1].lighting = lb::paramsFromPreset(*lb::findPreset("dogrose"));
        const Stages optics = run(c, cache);
        QVERIFY2(optics == (Stages{"shrub0: grow", "voxelize (cache hit)", "light (cache hit)", "birch1: grow", "voxelize (cache hit)", "light",
                                   "build", "trace"}),
                 qPrintable(joined(optics)));
        c = s;
        c.species[0].grid = 14;
        const Stages regrid = run(c, cache);
        QVERIFY2(regrid == (Stages{"shrub0: grow", "voxelize", "light", "birch1: grow", "voxelize (cache hit)", "light (cache hit)", "build",
                                   "trace"}),
                 qPrintable(joined(regrid)));
    }

    // Local mode uses no lighting grid: nothing is voxelized or solved, not even looked up in the cache.
    void localModeSolvesNothing()
    {
        Scene s = forest(2, 4);
        s.render.mode = RenderMode::Local;
        const Stages st = run(s, "local");
        QCOMPARE(st, (Stages{"shrub0: grow", "birch1: grow", "build", "trace"}));
        // Nor does a local render after a full one, or with the sun moved.
        s.render.mode = RenderMode::Full;
        run(s, "local");
        s.render.mode = RenderMode::Local;
        s.sun.direction = sunDirection(60.0, 10.0);
        QCOMPARE(run(s, "local"), (Stages{"shrub0: grow", "birch1: grow", "build", "trace"}));
    }

    // loadSpeciesGrids (the studio's inspector and grid export) goes through the same cache keys as a
    // render: after a render its grids are cache hits, equal to the render's; with the mesh given it
    // neither grows nor imports; a bad species index is an error naming it.
    void speciesGridsAreTheRendersGrids()
    {
        const Scene s = forest(2, 2);
        GridCache cache((m_dir + "/species-grids").toStdString());
        const std::vector<SpeciesAssets> assets = loadSpeciesAssets(s, &cache, true);
        JobLog log;
        const SpeciesGrids g = loadSpeciesGrids(s, 1, &cache, nullptr, &log);
        QCOMPARE(log.stages, (Stages{"birch1: grow", "voxelize (cache hit)", "light (cache hit)"}));
        QCOMPARE(g.lighting.geometry, assets[1].lighting.geometry);
        QVERIFY(g.lighting.rgb == assets[1].lighting.rgb);
        QCOMPARE(g.lightingNorm, assets[1].lightingNorm);
        QCOMPARE(g.density.geometry, g.lighting.geometry);
        QCOMPARE(g.density.density.size(), g.density.geometry.nodeCount());
        QCOMPARE(g.density.woodFraction.size(), g.density.geometry.nodeCount());
        QVERIFY(*std::max_element(g.density.density.begin(), g.density.density.end()) > 0.0f);
        QCOMPARE(g.params.sun, s.sun.direction);

        JobLog withMesh;
        const SpeciesGrids h = loadSpeciesGrids(s, 0, &cache, nullptr, &withMesh, &assets[0].mesh);
        QCOMPARE(withMesh.stages, (Stages{"voxelize (cache hit)", "light (cache hit)"}));
        QVERIFY(h.lighting.rgb == assets[0].lighting.rgb);

        try {
            loadSpeciesGrids(s, 2, &cache);
            QFAIL("species 2 of 2 was accepted");
        } catch (const Error& e) {
            QVERIFY2(QString(e.what()).contains("species 2"), e.what());
        }
    }
};

QTEST_GUILESS_MAIN(TestRenderStages)
#include "tst_render_stages.moc"
