// A scene without plants (ground, sky and volumes alone: look development before any plant) is a scene
// file and renders: read and written back, `sylva render` of a sunlit ground against the closed form
// albedo x (sunRadiance x cos + sky), the sky seen at the horizon, a cloud over the bare ground darkening
// what it shades and leaving the rest of the picture alone.
#include <QTest>

#include <algorithm>
#include <cmath>
#include <string>

#include "core/image/image.h"
#include "pipeline/io/image_io.h"
#include "pipeline/render/render_job.h"
#include "pipeline/scene/scene_file.h"
#include "tests/common/files.h"
#include "tests/common/run_program.h"
#include "tests/common/scenes.h"

using namespace sylva;

namespace {

// The sunlit ground under the constant sky: sun at 50 degrees, ground albedo (0.5, 0.3, 0.2), sky (0.3, 0.4, 0.6).
QByteArray bareScene(const char* camera, const char* volumes = "")
{
    return QByteArray(R"({"version": 1,
        "ground": {"color": [0.5, 0.3, 0.2]},
        "sun": {"elevation": 50, "azimuth": 30, "temperature": 5000},
        "sky": {"color": [0.3, 0.4, 0.6]},
        "camera": )") +
           camera + R"(,
        "render": {"width": 32, "height": 24, "spp": 4})" +
           volumes + "}\n";
}

const char* kDown = R"({"position": [0, 6, 0], "target": [0, 0, 2], "fov": 30})";
const char* kHorizon = R"({"position": [0, 2, 0], "target": [0, 2, 10], "fov": 40})";

ImageRgba renderFile(const QString& dir, const QString& name, const QByteArray& text, const QStringList& extra = {})
{
    const QString scene = dir + "/" + name + ".sylva.json", out = dir + "/" + name + ".exr";
    test::writeText(scene, text);
    const test::Run r = test::runSylva(QStringList{"render", scene, "-o", out, "--quiet"} + extra, dir + "/cache");
    if (r.code != 0) qWarning("%s", qPrintable(r.err));
    if (r.code != 0) return {};
    return readImage(out.toStdString());
}

glm::vec3 pixel(const ImageRgba& img, int x, int y)
{
    const float* p = &img.pixels[(size_t(y) * size_t(img.width) + size_t(x)) * 4];
    return {p[0], p[1], p[2]};
}

} // namespace

class TestBareScene : public QObject {
    Q_OBJECT

private Q_SLOTS:
    void readsAndWritesBack()
    {
        const QString dir = test::outputDir("bare_scene_file");
        for (const QByteArray& text : {QByteArray(R"({"version": 1})"), QByteArray(R"({"version": 1, "species": [], "instances": []})"),
                                       bareScene(kDown)}) {
            const QString path = dir + "/scene.sylva.json";
            test::writeText(path, text);
            const Scene s = readSceneFile(path.toStdString());
            QVERIFY(s.species.empty());
            QVERIFY(s.instances.empty());
            const QString again = dir + "/again.sylva.json";
            writeSceneFile(s, again.toStdString());
            const Scene t = readSceneFile(again.toStdString());
            QCOMPARE(sceneToJson(t, dir.toStdString()), sceneToJson(s, dir.toStdString()));
            QVERIFY(describeScene(s).find("0 species, 0 instances") != std::string::npos);
            QVERIFY(describeScene(s).find("terrain") == std::string::npos);   // none: no line for it
        }
        // An instance still needs a species that exists.
        const QString bad = dir + "/bad.sylva.json";
        test::writeText(bad, R"({"version": 1, "instances": [{"species": "oak", "position": [0, 0, 0]}]})");
        const std::string err = test::sceneFileError(bad.toStdString());
        QVERIFY2(err.find("instances[0].species") != std::string::npos, err.c_str());
    }

    // `sylva render` of the bare ground: every pixel albedo x (sunRadiance x cos + sky) (the EXR's half
    // floats: 1e-3); at the horizon, the pixels above it the sky's colour.
    void rendersTheGroundAndSky()
    {
        const QString dir = test::outputDir("bare_scene_render");
        const ImageRgba down = renderFile(dir, "down", bareScene(kDown));
        QCOMPARE(down.width, 32);
        QCOMPARE(down.height, 24);
        const Scene s = readSceneFile((dir + "/down.sylva.json").toStdString());
        const glm::vec3 rad = sunRadiance(s.sun);
        const double cosSun = double(glm::normalize(s.sun.direction).y);
        double worst = 0.0;
        for (int y = 0; y < down.height; ++y)
            for (int x = 0; x < down.width; ++x)
                for (int k = 0; k < 3; ++k) {
                    const double expected = double(s.ground.color[k]) * (double(rad[k]) * cosSun + double(s.sky[k]));
                    worst = std::max(worst, std::fabs(double(pixel(down, x, y)[k]) / expected - 1.0));
                }
        qInfo("the bare ground against the closed form: largest relative difference %.2e", worst);
        QVERIFY2(worst < 1e-3, qPrintable(QString::number(worst)));

        const ImageRgba horizon = renderFile(dir, "horizon", bareScene(kHorizon));
        QCOMPARE(horizon.height, 24);
        for (int x = 0; x < horizon.width; ++x) {
            const glm::vec3 top = pixel(horizon, x, 0);
            for (int k = 0; k < 3; ++k) QVERIFY2(std::fabs(top[k] / s.sky[k] - 1.0f) < 1e-3f, qPrintable(QString::number(top[k])));
            const glm::vec3 bottom = pixel(horizon, x, horizon.height - 1);   // the ground below the horizon
            QVERIFY(std::fabs(bottom.x / (s.ground.color.x * (rad.x * float(cosSun) + s.sky.x)) - 1.0f) < 1e-3f);
        }
    }

    // The bundled cloud over the bare ground (single scattering: no LB solve): the ground in its shadow is
    // darker than the open ground, the pixels the cloud covers differ, and the rest is the picture without it.
    void rendersAVolumeAlone()
    {
        const QString dir = test::outputDir("bare_scene_volume");
        const char* camera = R"({"position": [0, 9, -30], "target": [0, 8, 20], "fov": 50})";
        const QByteArray cloud = QByteArray(R"(, "volumes": [{"name": "cumulus", "grid": "GRID", "preset": "cloud", "tracer": "single",
                                                 "step": 4, "instances": [{"position": [8, 17, 4]}]}])")
                                     .replace("GRID", SYLVA_SOURCE_DIR "/resources/cloud/cloud.npy");
        // The cloud example's sun, which puts the cloud's shadow in its view.
        auto withSun = [](QByteArray t) { return t.replace("elevation\": 50, \"azimuth\": 30", "elevation\": 45, \"azimuth\": 150"); };
        const ImageRgba with = renderFile(dir, "with", withSun(bareScene(camera, cloud.constData())));
        const ImageRgba without = renderFile(dir, "without", withSun(bareScene(camera)));
        QCOMPARE(with.width, 32);
        QCOMPARE(without.width, 32);
        int changed = 0, darker = 0, same = 0;
        for (int y = 0; y < with.height; ++y)
            for (int x = 0; x < with.width; ++x) {
                const glm::vec3 a = pixel(with, x, y), b = pixel(without, x, y);
                if (a == b) {
                    ++same;
                    continue;
                }
                ++changed;
                if (y > with.height / 2 && a.x + a.y + a.z < b.x + b.y + b.z) ++darker;   // the ground, shaded
            }
        qInfo("the cloud changes %d of %d pixels, darkens %d of the ground's", changed, with.width * with.height, darker);
        QVERIFY(changed > 20);
        QVERIFY(same > 20);
        QVERIFY(darker > 0);
    }
};

QTEST_GUILESS_MAIN(TestBareScene)
#include "tst_bare_scene.moc"
