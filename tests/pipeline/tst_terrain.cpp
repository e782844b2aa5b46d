// A terrain in the renderer: a flat terrain renders the ground plane's picture,
// the same scene 5e6 m from the origin renders the same picture, the scene file's terrain keys (read,
// written, relative paths) and a DEM's bad input.
#include <QTemporaryDir>
#include <QTest>

#include <cmath>
#include <fstream>
#include <limits>
#include <vector>

#include <OpenImageIO/imageio.h>

#include "core/base/error.h"
#include "core/render/render_cpu.h"
#include "core/render/render_scene.h"
#include "pipeline/grow/tree_grower.h"
#include "pipeline/io/dem_io.h"
#include "pipeline/render/frame_build.h"
#include "pipeline/scene/scene_file.h"
#include "tests/common/scenes.h"

using namespace sylva;

namespace {

using test::oneShrub;

// Shrubs on a patch of ground seen from above at an angle, the whole view on the ground.
Scene shrubPatch()
{
    Scene s;
    s.species.resize(1);
    s.species[0].name = "shrub";
    s.instances = test::patchOfNine(3.0);
    s.camera.position = {0.0, 6.0, -6.0};
    s.camera.target = {0.0, 0.0, 6.0};
    s.sun.direction = glm::vec3(0.5f, 0.7f, 0.2f);
    s.render.width = 96;
    s.render.height = 72;
    return s;
}

// A terrain of nx x nz samples `spacing` apart with heights h(i, j), its first sample at `origin`.
void setTerrain(Scene& s, uint32_t nx, uint32_t nz, float spacing, glm::dvec3 origin, float (*h)(uint32_t, uint32_t))
{
    std::vector<float> hts(size_t(nx) * nz);
    for (uint32_t j = 0; j < nz; ++j)
        for (uint32_t i = 0; i < nx; ++i) hts[size_t(j) * nx + i] = h(i, j);
    s.terrain.dem = "(in memory)";
    s.terrain.origin = origin;
    s.terrain.spacing = spacing;
    s.terrain.field = std::make_shared<const HeightField>(buildHeightField(std::move(hts), nx, nz, spacing, spacing));
}

std::vector<glm::vec3> render(const Scene& s, const std::vector<SpeciesAssets>& assets)
{
    return composeMode(renderFilm(buildRenderScene(s, assets, glm::vec3(1.0f)).view()), RenderMode::Full, s.sky);
}

void writeFloatImage(const std::string& path, int w, int h, const std::vector<float>& v)
{
    auto out = OIIO::ImageOutput::create(path);
    QVERIFY(out);
    QVERIFY(out->open(path, OIIO::ImageSpec(w, h, 1, OIIO::TypeDesc::FLOAT)));
    QVERIFY(out->write_image(OIIO::TypeDesc::FLOAT, v.data()));
    QVERIFY(out->close());
}

} // namespace

class TestTerrain : public QObject {
    Q_OBJECT

    std::vector<SpeciesAssets> m_assets;
    QTemporaryDir m_dir;

    std::string file(const char* name) const { return m_dir.filePath(QString::fromLatin1(name)).toStdString(); }
    void writeText(const std::string& path, const std::string& text)
    {
        std::ofstream f(path);
        f << text;
    }

private Q_SLOTS:
    void initTestCase() { m_assets = oneShrub(); }

    // A flat terrain at the plane's height, under the whole view, is the ground plane: the same picture
    // (sun, shadows of the shrubs, sky light), up to the rounding of two different intersection tests.
    void flatTerrainRendersTheGroundPlane()
    {
        Scene plane = shrubPatch();
        plane.ground.height = 0.0;
        const std::vector<glm::vec3> want = render(plane, m_assets);
        Scene terr = shrubPatch();
        setTerrain(terr, 401, 401, 0.5f, {-100.0, 0.0, -20.0}, [](uint32_t, uint32_t) { return 0.0f; });   // beyond the view
        const std::vector<glm::vec3> got = render(terr, m_assets);
        int differ = 0;
        double sum = 0.0;
        for (size_t i = 0; i < got.size(); ++i) {
            const float d = glm::length(got[i] - want[i]);
            sum += d;
            if (d > 1e-3f * std::max(1.0f, glm::length(want[i]))) ++differ;
        }
        qInfo("%d of %zu pixels differ; mean difference %g", differ, got.size(), sum / double(got.size()));
        QVERIFY(differ <= int(got.size()) / 200);
        QVERIFY(sum / double(got.size()) < 1e-3);
    }

    // Hilly terrain with shrubs on it: moved 5e6 m (terrain origin, instances and camera together), the
    // picture stays (the top level and the terrain are camera-relative, computed in double).
    void farFromOriginRendersTheSame()
    {
        auto hills = [](uint32_t i, uint32_t j) { return 1.5f * std::sin(float(i) * 0.11f) * std::cos(float(j) * 0.07f) - 1.0f; };
        Scene s = shrubPatch();
        setTerrain(s, 161, 161, 0.25f, {-20.0, 0.0, -5.0}, hills);
        for (InstanceDesc& d : s.instances) {   // on the ground: the height at the sample under the plant
            const uint32_t i = uint32_t(std::lround((d.position.x + 20.0) / 0.25)), j = uint32_t(std::lround((d.position.z + 5.0) / 0.25));
            d.position.y = hills(i, j);
        }
        const std::vector<glm::vec3> ref = render(s, m_assets);
        Scene far = s;
        const glm::dvec3 off(5e6, 1200.0, -5e6);
        far.terrain.origin += off;
        far.camera.position += off;
        far.camera.target += off;
        for (InstanceDesc& d : far.instances) d.position += off;
        const std::vector<glm::vec3> img = render(far, m_assets);
        int differ = 0, terrain = 0;
        for (size_t i = 0; i < img.size(); ++i) {
            if (glm::any(glm::greaterThan(glm::abs(img[i] - ref[i]), glm::vec3(0.02f)))) ++differ;
            if (glm::any(glm::notEqual(ref[i], s.sky))) ++terrain;
        }
        qInfo("%d of %zu pixels differ by more than 0.02", differ, img.size());
        QVERIFY(terrain > int(img.size()) / 2);
        QVERIFY2(differ <= int(img.size()) / 500, qPrintable(QString("%1 pixels differ").arg(differ)));
    }

    // A scene with a terrain and no instances renders (the terrain alone, shadowed by itself); so does one
    // with neither.
    void terrainOnlySceneRenders()
    {
        Scene s = shrubPatch();
        s.instances.clear();
        setTerrain(s, 65, 65, 0.5f, {-16.0, 0.0, -8.0}, [](uint32_t i, uint32_t) { return float(i % 8) * 0.2f; });
        const std::vector<glm::vec3> img = render(s, m_assets);
        int sky = 0;
        for (const glm::vec3& c : img) sky += c == s.sky;
        QVERIFY(sky < int(img.size()) / 4);
        // Without the terrain either, the ground plane and the sky alone (closed form: tst_bare_scene).
        s.terrain = TerrainDesc{};
        int ground = 0;
        for (const glm::vec3& c : render(s, m_assets)) ground += c != s.sky;
        QVERIFY(ground > int(img.size()) / 4);
    }

    // The scene file: a DEM relative to the scene's folder, its keys read and written back, the heights
    // loaded with the file (16-bit PNG units x height_scale, as the bundled St Helens DEM).
    void sceneFileReadsAndWritesTheTerrain()
    {
        const std::string dem = file("hills.png");
        {
            std::vector<uint16_t> px(4 * 3);
            for (size_t k = 0; k < px.size(); ++k) px[k] = uint16_t(1000 * k);
            auto out = OIIO::ImageOutput::create(dem);
            QVERIFY(out && out->open(dem, OIIO::ImageSpec(4, 3, 1, OIIO::TypeDesc::UINT16)));
            QVERIFY(out->write_image(OIIO::TypeDesc::UINT16, px.data()) && out->close());
        }
        const std::string scene = file("land.sylva.json");
        writeText(scene, R"({"version": 1, "species": [{"name": "s", "grow": {"species": "shrub"}}], "instances": [],
            "terrain": {"dem": "hills.png", "origin": [5000000, 10, -3], "spacing": 2.5, "height_scale": 0.1, "snow_line": 1500}})");
        const Scene s = readSceneFile(scene);
        QCOMPARE(s.terrain.dem, dem);
        QCOMPARE(s.terrain.origin, glm::dvec3(5000000.0, 10.0, -3.0));
        QCOMPARE(s.terrain.spacing, 2.5);
        QVERIFY(s.terrain.field);
        QCOMPARE(s.terrain.field->layout.nx, 4u);
        QCOMPARE(s.terrain.field->layout.nz, 3u);
        for (uint32_t k = 0; k < 12; ++k) QVERIFY(std::fabs(s.terrain.field->heights[k] - 100.0f * float(k)) < 1e-3f);
        const std::string text = sceneToJson(s, m_dir.path().toStdString());
        QVERIFY2(text.find("\"dem\": \"hills.png\"") != std::string::npos, text.c_str());
        const Scene back = parseScene(text, m_dir.path().toStdString(), "back");
        QCOMPARE(back.terrain.dem, dem);
        QCOMPARE(back.terrain.snowLine, 1500.0f);
        QCOMPARE(back.terrain.heightScale, 0.1);
        // A scene without a terrain writes none.
        Scene none = s;
        none.terrain = TerrainDesc{};
        none.instances.push_back(InstanceDesc{});
        QVERIFY(sceneToJson(none, m_dir.path().toStdString()).find("terrain") == std::string::npos);
    }

    // The bundled example: St Helens at 10 m (2000 x 2000 samples, 567.5 m to 2538.2 m as the data's
    // README gives them) with the default forest's species standing on it.
    void bundledLandscapeReads()
    {
        const Scene s = readSceneFile(SYLVA_SOURCE_DIR "/resources/landscape.sylva.json");
        QVERIFY(s.terrain.field);
        QCOMPARE(s.terrain.field->layout.nx, 2000u);
        QCOMPARE(s.terrain.field->layout.nz, 2000u);
        const glm::vec2 range = s.terrain.field->ranges.back();
        QVERIFY2(std::fabs(range.x - 567.5f) < 0.05f && std::fabs(range.y - 2538.2f) < 0.05f, qPrintable(QString("%1 .. %2").arg(range.x).arg(range.y)));
        QCOMPARE(s.species.size(), size_t(5));
        // Its plants are Wang tiles of the five species on 125 x 125 cells (160 m, the seed's cell size), thinned by altitude.
        QVERIFY(s.instances.empty());
        QCOMPARE(s.terrain.cells, 125);
        QCOMPARE(s.terrain.tiles.plants.size(), size_t(5));
        QVERIFY(s.terrain.density.enabled);
    }

    // An instance standing on the terrain is lifted onto its surface; one off the terrain or in a scene
    // without a terrain is refused.
    void instancesStandOnTheTerrain()
    {
        Scene s = shrubPatch();
        setTerrain(s, 81, 81, 0.5f, {-20.0, 3.0, -5.0}, [](uint32_t i, uint32_t j) { return 0.1f * float(i) + 0.05f * float(j); });
        Scene lifted = s;
        for (InstanceDesc& d : s.instances) {
            d.onTerrain = true;
            d.position.y = 0.25;
        }
        for (InstanceDesc& d : lifted.instances)   // the plane's height at (x, z), written out here
            d.position.y = 3.0 + 0.25 + 0.1 * (d.position.x + 20.0) / 0.5 + 0.05 * (d.position.z + 5.0) / 0.5;
        const std::vector<glm::vec3> a = render(s, m_assets), b = render(lifted, m_assets);
        int differ = 0;
        for (size_t i = 0; i < a.size(); ++i) differ += glm::length(a[i] - b[i]) > 1e-3f;
        QVERIFY2(differ <= int(a.size()) / 500, qPrintable(QString("%1 pixels differ").arg(differ)));
        s.instances[2].position.x = 30.0;   // off the terrain's 40 m
        QVERIFY_THROWS_EXCEPTION(Error, buildRenderScene(s, m_assets, glm::vec3(1.0f)));
        Scene noTerrain = shrubPatch();
        noTerrain.instances[0].onTerrain = true;
        QVERIFY_THROWS_EXCEPTION(Error, buildRenderScene(noTerrain, m_assets, glm::vec3(1.0f)));
    }

    // Bad DEMs and terrain keys: a clear error naming the file or key, never a half-read terrain.
    void badTerrainIsRefused()
    {
        const std::string scene = file("bad.sylva.json");
        auto withTerrain = [&](const std::string& terrain) {
            writeText(scene, R"({"version": 1, "species": [{"name": "s", "grow": {"species": "shrub"}}], "instances": [], "terrain": )" + terrain + "}");
            return test::sceneFileError(scene);
        };
        auto expect = [](const std::string& message, const char* part) {
            QVERIFY2(message.find(part) != std::string::npos, qPrintable(QString::fromStdString("'" + message + "' lacks '" + part + "'")));
        };
        expect(withTerrain(R"({"dem": "nowhere.png"})"), "terrain.dem: no such file");
        expect(withTerrain(R"({})"), "terrain.dem: missing");
        writeFloatImage(file("nan.exr"), 3, 3, {0, 1, 2, 3, std::numeric_limits<float>::quiet_NaN(), 5, 6, 7, 8});
        expect(withTerrain(R"({"dem": "nan.exr"})"), "(column 1, row 1) is NaN");
        writeFloatImage(file("ninf.exr"), 3, 2, {0, 1, 2, -std::numeric_limits<float>::infinity(), 4, 5});
        expect(withTerrain(R"({"dem": "ninf.exr"})"), "(column 0, row 1) is -infinity");
        writeFloatImage(file("line.exr"), 5, 1, {0, 1, 2, 3, 4});
        expect(withTerrain(R"({"dem": "line.exr"})"), "at least 2 x 2 samples");
        writeFloatImage(file("ok.exr"), 2, 2, {0, 1, 2, 3});
        expect(withTerrain(R"({"dem": "ok.exr", "spacing": 0})"), "terrain.spacing: must be > 0");
        expect(withTerrain(R"({"dem": "ok.exr", "spacing": -2})"), "terrain.spacing: must be > 0");
        expect(withTerrain(R"({"dem": "ok.exr", "height_scale": 0})"), "terrain.height_scale: must be > 0");
        writeText(file("text.png"), "not an image");
        expect(withTerrain(R"({"dem": "text.png"})"), "cannot read the DEM");
        expect(withTerrain(R"({"dem": "ok.exr", "colour": 1})"), "unknown field");
        // Too large for the memory left (checked before allocating): a 2 x 2 DEM under a 0 MB limit.
        qputenv("SYLVA_MEMORY_LIMIT_MB", "0.00001");
        const std::string big = withTerrain(R"({"dem": "ok.exr"})");
        qunsetenv("SYLVA_MEMORY_LIMIT_MB");
        expect(big, "MiB are available");
        // No instances and no terrain is a scene too (the ground and sky alone: tst_bare_scene).
        writeText(scene, R"({"version": 1, "species": [{"name": "s", "grow": {"species": "shrub"}}], "instances": []})");
        QCOMPARE(test::sceneFileError(scene), test::kNoError);
        writeText(scene, R"({"version": 1, "species": [{"name": "s", "grow": {"species": "shrub"}}],
            "instances": [{"species": "s", "position": [0, 0, 0], "on_terrain": true}]})");
        expect(test::sceneFileError(scene), "instances[0].on_terrain: needs a terrain");
    }
};

QTEST_GUILESS_MAIN(TestTerrain)
#include "tst_terrain.moc"
