// The picture's display transforms (pipeline/render/display_view.h): OpenColorIO's views of the bundled config
// against OpenColorIO's own `ocioconvert` on the same pixels (synthesized, and a render's EXR exposed as
// `sylva render` exposes it); the default view is the seed's picture, to the bit; $OCIO's config replaces
// the bundled one; the EXR's header names its colour space.
#include <QProcessEnvironment>
#include <QStandardPaths>
#include <QTest>

#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "core/render/tonemap.h"
#include "pipeline/io/image_io.h"
#include "pipeline/render/display_view.h"
#include "pipeline/render/render_job.h"
#include "pipeline/scene/scene_file.h"
#include "tests/common/files.h"
#include "tests/common/run_program.h"

using namespace sylva;

namespace {

const QString kBundledConfig = QStringLiteral(SYLVA_RESOURCES "/ocio/config.ocio");
const std::vector<std::string> kOcioViews = {"Standard", "ACES 1.0 SDR-video", "Sylva Filmic"};

// A sunlit ground under a Preetham sky, the camera facing the sun: shadows to the sky around the sun.
const QByteArray kScene = R"({"version": 1,
    "ground": {"color": [0.35, 0.3, 0.2]},
    "sun": {"elevation": 12, "azimuth": 20},
    "sky": {"kind": "preetham"},
    "camera": {"position": [0, 1.5, 0], "target": [0, 3, 10], "fov": 70},
    "render": {"width": 48, "height": 32, "spp": 1RENDER}}
)";

QByteArray scene(const QByteArray& renderExtra = {}) { return QByteArray(kScene).replace("RENDER", renderExtra); }

// The sRGB encoding (IEC 61966-2-1) of a value clipped to [0, 1], in double.
double srgb(double v)
{
    v = std::clamp(v, 0.0, 1.0);
    return v <= 0.0031308 ? 12.92 * v : 1.055 * std::pow(v, 1.0 / 2.4) - 0.055;
}

// Linear RGB test pixels: 64 exposures from 2^-14 to 2^6 along x, a colour per row (greys, primaries,
// foliage, sky, a warm light, a slightly negative channel), 3 floats a pixel.
std::vector<float> testPixels(int& width, int& height)
{
    const float colours[][3] = {{1, 1, 1},       {1, 0, 0},         {0, 1, 0},    {0, 0, 1},       {0.2f, 0.5f, 0.08f},
                                {0.4f, 0.6f, 1}, {1, 0.75f, 0.45f}, {1, 1, 0.2f}, {0.5f, 0, 0.5f}, {0.3f, 0.5f, -0.01f}};
    width = 64;
    height = int(std::size(colours));
    std::vector<float> px;
    for (int y = 0; y < height; ++y)
        for (int x = 0; x < width; ++x) {
            const float e = std::exp2(-14.0f + 20.0f * float(x) / float(width - 1));
            for (int c = 0; c < 3; ++c) px.push_back(colours[y][c] * e);
        }
    return px;
}

// RGB of an image read back (RGBA float), 3 floats a pixel.
std::vector<float> rgbOf(const ImageRgba& img)
{
    std::vector<float> out;
    for (size_t p = 0; p < size_t(img.width) * size_t(img.height); ++p)
        for (int c = 0; c < 3; ++c) out.push_back(img.pixels[p * 4 + size_t(c)]);
    return out;
}

// `ocioconvert --view IN lin_rec709 OUT DISPLAY VIEW` under the config `config`: the converted pixels (empty
// with a warning when it failed).
std::vector<float> ocioconvert(const QString& config, const QString& in, const QString& out, const std::string& display,
                               const std::string& view)
{
    QProcessEnvironment env = QProcessEnvironment::systemEnvironment();
    env.insert("OCIO", config);
    const test::Run r = test::runProgram(QStandardPaths::findExecutable("ocioconvert"),
                                         {"--view", in, "lin_rec709", out, QString::fromStdString(display), QString::fromStdString(view)}, env);
    if (r.code != 0) {
        qWarning("ocioconvert failed (%d): %s", r.code, qPrintable(r.err + r.out));
        return {};
    }
    return rgbOf(readImage(out.toStdString()));
}

// The largest difference of two pictures (3 floats a pixel), and how many values differ by more than tol.
struct Difference {
    double largest = 0.0;
    int over = 0;
};
Difference difference(const std::vector<float>& a, const std::vector<float>& b, double tol)
{
    Difference d;
    if (a.size() != b.size()) return {1e30, int(std::max(a.size(), b.size()))};
    for (size_t i = 0; i < a.size(); ++i) {
        const double e = std::fabs(double(a[i]) - double(b[i]));
        d.largest = std::max(d.largest, e);
        d.over += e > tol ? 1 : 0;
    }
    return d;
}

// The environment of `sylva` with $OCIO set to `config` (empty: unset).
QProcessEnvironment ocioEnv(const QString& dir, const QString& config)
{
    QProcessEnvironment env = QProcessEnvironment::systemEnvironment();
    env.remove("OCIO");
    if (!config.isEmpty()) env.insert("OCIO", config);
    env.insert("XDG_CACHE_HOME", dir + "/cache");
    return env;
}

test::Run runWith(const QStringList& args, const QProcessEnvironment& env) { return test::runProgram(SYLVA_CLI_PATH, args, env); }

// A render's linear EXR exposed as `sylva render` exposes it (key 0.18 over the log-average luminance).
std::vector<float> exposed(const ImageRgba& linear)
{
    std::vector<float> rgb = rgbOf(linear);
    const float scale = toneMapScale(logAverageLuminance(rgb.data(), rgb.size() / 3, 3));
    for (float& v : rgb) v *= scale;
    return rgb;
}

} // namespace

class TestDisplayView : public QObject {
    Q_OBJECT

private Q_SLOTS:
    void initTestCase() { qunsetenv("OCIO"); }   // this process reads the bundled config

    // The bundled config's displays and views, Sylva Reinhard first and the default; unknown names refused
    // with the names there are.
    void bundledViews()
    {
        QCOMPARE(RenderSettings{}.view, std::string(kReinhardView));
        QVERIFY(RenderSettings{}.display.empty());
        const ColorConfigInfo& c = colorConfig();
        QCOMPARE(c.source, std::string("the bundled config"));
        QCOMPARE(c.name, std::string("sylva"));
        QCOMPARE(c.inputSpace, std::string("lin_rec709"));
        QCOMPARE(c.defaultDisplay, std::string("sRGB"));
        QCOMPARE(int(c.displays.size()), 1);
        std::vector<std::string> views{kReinhardView};
        views.insert(views.end(), kOcioViews.begin(), kOcioViews.end());
        QCOMPARE(c.displays[0].views, views);
        QCOMPARE(QString::fromStdString(bundledColorConfigText()), test::readText(kBundledConfig));   // the file, built in
        QVERIFY(DisplayTransform().isReinhard());
        QVERIFY(DisplayTransform::find("", kReinhardView).isReinhard());
        QVERIFY(DisplayTransform::find("sRGB", kReinhardView).isReinhard());
        for (const std::string& v : kOcioViews) QVERIFY(!DisplayTransform::find("", v).isReinhard());
        const std::string unknownView = test::errorOf([] { DisplayTransform::find("", "Filmic"); });
        QVERIFY2(unknownView.find("unknown view 'Filmic' of display 'sRGB'") != std::string::npos, unknownView.c_str());
        QVERIFY2(unknownView.find("Sylva Reinhard, Standard, ACES 1.0 SDR-video, Sylva Filmic") != std::string::npos, unknownView.c_str());
        const std::string unknownDisplay = test::errorOf([] { DisplayTransform::find("P3", "Standard"); });
        QVERIFY2(unknownDisplay.find("unknown display 'P3'") != std::string::npos && unknownDisplay.find("displays: sRGB") != std::string::npos,
                 unknownDisplay.c_str());
        const std::string list = describeViews(c);
        QVERIFY2(list.find("sRGB (default): Sylva Reinhard, Standard, ACES 1.0 SDR-video, Sylva Filmic\n") != std::string::npos, list.c_str());
    }

    // Sylva Reinhard is the seed's tone mapping, bit for bit: toneMapScaled per pixel, toneMapToSrgb per
    // picture (non-finite and negative pixels included).
    void reinhardIsTheSeedsPicture()
    {
        int w = 0, h = 0;
        std::vector<float> px = testPixels(w, h);
        px[5] = std::nanf("");
        px[9] = INFINITY;
        const size_t n = px.size() / 3;
        std::vector<float> seed(px.size()), ours(px.size());
        toneMapScaled(px.data(), n, seed.data(), 3.7f);
        DisplayTransform::find("sRGB", kReinhardView).apply(px.data(), n, ours.data(), 3.7f);
        QVERIFY(seed == ours);
        ToneMapParams key;
        key.key = 0.3f;
        toneMapToSrgb(px.data(), n, seed.data(), key);
        displayEncode(px.data(), n, ours.data(), 0.3f, DisplayTransform());
        QVERIFY(seed == ours);
    }

    // The Standard view is the sRGB curve of the exposed value, clipped (the formula written again here):
    // within 2e-4 from 2^-14 to 2^6 in every colour of the test pixels; NaN gives 0.
    void standardIsTheSrgbCurve()
    {
        int w = 0, h = 0;
        std::vector<float> px = testPixels(w, h);
        std::vector<float> out(px.size());
        DisplayTransform::find("", "Standard").apply(px.data(), px.size() / 3, out.data(), 0.5f);
        double worst = 0.0;
        for (size_t i = 0; i < px.size(); ++i) worst = std::max(worst, std::fabs(double(out[i]) - srgb(0.5 * double(px[i]))));
        qInfo("Standard against the sRGB curve: largest difference %.2e", worst);
        QVERIFY2(worst < 2e-4, qPrintable(QString::number(worst)));
        const float bad[6] = {std::nanf(""), 0.5f, INFINITY, -INFINITY, 0.0f, 1e30f};
        for (const std::string& v : kOcioViews) {
            float o[6];
            DisplayTransform::find("", v).apply(bad, 2, o, 1.0f);
            for (float x : o) QVERIFY2(x >= 0.0f && x <= 1.0f, v.c_str());   // finite, in [0, 1]
            QCOMPARE(o[0], 0.0f);
        }
    }

    // Each view of the bundled config against ocioconvert --view on the same float EXR: within 1/255.
    void matchesOcioconvert()
    {
        if (QStandardPaths::findExecutable("ocioconvert").isEmpty())
            QSKIP("ocioconvert (Debian opencolorio-tools) is not installed: OpenColorIO's own conversion is not compared");
        const QString dir = test::outputDir("display_view_ocioconvert");
        int w = 0, h = 0;
        const std::vector<float> px = testPixels(w, h);
        const QString in = dir + "/in.exr";
        writeImageChannels(in.toStdString(), w, h, {"R", "G", "B"}, px);
        for (const std::string& view : kOcioViews) {
            const std::vector<float> theirs = ocioconvert(kBundledConfig, in, dir + "/out.exr", "sRGB", view);
            QVERIFY2(!theirs.empty(), view.c_str());
            std::vector<float> ours(px.size());
            DisplayTransform::find("sRGB", view).apply(px.data(), px.size() / 3, ours.data(), 1.0f);
            const Difference d = difference(ours, theirs, 1.0 / 255.0);
            qInfo("%s: ocioconvert and Sylva differ by at most %.2e over %zu values", view.c_str(), d.largest, px.size());
            QVERIFY2(d.over == 0, qPrintable(QString("%1: %2 values off").arg(QString::fromStdString(view)).arg(d.over)));
        }
    }

    // `sylva render --view V` of a scene: its PNG is the render's EXR, exposed with the key, through
    // ocioconvert (within 1/255 and the PNG's rounding); a frame in bands gives the same picture.
    void renderMatchesOcioconvert()
    {
        if (QStandardPaths::findExecutable("ocioconvert").isEmpty())
            QSKIP("ocioconvert (Debian opencolorio-tools) is not installed: OpenColorIO's own conversion is not compared");
        const QString dir = test::outputDir("display_view_render");
        const QProcessEnvironment env = ocioEnv(dir, {});
        const QString file = dir + "/scene.sylva.json";
        test::writeText(file, scene());
        const test::Run lin = runWith({"render", file, "-o", dir + "/lin.exr", "--quiet"}, env);
        QVERIFY2(lin.code == 0, qPrintable(lin.err));
        const ImageRgba linear = readImage((dir + "/lin.exr").toStdString());
        const std::vector<float> rgb = exposed(linear);
        const QString in = dir + "/exposed.exr";
        writeImageChannels(in.toStdString(), linear.width, linear.height, {"R", "G", "B"}, rgb);
        for (const std::string& view : kOcioViews) {
            const QString png = dir + "/" + QString::fromStdString(view).replace(' ', '_') + ".png";
            const test::Run r = runWith({"render", file, "--view", QString::fromStdString(view), "-o", png, "--quiet"}, env);
            QVERIFY2(r.code == 0, qPrintable(r.err));
            const std::vector<float> ours = rgbOf(readImage(png.toStdString()));
            const std::vector<float> theirs = ocioconvert(kBundledConfig, in, dir + "/out.exr", "sRGB", view);
            QVERIFY2(!theirs.empty(), view.c_str());
            const Difference d = difference(ours, theirs, 1.0 / 255.0 + 1e-6);
            qInfo("sylva render --view '%s' against ocioconvert of its EXR: largest difference %.2f / 255", view.c_str(), d.largest * 255.0);
            QVERIFY2(d.over == 0, qPrintable(QString("%1: %2 values off").arg(QString::fromStdString(view)).arg(d.over)));
            const QString bands = dir + "/bands.png";
            const test::Run b = runWith({"render", file, "--view", QString::fromStdString(view), "--band-rows", "8", "-o", bands, "--quiet"}, env);
            QVERIFY2(b.code == 0, qPrintable(b.err));
            QVERIFY2(rgbOf(readImage(bands.toStdString())) == ours, view.c_str());
        }
    }

    // Without a view the picture is the seed's: the PNG equals the seed's tone mapping (toneMapToSrgb) of the
    // render computed in this process, to the bit, and `--view "Sylva Reinhard"` writes the same file; a scene's
    // render.view is the option's picture, read and written back (and not written when it is the default).
    void defaultViewKeepsThePicture()
    {
        const QString dir = test::outputDir("display_view_default");
        const QProcessEnvironment env = ocioEnv(dir, {});
        const QString file = dir + "/scene.sylva.json";
        test::writeText(file, scene());
        QVERIFY(runWith({"render", file, "-o", dir + "/default.png", "--quiet"}, env).code == 0);
        QVERIFY(runWith({"render", file, "--view", kReinhardView, "-o", dir + "/reinhard.png", "--quiet"}, env).code == 0);
        QFile a(dir + "/default.png"), b(dir + "/reinhard.png");
        QVERIFY(a.open(QIODevice::ReadOnly) && b.open(QIODevice::ReadOnly));
        QVERIFY(a.readAll() == b.readAll());

        const Scene s = readSceneFile(file.toStdString());
        QVERIFY(sceneToJson(s, dir.toStdString()).find("\"view\"") == std::string::npos);
        const RenderOutput out = renderScene(s, nullptr);
        const std::vector<glm::vec3> linear = composeMode(out.film, s.render.mode, composeSky(s));
        std::vector<float> seed(linear.size() * 3);
        toneMapToSrgb(&linear[0].x, linear.size(), seed.data(), ToneMapParams{s.render.exposureKey});
        const std::vector<float> png = rgbOf(readImage((dir + "/default.png").toStdString()));
        QCOMPARE(png.size(), seed.size());
        int off = 0;
        for (size_t i = 0; i < seed.size(); ++i) off += int(std::lround(png[i] * 255.0f)) != int(seed[i] * 255.0f + 0.5f) ? 1 : 0;
        QCOMPARE(off, 0);

        const QString withView = dir + "/filmic.sylva.json";
        test::writeText(withView, scene(R"(, "view": "Sylva Filmic", "display": "sRGB")"));
        const Scene f = readSceneFile(withView.toStdString());
        QCOMPARE(f.render.view, std::string("Sylva Filmic"));
        QCOMPARE(f.render.display, std::string("sRGB"));
        const std::string text = sceneToJson(f, dir.toStdString());
        QVERIFY2(text.find("\"view\": \"Sylva Filmic\", \"display\": \"sRGB\"") != std::string::npos, text.c_str());
        QVERIFY(runWith({"render", withView, "-o", dir + "/scene_view.png", "--quiet"}, env).code == 0);
        QVERIFY(runWith({"render", file, "--view", "Sylva Filmic", "-o", dir + "/option_view.png", "--quiet"}, env).code == 0);
        const ImageRgba fromScene = readImage((dir + "/scene_view.png").toStdString());
        QVERIFY(fromScene.pixels == readImage((dir + "/option_view.png").toStdString()).pixels);
        QVERIFY(fromScene.pixels != readImage((dir + "/default.png").toStdString()).pixels);
        // An empty view is refused on reading; an unknown one before any work, naming the views.
        test::writeText(withView, scene(R"(, "view": "")"));
        const std::string empty = test::errorOf([&] { readSceneFile(withView.toStdString()); });
        QVERIFY2(empty.find("render.view: must name a view") != std::string::npos, empty.c_str());
        test::writeText(withView, scene(R"(, "view": "Filmic")"));
        const test::Run unknown = runWith({"render", withView, "-o", dir + "/unknown.png", "--quiet"}, env);
        QCOMPARE(unknown.code, 1);
        QVERIFY2(unknown.err.contains("unknown view 'Filmic'") && unknown.err.contains("Sylva Reinhard, Standard"), qPrintable(unknown.err));
        QVERIFY(!QFile::exists(dir + "/unknown.png"));
    }

    // $OCIO's config (one written here: display Test, view Half = half the exposed value) replaces the bundled
    // one: --list-views shows it, --view Half renders through it, the bundled views are unknown there (exit 2,
    // the views listed); a config that cannot be read is named, and the default view needs none.
    void ocioVariableIsHonoured()
    {
        const QString dir = test::outputDir("display_view_env");
        const QString config = dir + "/half.ocio";
        test::writeText(config, R"(ocio_profile_version: 2
roles:
  default: linear
  scene_linear: linear
file_rules:
  - !<Rule> {name: Default, colorspace: default}
displays:
  Test:
    - !<View> {name: Half, colorspace: half}
active_displays: []
active_views: []
colorspaces:
  - !<ColorSpace> {name: linear, isdata: false}
  - !<ColorSpace>
    name: half
    isdata: false
    from_scene_reference: !<MatrixTransform> {matrix: [0.5, 0, 0, 0, 0, 0.5, 0, 0, 0, 0, 0.5, 0, 0, 0, 0, 1]}
)");
        const QProcessEnvironment env = ocioEnv(dir, config);
        const test::Run list = runWith({"render", "--list-views"}, env);
        QCOMPARE(list.code, 0);
        QVERIFY2(list.out.contains("$OCIO (" + config + ")") && list.out.contains("pixels enter as linear") &&
                     list.out.contains("Test (default): Sylva Reinhard, Half\n"),
                 qPrintable(list.out));
        const QString bundled = runWith({"render", "--list-views"}, ocioEnv(dir, {})).out;
        QVERIFY2(bundled.contains("the bundled config") && bundled.contains("sRGB (default): Sylva Reinhard, Standard"), qPrintable(bundled));

        const QString file = dir + "/scene.sylva.json";
        test::writeText(file, scene());
        QVERIFY(runWith({"render", file, "-o", dir + "/lin.exr", "--quiet"}, env).code == 0);
        QVERIFY(runWith({"render", file, "--view", "Half", "-o", dir + "/half.png", "--quiet"}, env).code == 0);
        std::vector<float> want = exposed(readImage((dir + "/lin.exr").toStdString()));
        for (float& v : want) v = std::clamp(0.5f * v, 0.0f, 1.0f);
        const Difference d = difference(rgbOf(readImage((dir + "/half.png").toStdString())), want, 1.0 / 255.0 + 1e-6);
        qInfo("--view Half of $OCIO's config: largest difference %.2f / 255", d.largest * 255.0);
        QCOMPARE(d.over, 0);

        const test::Run standard = runWith({"render", file, "--view", "Standard", "-o", dir + "/standard.png", "--quiet"}, env);
        QCOMPARE(standard.code, 2);
        QVERIFY2(standard.err.contains("unknown view 'Standard' of display 'Test'") && standard.err.contains("views: Sylva Reinhard, Half"),
                 qPrintable(standard.err));
        QVERIFY(!QFile::exists(dir + "/standard.png"));
        const test::Run display = runWith({"render", file, "--display", "sRGB", "--view", "Half", "-o", dir + "/x.png", "--quiet"}, env);
        QCOMPARE(display.code, 2);
        QVERIFY2(display.err.contains("unknown display 'sRGB'") && display.err.contains("displays: Test"), qPrintable(display.err));

        const QProcessEnvironment missing = ocioEnv(dir, dir + "/missing.ocio");
        const test::Run broken = runWith({"render", "--list-views"}, missing);
        QCOMPARE(broken.code, 1);
        QVERIFY2(broken.err.contains("$OCIO=" + dir + "/missing.ocio"), qPrintable(broken.err));
        QVERIFY(runWith({"render", file, "-o", dir + "/default.png", "--quiet"}, missing).code == 0);
    }

    // The linear EXR's header names scene-linear Rec.709: the Rec.709 primaries and D65 white as OpenEXR's
    // chromaticities, and the colour interop ID, for a whole frame, a frame in bands and the passes.
    void exrNamesItsColourSpace()
    {
        const QString dir = test::outputDir("display_view_exr");
        const QProcessEnvironment env = ocioEnv(dir, {});
        const QString file = dir + "/scene.sylva.json";
        test::writeText(file, scene());
        QVERIFY(runWith({"render", file, "-o", dir + "/whole.exr", "--quiet"}, env).code == 0);
        QVERIFY(runWith({"render", file, "--band-rows", "8", "-o", dir + "/bands.exr", "--quiet"}, env).code == 0);
        QVERIFY(runWith({"render", file, "--passes", "-o", dir + "/passes.exr", "--quiet"}, env).code == 0);
        const test::Run note = runWith({"render", file, "--view", "Standard", "-o", dir + "/view.exr", "--quiet"}, env);
        QVERIFY2(note.code == 0 && note.err.contains("stays scene-linear"), qPrintable(note.err));
        for (const char* name : {"whole.exr", "bands.exr", "passes.exr", "view.exr"}) {
            auto in = OIIO::ImageInput::open((dir + "/" + name).toStdString());
            QVERIFY2(in, name);
            const OIIO::ImageSpec& spec = in->spec();
            const OIIO::ParamValue* chroma = spec.find_attribute("chromaticities");
            QVERIFY2(chroma && chroma->type() == OIIO::TypeDesc(OIIO::TypeDesc::FLOAT, 8), name);
            const float want[8] = {0.64f, 0.33f, 0.30f, 0.60f, 0.15f, 0.06f, 0.3127f, 0.3290f};
            for (int i = 0; i < 8; ++i) QCOMPARE(static_cast<const float*>(chroma->data())[i], want[i]);
            QCOMPARE(QString::fromStdString(spec.get_string_attribute("colorInteropID")), QStringLiteral("lin_rec709_scene"));
            in->close();
        }
        QVERIFY(readImage((dir + "/view.exr").toStdString()).pixels == readImage((dir + "/whole.exr").toStdString()).pixels);
    }
};

QTEST_GUILESS_MAIN(TestDisplayView)
#include "tst_display_view.moc"
