// The forest-level LB grid in the picture: a square stand of shrubs under a low sun, seen
// from the sun's side (the sunward faces: the front row open to the sun, the rows behind it in its shade; from
// above, the crowns' tops are lit alike in a stand and the face factors keep them so), with
// lighting.forest_grid on, auto and off. The species has no LB grid of its own (its indirect light is
// the open-sky value 1), so each pixel's indirect light is albedo x the forest factor x the sun: the
// oracle per instance is its pixels traced once more with the grid off. Interior instances must come out
// darker than edge instances with the grid on, and every instance of the species alike with it off.
#include <QTest>

#include <cmath>
#include <map>

#include "core/render/render_cpu.h"
#include "core/render/render_scene.h"
#include "core/render/shade.h"
#include "core/terrain/landscape_light.h"
#include "pipeline/render/frame_build.h"
#include "tests/common/scenes.h"

using namespace sylva;

namespace {

constexpr int kSide = 6;   // kSide x kSide shrubs

// The shrub's forest-grid view: its mesh bounds filled at density 0.5 (what a voxelized dense crown gives).
lb::ForestSpecies shrubForest(const TriangleMesh& mesh)
{
    glm::dvec3 lo(1e30), hi(-1e30);
    for (const glm::vec3& p : mesh.positions) lo = glm::min(lo, glm::dvec3(p)), hi = glm::max(hi, glm::dvec3(p));
    lb::ForestSpecies s;
    s.boxMin = lo;
    s.boxMax = hi;
    const glm::dvec3 e = hi - lo;
    s.biomass = 0.5 * e.x * e.y * e.z;
    s.spacing = std::max({e.x, e.y, e.z}) / 24.0;
    return s;
}

Scene stand(const lb::ForestSpecies& f, double gap)
{
    Scene s;
    s.species.resize(1);
    s.species[0].name = "shrub";
    s.species[0].lighting = lb::paramsFromPreset(*lb::findPreset("leaf"));
    const double w = std::max(f.boxMax.x - f.boxMin.x, f.boxMax.z - f.boxMin.z);
    const double step = w * gap;
    for (int a = 0; a < kSide; ++a)
        for (int b = 0; b < kSide; ++b) {
            InstanceDesc d;
            d.position = {(a - 0.5 * (kSide - 1)) * step, 0.0, (b - 0.5 * (kSide - 1)) * step};
            s.instances.push_back(d);
        }
    const double h = f.boxMax.y;
    s.camera.position = {0.0, h + 1.1 * step * kSide, -1.5 * step * kSide};
    s.camera.target = {0.0, 0.0, 0.0};
    s.camera.fovY = 30.0f;
    s.sun.direction = {0.2f, 0.45f, -1.0f};
    s.render.width = 96;
    s.render.height = 96;
    s.render.spp = 1;
    s.render.mode = RenderMode::Lb;
    s.lighting.forestGridResolution = 32;
    return s;
}

// A landscape of shrubs in a V valley along z (121 m across, walls rising 0.6 m per metre), lit by a low sun
// from +x, seen from above the valley's south end looking north along it.
Scene valley(const lb::ForestSpecies& f)
{
    Scene s;
    s.species.resize(1);
    s.species[0].name = "shrub";
    s.species[0].lighting = lb::paramsFromPreset(*lb::findPreset("leaf"));
    constexpr uint32_t n = 121;
    std::vector<float> hts(size_t(n) * n);
    for (uint32_t j = 0; j < n; ++j)
        for (uint32_t i = 0; i < n; ++i) hts[size_t(j) * n + i] = 0.6f * std::fabs(float(i) - 60.0f);
    s.terrain.dem = "(in memory)";
    s.terrain.spacing = 1.0;
    s.terrain.field = std::make_shared<const HeightField>(buildHeightField(std::move(hts), n, n, 1.0f, 1.0f));
    s.terrain.cells = 6;
    s.terrain.tiles.size = 20.0;
    TilePlantDesc p;
    p.species = 0;
    p.speciesName = "shrub";
    p.spacing = 1.2 * std::max(f.boxMax.x - f.boxMin.x, f.boxMax.z - f.boxMin.z);
    s.terrain.tiles.plants = {p};
    s.camera.position = {60.0, 75.0, -25.0};
    s.camera.target = {60.0, 5.0, 60.0};
    s.camera.fovY = 50.0f;
    s.sun.direction = {0.9f, 0.42f, 0.0f};
    s.render.width = 64;
    s.render.height = 64;
    s.render.spp = 1;
    s.render.mode = RenderMode::Lb;
    return s;
}

bool edge(size_t i) { return i / kSide == 0 || i / kSide == kSide - 1 || i % kSide == 0 || i % kSide == kSide - 1; }

// Mean luminance of each top-level instance's pixels (the instance the pixel's ray hits first).
std::map<uint32_t, double> perInstance(const RenderScene& rs, const Film& film)
{
    const RenderView v = rs.view();
    std::map<uint32_t, double> sum, count;
    for (int y = 0; y < film.height; ++y)
        for (int x = 0; x < film.width; ++x) {
            Hit hit{};
            if (!intersectStage(v, cameraRay(v, float(x) + 0.5f, float(y) + 0.5f), hit) || hitKind(hit) == SurfaceKind::Ground || hit.depth != 0) continue;
            const glm::vec3 c = film.pixels[size_t(y) * size_t(film.width) + size_t(x)].indirect;
            sum[hit.inst] += 0.2126 * c.x + 0.7152 * c.y + 0.0722 * c.z;
            count[hit.inst] += 1.0;
        }
    for (auto& [k, s] : sum) s /= count[k];
    return sum;
}

} // namespace

class TestForestGridRender : public QObject {
    Q_OBJECT
    std::vector<SpeciesAssets> m_assets;

private Q_SLOTS:
    void initTestCase()
    {
        m_assets = test::oneShrub();
        m_assets[0].forest = shrubForest(m_assets[0].mesh);
    }

    void interiorDarkerWithTheGridOn()
    {
        Scene s = stand(m_assets[0].forest, 0.9);   // crowns overlapping a little: a closed stand
        s.lighting.forestGrid = ForestGridMode::Off;
        const RenderScene off = buildRenderScene(s, m_assets, glm::vec3(1.0f));
        s.lighting.forestGrid = ForestGridMode::On;
        const RenderScene on = buildRenderScene(s, m_assets, glm::vec3(1.0f));
        const ForestGridStats& st = on.stats().forestGrid;
        QVERIFY(st.solved && st.applied && !st.skipped);
        QCOMPARE(st.plants, size_t(kSide * kSide));
        QVERIFY(!off.stats().forestGrid.solved && off.instanceLights.empty());
        const std::map<uint32_t, double> a = perInstance(off, renderFilm(off.view())), b = perInstance(on, renderFilm(on.view()));
        double edgeOn = 0.0, innerOn = 0.0, edgeOff = 0.0, innerOff = 0.0;
        int edges = 0, inners = 0;
        for (const auto& [i, lum] : b) {
            QVERIFY(a.count(i));
            if (edge(i)) edgeOn += lum, edgeOff += a.at(i), ++edges;
            else innerOn += lum, innerOff += a.at(i), ++inners;
        }
        QVERIFY2(edges >= 12 && inners >= 8, qPrintable(QString("%1 edge, %2 interior instances seen").arg(edges).arg(inners)));
        edgeOn /= edges, innerOn /= inners, edgeOff /= edges, innerOff /= inners;
        qInfo("mean luminance: grid on edge %.4f interior %.4f (%.3f); off edge %.4f interior %.4f; factors %.3f/%.3f/%.3f", edgeOn, innerOn,
              innerOn / edgeOn, edgeOff, innerOff, double(st.minFactor), double(st.medianFactor), double(st.maxFactor));
        QVERIFY(innerOn < 0.98 * edgeOn);   // the stand's interior darker by more than auto's 2% uniform spread
        QVERIFY(innerOn < innerOff && edgeOn <= edgeOff * 1.05);
        // Off: the open-sky value everywhere (albedo x 1 x sun), edge and interior alike to the albedo's texture.
        QVERIFY(std::fabs(innerOff - edgeOff) < 0.05 * edgeOff);
    }

    // Per pixel, the indirect light with the grid on is the one with it off times forestFactor, whose
    // records hold the solve's factors: the renderer applies exactly what the grid gave.
    void pixelsCarryTheFactors()
    {
        Scene s = stand(m_assets[0].forest, 0.9);
        s.render.width = s.render.height = 48;
        s.lighting.forestGrid = ForestGridMode::Off;
        const RenderScene off = buildRenderScene(s, m_assets, glm::vec3(1.0f));
        s.lighting.forestGrid = ForestGridMode::On;
        const RenderScene on = buildRenderScene(s, m_assets, glm::vec3(1.0f));
        const Film fa = renderFilm(off.view()), fb = renderFilm(on.view());
        const RenderView v = on.view();
        const ForestGridStats& st = on.stats().forestGrid;
        int checked = 0;
        for (int y = 0; y < fa.height; ++y)
            for (int x = 0; x < fa.width; ++x) {
                Hit hit{};
                const Ray ray = cameraRay(v, float(x) + 0.5f, float(y) + 0.5f);
                const size_t k = size_t(y) * size_t(fa.width) + size_t(x);
                if (!intersectStage(v, ray, hit) || hitKind(hit) == SurfaceKind::Ground) {
                    QCOMPARE(fb.pixels[k].indirect, fa.pixels[k].indirect);   // the ground: no factor
                    continue;
                }
                const InstanceRecord in = hitInstance(v, hit);
                const glm::vec3 lp = toLocalPoint(in, ray.org) + hit.t * toLocalDir(in, ray.dir);
                const glm::vec3 f = forestFactor(v, in, lp);
                for (int c = 0; c < 3; ++c) {
                    QVERIFY(f[c] >= std::min(st.minFactor, st.minFaceFactor) - 1e-6f && f[c] <= std::max(st.maxFactor, st.maxFaceFactor) + 1e-6f);
                    QVERIFY(std::fabs(fb.pixels[k].indirect[c] - fa.pixels[k].indirect[c] * f[c]) <= 1e-5f + 1e-5f * fa.pixels[k].indirect[c]);
                }
                ++checked;
            }
        QVERIFY(checked > 200);
    }

    // The landscape's plants: per pixel, the indirect light with the grid on is the one with it off times the
    // landscape lattice's factor at the hit (the renderer applies what the lattice gave), and the valley's
    // floor comes out darker against its ridges than with the grid off.
    void landscapeValleyDarkerThanRidges()
    {
        Scene s = valley(m_assets[0].forest);
        s.lighting.forestGrid = ForestGridMode::Off;
        const RenderScene off = buildRenderScene(s, m_assets, glm::vec3(1.0f));
        QVERIFY(!off.stats().landscapeLight.solved && off.landLight.empty());
        s.lighting.forestGrid = ForestGridMode::Auto;
        const RenderScene on = buildRenderScene(s, m_assets, glm::vec3(1.0f));
        const LandscapeLightStats& st = on.stats().landscapeLight;
        QVERIFY2(st.solved && st.applied && !st.skipped, qPrintable(QString("spread %1").arg(double(st.spread))));
        QVERIFY(!on.stats().forestGrid.solved);   // no top-level instances
        const Film fa = renderFilm(off.view()), fb = renderFilm(on.view());
        const RenderView v = on.view();
        double floorOn = 0.0, floorOff = 0.0, ridgeOn = 0.0, ridgeOff = 0.0;
        int plants = 0, floors = 0, ridges = 0;
        for (int y = 0; y < fa.height; ++y)
            for (int x = 0; x < fa.width; ++x) {
                Hit hit{};
                const Ray ray = cameraRay(v, float(x) + 0.5f, float(y) + 0.5f);
                const size_t k = size_t(y) * size_t(fa.width) + size_t(x);
                if (!intersectStage(v, ray, hit) || hitKind(hit) != SurfaceKind::Landscape) {
                    QCOMPARE(fb.pixels[k].indirect, fa.pixels[k].indirect);   // the ground and the sky: no factor
                    continue;
                }
                const glm::vec3 p = ray.org + hit.t * ray.dir - v.terrain.origin;
                const glm::vec3 f = landLightFactor(v.landscape.lightLayout, v.landLight, p);
                for (int c = 0; c < 3; ++c) {
                    QVERIFY(f[c] > 0.0f && f[c] < 1.2f);
                    QVERIFY(std::fabs(fb.pixels[k].indirect[c] - fa.pixels[k].indirect[c] * f[c]) <= 1e-5f + 1e-5f * fa.pixels[k].indirect[c]);
                }
                ++plants;
                const auto lum = [](const glm::vec3& c) { return 0.2126 * c.x + 0.7152 * c.y + 0.0722 * c.z; };
                if (std::fabs(p.x - 60.0f) < 12.0f) floorOn += lum(fb.pixels[k].indirect), floorOff += lum(fa.pixels[k].indirect), ++floors;
                if (std::fabs(p.x - 60.0f) > 45.0f) ridgeOn += lum(fb.pixels[k].indirect), ridgeOff += lum(fa.pixels[k].indirect), ++ridges;
            }
        qInfo("%d plant pixels (%d on the floor, %d on the ridges); floor / ridge luminance: grid on %.3f, off %.3f; factors %.3f / %.3f / %.3f",
              plants, floors, ridges, (floorOn / floors) / (ridgeOn / ridges), (floorOff / floors) / (ridgeOff / ridges), double(st.minFactor),
              double(st.medianFactor), double(st.maxFactor));
        QVERIFY(plants > 800 && floors > 100 && ridges > 50);
        // The walls (31 degrees) stand above the sun (25) but below the lattice's 45-degree direction: the floor
        // loses the sun's level share, the ridges' first columns keep it (tst_landscape_light has the steep valley).
        QVERIFY((floorOn / floors) / (ridgeOn / ridges) < 0.98 * (floorOff / floors) / (ridgeOff / ridges));
        QVERIFY(st.minFactor < 0.5f * st.maxFactor);
    }

    // Auto on a stand whose plants stand far apart (off each other's lattice lines, as tst_forest_grid's
    // separated forest): the skip branch, the picture equal to the grid off; on the closed stand auto applies.
    void autoSkipsUniformExposure()
    {
        Scene s = stand(m_assets[0].forest, 0.9);
        s.render.width = s.render.height = 32;
        s.lighting.forestGrid = ForestGridMode::Auto;
        QVERIFY(buildRenderScene(s, m_assets, glm::vec3(1.0f)).stats().forestGrid.applied);
        const lb::ForestSpecies& f = m_assets[0].forest;
        const double w = std::max(f.boxMax.x - f.boxMin.x, f.boxMax.z - f.boxMin.z);
        s.instances.clear();
        for (int a = 0; a < 2; ++a)
            for (int b = 0; b < 2; ++b) {
                InstanceDesc d;
                d.position = {w * (6.0 * a + 2.5 * b), 0.0, w * (6.0 * b - 2.5 * a)};
                s.instances.push_back(d);
            }
        const RenderScene autoScene = buildRenderScene(s, m_assets, glm::vec3(1.0f));
        const ForestGridStats& st = autoScene.stats().forestGrid;
        QVERIFY2(st.solved && st.skipped && !st.applied, qPrintable(QString("spread %1").arg(double(st.spread))));
        QVERIFY(st.spread < 0.02f);
        QVERIFY(autoScene.instanceLights.empty());
        s.lighting.forestGrid = ForestGridMode::Off;
        const Film a = renderFilm(autoScene.view()), b = renderFilm(buildRenderScene(s, m_assets, glm::vec3(1.0f)).view());
        for (size_t k = 0; k < a.pixels.size(); ++k) QCOMPARE(a.pixels[k].indirect, b.pixels[k].indirect);
    }
};

QTEST_APPLESS_MAIN(TestForestGridRender)
#include "tst_forest_grid_render.moc"
