// Environment maps from files (pipeline/io/env_map_io) and `sylva sky`: the real HDRIs of resources/hdri
// (cleaned, their sun found, lights summing to the map), bad maps refused with clear errors, hostile values
// cleaned, and the written Preetham map read back against the model at the pixel centres.
#include <QDir>
#include <QFile>
#include <QProcess>
#include <QTest>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>
#include <vector>

#include <OpenImageIO/imageio.h>

#include "core/base/error.h"
#include "core/sky/env_map.h"
#include "core/sky/preetham.h"
#include "core/sky/sky_light.h"
#include "core/sky/virtual_lights.h"
#include "pipeline/io/env_map_io.h"
#include "pipeline/render/render_job.h"
#include "tests/common/files.h"
#include "tests/common/run_program.h"

using namespace sylva;

namespace {

std::string outPath(const char* name) { return (test::outputDir("sky_map", false) + "/" + name).toStdString(); }

// Writes a float RGB EXR through OpenImageIO.
void writeFloatExr(const std::string& path, int w, int h, const std::vector<float>& rgb, int channels = 3)
{
    auto out = OIIO::ImageOutput::create(path);
    QVERIFY(out);
    OIIO::ImageSpec spec(w, h, channels, OIIO::TypeDesc::FLOAT);
    QVERIFY(out->open(path, spec));
    QVERIFY(out->write_image(OIIO::TypeDesc::FLOAT, rgb.data()));
    QVERIFY(out->close());
}

std::vector<float> readFloat(const std::string& path, int* w, int* h, int* nc)
{
    auto in = OIIO::ImageInput::open(path);
    if (!in) return {};
    *w = in->spec().width, *h = in->spec().height, *nc = in->spec().nchannels;
    std::vector<float> px(size_t(*w) * size_t(*h) * size_t(*nc));
    in->read_image(0, 0, 0, *nc, OIIO::TypeDesc::FLOAT, px.data());
    return px;
}

std::string errorOf(const std::string& path) { return test::errorOf([&] { readEnvMap(path); }); }

using test::Run;
using test::runSylva;

double lumOf(glm::dvec3 c) { return 0.2126 * c.x + 0.7152 * c.y + 0.0722 * c.z; }

} // namespace

class TestSkyMap : public QObject {
    Q_OBJECT
private Q_SLOTS:
    void realMaps()
    {
        const QString dir = QString(SYLVA_RESOURCES) + "/hdri";
        QVERIFY2(QDir(dir).exists(), qPrintable(dir));
        int suns = 0;
        for (const char* name : {"forest", "sky", "park", "sunset", "dawn"}) {
            const std::string path = (dir + "/" + name + ".exr").toStdString();
            // The raw file, for the counts the cleaning must report.
            int w = 0, h = 0, nc = 0;
            const std::vector<float> raw = readFloat(path, &w, &h, &nc);
            size_t negative = 0;
            for (size_t p = 0; p < size_t(w) * size_t(h); ++p) {
                bool neg = false;
                for (int c = 0; c < 3; ++c) neg = neg || raw[p * size_t(nc) + size_t(c)] < 0.0f;
                negative += neg ? 1 : 0;
            }
            EnvMapFile f = readEnvMap(path);
            QCOMPARE(f.map.width, 512);
            QCOMPARE(f.map.height, 256);
            QCOMPARE(f.cleaned.negative, negative);
            for (float v : f.map.rgb) QVERIFY(std::isfinite(v) && v >= 0.0f);
            // Cleaning never adds light: no pixel's luminance exceeds that of its raw value clamped at 0.
            for (size_t p = 0; p < size_t(w) * size_t(h); ++p) {
                glm::dvec3 clamped, now;
                for (int c = 0; c < 3; ++c) {
                    clamped[c] = std::max(raw[p * size_t(nc) + size_t(c)], 0.0f);
                    now[c] = f.map.rgb[p * 3 + size_t(c)];
                }
                QVERIFY(lumOf(now) <= lumOf(clamped) * (1.0 + 1e-6) + 1e-12);
            }
            const glm::dvec3 before = sky::envMapIntegral(f.map);
            sky::FoundSun found;
            const sky::Sky s = sky::mapSky(f.map, 0.0f, 1.0f, true, &found);
            const glm::dvec3 after = sky::skyTotal(s);
            qInfo("%s; sun: %s, %d pixels, peak %.4g, median %.4g, illuminance %.4g = %.1f%% of the map's power, direction (%.3f, %.3f, %.3f)",
                  envMapCleanSummary(name, f).c_str(), found.sun.present ? "found" : "none", found.pixels, double(found.peakLuminance),
                  double(found.medianLuminance), double(found.sun.illuminance), 100.0 * found.sun.illuminance / lumOf(before),
                  double(found.sun.direction.x), double(found.sun.direction.y), double(found.sun.direction.z));
            suns += found.sun.present ? 1 : 0;
            // Energy: the map after plus the sun is the map before.
            QVERIFY(glm::length(after + glm::dvec3(s.sun.radiance()) - before) < 1e-4 * glm::length(before));
            // The lights of the map (sun apart) sum to its integral.
            glm::dvec3 sum(0.0);
            for (const sky::VirtualLight& l : sky::skyLights(s, 256)) sum += glm::dvec3(l.power);
            QVERIFY(glm::length(sum - after) < 1e-5 * glm::length(after));
        }
        QVERIFY(suns >= 3);   // sky, park and sunset show a compact sun; forest and dawn none
    }

    void badMaps()
    {
        // Missing, empty, not an image, 1 x N, not 2:1.
        QVERIFY(errorOf(outPath("missing.exr")).find("no such") != std::string::npos);
        {
            QFile f(QString::fromStdString(outPath("empty.exr")));
            QVERIFY(f.open(QIODevice::WriteOnly));
        }
        QVERIFY(errorOf(outPath("empty.exr")).find("not an image") != std::string::npos);
        {
            QFile f(QString::fromStdString(outPath("text.hdr")));
            QVERIFY(f.open(QIODevice::WriteOnly));
            f.write("this is not a picture\n");
        }
        QVERIFY(errorOf(outPath("text.hdr")).find("not an image") != std::string::npos);
        writeFloatExr(outPath("column.exr"), 1, 8, std::vector<float>(24, 1.0f));
        const std::string column = errorOf(outPath("column.exr"));
        QVERIFY2(column.find("1 x 8") != std::string::npos && column.find("too small") != std::string::npos, column.c_str());
        writeFloatExr(outPath("square.exr"), 16, 16, std::vector<float>(16 * 16 * 3, 1.0f));
        const std::string square = errorOf(outPath("square.exr"));
        QVERIFY2(square.find("twice as wide") != std::string::npos && square.find("16 x 16") != std::string::npos, square.c_str());
        QVERIFY(errorOf(QDir::tempPath().toStdString()).find("folder") != std::string::npos);
    }

    void hostileValuesCleaned()
    {
        const int w = 32, h = 16;
        std::vector<float> px(size_t(w) * size_t(h) * 3, 0.5f);
        px[0] = -1.0f;
        px[3 * 7 + 1] = std::numeric_limits<float>::quiet_NaN();
        px[3 * 40 + 2] = std::numeric_limits<float>::infinity();
        px[3 * 41] = -std::numeric_limits<float>::infinity();
        writeFloatExr(outPath("hostile.exr"), w, h, px);
        const EnvMapFile f = readEnvMap(outPath("hostile.exr"));
        QCOMPARE(f.cleaned.negative, size_t(1));
        QCOMPARE(f.cleaned.nonFinite, size_t(3));
        for (float v : f.map.rgb) QVERIFY(std::isfinite(v) && v >= 0.0f);
        QVERIFY(envMapCleanSummary("hostile.exr", f).find("1 pixels with negative values") != std::string::npos);
        // And nothing downstream turns into NaN.
        const sky::Sky s = sky::mapSky(f.map, 10.0f, 1.0f);
        for (const sky::VirtualLight& l : sky::skyLights(s, 16)) QVERIFY(std::isfinite(l.power.x + l.power.y + l.power.z) && glm::all(glm::greaterThanEqual(l.power, glm::vec3(0.0f))));
        // Radiance .hdr (RGBE: 8-bit mantissas) reads back within its precision.
        std::vector<float> ramp(size_t(w) * size_t(h) * 3);
        for (size_t i = 0; i < ramp.size(); ++i) ramp[i] = 0.01f * float(i % 97) + float(i % 3) * 100.0f;
        writeFloatExr(outPath("ramp.hdr"), w, h, ramp);
        const EnvMapFile hdr = readEnvMap(outPath("ramp.hdr"));
        QCOMPARE(hdr.map.width, w);
        for (size_t p = 0; p < size_t(w) * size_t(h); ++p) {
            const float big = std::max({ramp[p * 3], ramp[p * 3 + 1], ramp[p * 3 + 2]});
            for (int c = 0; c < 3; ++c) QVERIFY(std::abs(hdr.map.rgb[p * 3 + size_t(c)] - ramp[p * 3 + size_t(c)]) <= big / 128.0f + 1e-6f);
        }
        // A grey (one-channel) map is read into all three.
        writeFloatExr(outPath("grey.exr"), 8, 4, std::vector<float>(32, 2.0f), 1);
        const EnvMapFile g = readEnvMap(outPath("grey.exr"));
        QCOMPARE(g.map.at(3, 2), glm::vec3(2.0f));
    }

    void skyCommandWritesTheModel()
    {
        const std::string out = outPath("preetham.exr");
        QFile::remove(QString::fromStdString(out));
        const Run r = runSylva({"sky", "--turbidity", "4.5", "--sun", "0.3,0.5,-0.6", "--width", "128", "-o", QString::fromStdString(out)});
        QVERIFY2(r.code == 0, qPrintable(r.err));
        QVERIFY(r.out.contains("wrote"));
        int w = 0, h = 0, nc = 0;
        const std::vector<float> px = readFloat(out, &w, &h, &nc);
        QCOMPARE(w, 128);
        QCOMPARE(h, 64);
        QCOMPARE(nc, 3);
        const sky::PreethamSky model = sky::makePreetham({.turbidity = 4.5, .sunDirection = glm::vec3(0.3f, 0.5f, -0.6f)});
        double worst = 0.0;
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x) {
                // The pixel centre's direction, from the documented convention (not through env_map.cpp).
                const double theta = M_PI * (y + 0.5) / h, az = M_PI * (1.0 - 2.0 * (x + 0.5) / w);
                const glm::vec3 d(float(std::sin(theta) * std::sin(az)), float(std::cos(theta)), float(std::sin(theta) * std::cos(az)));
                const glm::vec3 want = sky::preethamRadiance(model, d);
                for (int c = 0; c < 3; ++c) {
                    const double got = px[(size_t(y) * size_t(w) + size_t(x)) * 3 + size_t(c)];
                    const double err = std::abs(got - want[c]) / (std::abs(want[c]) + 1e-3);
                    worst = std::max(worst, err);
                }
            }
        QVERIFY2(worst < 1e-3, qPrintable(QString::number(worst)));   // half floats: 11-bit mantissa
        // Bad usage: odd width, turbidity outside 2 .. 10, sun too far below the horizon, not an HDR file.
        QCOMPARE(runSylva({"sky", "--width", "101", "-o", QString::fromStdString(out)}).code, 2);
        QCOMPARE(runSylva({"sky", "--turbidity", "12", "-o", QString::fromStdString(out)}).code, 2);
        QCOMPARE(runSylva({"sky", "--sun", "0,0,0", "-o", QString::fromStdString(out)}).code, 2);
        QCOMPARE(runSylva({"sky", "-o", QString::fromStdString(outPath("sky.png"))}).code, 2);
        const Run below = runSylva({"sky", "--sun", "1,-0.5,0", "-o", QString::fromStdString(out)});
        QCOMPARE(below.code, 1);
        QVERIFY(below.err.contains("below the horizon"));
        // The sun by date and place: NREL SPA's example (Reda & Andreas 2004: elevation 90 - 50.11162,
        // bearing 194.34024), parsed from the command line.
        const Run at = runSylva({"sky", "--sun-at", "2003-10-17,12:30:30,-7,39.742476,-105.1786", "--width", "16", "-o", QString::fromStdString(out)});
        QVERIFY2(at.code == 0, qPrintable(at.err));
        double el = 0.0, az = 0.0, bearing = 0.0;
        const int idx = at.out.indexOf("elevation ");
        QVERIFY(idx >= 0);
        QCOMPARE(std::sscanf(at.out.mid(idx).toUtf8().constData(), "elevation %lf deg, azimuth %lf deg (compass bearing %lf", &el, &az, &bearing), 3);
        QVERIFY(std::abs(el - (90.0 - 50.11162)) < 0.02 && std::abs(bearing - 194.34024) < 0.02 && std::abs(az - (180.0 - 194.34024 + 360.0)) < 0.02);
        for (const char* bad : {"2003-10-17,12:30,-7,39.7", "2003-13-17,12:30,-7,39.7,-105", "2003-10-17,12h30,-7,39.7,-105", "2003-10-17,12:30,-7,95,-105"})
            QCOMPARE(runSylva({"sky", "--sun-at", bad, "-o", QString::fromStdString(out)}).code, 2);
        QCOMPARE(runSylva({"sky", "--sun", "0,1,0", "--sun-at", "2003-10-17,12:30,-7,39.7,-105", "-o", QString::fromStdString(out)}).code, 2);
        // render takes the same option (so do light and reference), checked before any work.
        {
            const Run bad = runSylva({"render", "--sun-at", "2003-02-29,12:30,-7,39.7,-105", "-o", QString::fromStdString(outPath("x.png"))});
            QCOMPARE(bad.code, 2);
            QVERIFY2(bad.err.contains("--sun-at") && bad.err.contains("day"), qPrintable(bad.err));
        }
        QCOMPARE(runSylva({"render", "--sun", "0,1,0", "--sun-at", "2003-10-17,12:30,-7,39.7,-105"}).code, 2);
        // The sun from a scene file.
        const std::string scene = outPath("sun.sylva.json");
        {
            QFile f(QString::fromStdString(scene));
            QVERIFY(f.open(QIODevice::WriteOnly));
            f.write("{\"version\": 1, \"species\": [{\"name\": \"a\", \"grow\": {\"species\": \"broadleaf\"}}], \"instances\": [{\"species\": \"a\", \"position\": [0, 0, 0]}], \"sun\": {\"elevation\": 12, \"azimuth\": 250}}");
        }
        const Run fromScene = runSylva({"sky", QString::fromStdString(scene), "--width", "64", "-o", QString::fromStdString(outPath("scene_sky.exr"))});
        QVERIFY2(fromScene.code == 0, qPrintable(fromScene.err));
        QVERIFY2(fromScene.out.contains("sun elevation 12.00"), qPrintable(fromScene.out));
    }
};

QTEST_APPLESS_MAIN(TestSkyMap)
#include "tst_sky_map.moc"
