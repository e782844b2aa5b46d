// Aerial perspective (core/render/surfaces/atmosphere.h): the air column's closed form against quadrature; the
// vertical column from sea level is the Preetham sun's air at the zenith; a ground plane seen from 1000 m renders
// as the picture without air x T + (1 - T) x the sky, with T integrated in the test over the density along each
// pixel's ray (its own pinhole rays); the sky's pixels unchanged; far ground under a Preetham sky meets the sky
// above the horizon without a seam; the scene key read, written and refused where it means nothing; the quality
// presets turn it on for terrains only.
#include <QTemporaryDir>
#include <QTest>

#include <cmath>
#include <string>
#include <vector>

#include "core/base/error.h"
#include "core/render/render_cpu.h"
#include "core/render/render_scene.h"
#include "core/render/surfaces/atmosphere.h"
#include "core/scene/quality.h"
#include "core/sky/preetham.h"
#include "pipeline/io/env_map_io.h"
#include "pipeline/render/frame_build.h"
#include "pipeline/render/render_job.h"
#include "pipeline/scene/scene_file.h"
#include "tests/common/pinhole.h"
#include "tests/common/scenes.h"

using namespace sylva;

namespace {

constexpr double kPi = 3.14159265358979323846;

// integral_0^t exp(-(y0 + s dy) / H) ds by composite Simpson's rule, 4000 intervals, in double.
double columnByQuadrature(double y0, double dy, double t, double H)
{
    const int n = 4000;
    const double h = t / n;
    double sum = 0.0;
    for (int i = 0; i <= n; ++i) {
        const double w = (i == 0 || i == n) ? 1.0 : (i % 2 ? 4.0 : 2.0);
        sum += w * std::exp(-(y0 + i * h * dy) / H);
    }
    return sum * h / 3.0;
}

// A white ground at y = 0 seen from (0, height, 0), pitched down by pitchDeg, looking along +z; the one shrub
// the renderer needs 1000 m under the ground (never seen, never in a shadow ray's way).
Scene groundFromAbove(double height, double pitchDeg, float fovY, int w, int h)
{
    Scene s = test::shrubUnderGround();
    s.ground.color = glm::vec3(0.6f, 0.5f, 0.4f);
    s.camera.position = {0.0, height, 0.0};
    const double p = pitchDeg * kPi / 180.0;
    s.camera.target = {0.0, height - std::sin(p) * 100.0, std::cos(p) * 100.0};
    s.camera.fovY = fovY;
    s.sun.direction = sunDirection(40.0, 30.0);
    s.render.width = w;
    s.render.height = h;
    s.render.spp = 1;
    return s;
}

struct Rendered {
    Film film;
    std::vector<glm::vec3> picture;
};

Rendered render(const Scene& s, const std::vector<SpeciesAssets>& assets)
{
    Rendered r;
    r.film = renderFilm(buildRenderScene(s, assets, glm::vec3(0.0f)).view());
    r.picture = composeMode(r.film, RenderMode::Full, composeSky(s));
    return r;
}

double luminance(glm::vec3 c) { return 0.2126 * c.x + 0.7152 * c.y + 0.0722 * c.z; }

} // namespace

class TestAerialPerspective : public QObject {
    Q_OBJECT

    std::vector<SpeciesAssets> m_shrub;

private Q_SLOTS:
    void initTestCase() { m_shrub = test::oneShrub(); }

    // airColumn's closed form (and its midpoint rule near the horizontal) against Simpson's rule.
    void columnClosedForm()
    {
        struct Case {
            double y0, dy, t, H;
        };
        const std::vector<Case> cases = {{0, 0, 5000, 1200},       {1000, -0.3, 3000, 1200}, {1000, 0.5, 20000, 8000}, {2500, -1, 2400, 1200},
                                         {-400, 0.02, 60000, 8000}, {300, 1e-7, 80000, 1200}, {300, -1e-4, 5000, 1200}, {10, 0.999, 1e5, 8000}};
        for (const Case& c : cases) {
            const double want = columnByQuadrature(c.y0, c.dy, c.t, c.H);
            const double got = airColumn(float(c.y0), float(c.dy), float(c.t), float(c.H));
            QVERIFY2(std::abs(got - want) <= 2e-5 * want,
                     qPrintable(QString("y0 %1 dy %2 t %3 H %4: %5 vs %6").arg(c.y0).arg(c.dy).arg(c.t).arg(c.H).arg(got).arg(want)));
        }
    }

    // From sea level straight up, the air's transmittance is the Preetham sun's at the zenith (its optical mass
    // there is 0.9995, not 1: within 0.1% of the optical depth), at each channel's wavelength and turbidity.
    void verticalColumnIsTheSunsAir()
    {
        for (const double turbidity : {2.0, 3.0, 6.0, 10.0}) {
            const AtmosphereRecord a = makeAtmosphere(turbidity, 0.0);
            const glm::vec3 T = atmosphereTransmittance(a, 0.0f, glm::vec3(0.0f, 1.0f, 0.0f), 2e5f);
            for (int c = 0; c < 3; ++c) {
                const double sun = sky::sunTransmittance(kAtmosphereWavelengthsNm[c], turbidity, 0.0);
                QVERIFY2(std::abs(std::log(double(T[c])) - std::log(sun)) <= 1e-3 * -std::log(sun),
                         qPrintable(QString("T %1 channel %2: %3 vs the sun's %4").arg(turbidity).arg(c).arg(T[c]).arg(sun)));
            }
            // blue fades first; thicker haze fades more
            QVERIFY(T.z < T.y && T.y < T.x);
        }
        QVERIFY(makeAtmosphere(2.0, 0.0).aerosol.y < makeAtmosphere(6.0, 0.0).aerosol.y);
        QVERIFY_THROWS_EXCEPTION(Error, makeAtmosphere(1.5, 0.0));
    }

    // The ground from 1000 m: every ground pixel is the picture without air x T + (1 - T) x the constant sky,
    // T from the quadrature along the pixel's ray to the plane; sky pixels keep their bits.
    void groundFadesByTheColumn()
    {
        Scene off = groundFromAbove(1000.0, 10.0, 30.0f, 48, 32);
        off.skyModel.turbidity = 4.0;
        Scene on = off;
        on.skyModel.aerialPerspective = true;
        const Rendered a = render(off, m_shrub), b = render(on, m_shrub);
        const glm::vec3 sky = composeSky(on);
        const AtmosphereRecord air = makeAtmosphere(4.0, 1000.0);
        int ground = 0, skyPixels = 0;
        double worst = 0.0, minT = 1.0, maxT = 0.0;
        for (int py = 0; py < off.render.height; ++py)
            for (int px = 0; px < off.render.width; ++px) {
                const size_t i = size_t(py) * size_t(off.render.width) + size_t(px);
                const glm::dvec3 d = test::pinholeDirection(off, px + 0.5, py + 0.5);
                if (d.y >= -1e-3) {
                    if (a.film.pixels[i].skyCover == 1.0f) {
                        ++skyPixels;
                        QCOMPARE(b.picture[i], a.picture[i]);
                    }
                    continue;
                }
                ++ground;
                const double t = 1000.0 / -d.y;
                glm::dvec3 T;
                for (int c = 0; c < 3; ++c)
                    T[c] = std::exp(-(double(air.rayleigh[c]) * columnByQuadrature(1000.0, d.y, t, kRayleighScaleHeight) +
                                      double(air.aerosol[c]) * columnByQuadrature(1000.0, d.y, t, kAerosolScaleHeight)));
                minT = std::min(minT, T.y);
                maxT = std::max(maxT, T.y);
                const glm::dvec3 want = glm::dvec3(a.picture[i]) * T + (glm::dvec3(1.0) - T) * glm::dvec3(sky);
                for (int c = 0; c < 3; ++c) worst = std::max(worst, std::abs(double(b.picture[i][c]) - want[c]) / want[c]);
            }
        qInfo("%d ground pixels (T of green %.3f .. %.3f), %d sky pixels; largest relative difference %.2e", ground, minT, maxT, skyPixels, worst);
        QVERIFY(ground > 800 && skyPixels > 50);
        QVERIFY(minT < 0.3 && maxT > 0.6);   // the test spans near and far
        QVERIFY2(worst < 1e-4, qPrintable(QString("largest relative difference %1").arg(worst)));
    }

    // Under a Preetham sky, ground 30-100 km away (a camera 100 m up looking at the horizon) takes the sky's
    // colour just above the horizon in its own column: no seam where the land meets the sky.
    void farGroundMeetsTheSky()
    {
        Scene s = groundFromAbove(100.0, 0.0, 6.0f, 40, 40);
        s.skyModel.kind = sky::SkyKind::Preetham;
        s.skyModel.turbidity = 3.0;
        s.skyModel.aerialPerspective = true;
        s.sun.direction = sunDirection(20.0, 60.0);
        loadSceneSky(s);
        const Rendered r = render(s, m_shrub);
        const int W = s.render.width;
        int columns = 0;
        double worst = 0.0;
        for (int px = 0; px < W; ++px) {
            // the last sky row and the first ground row of the column
            int lastSky = -1;
            for (int py = 0; py < s.render.height; ++py)
                if (r.film.pixels[size_t(py) * size_t(W) + size_t(px)].skyCover == 1.0f) lastSky = py;
            if (lastSky < 0 || lastSky + 1 >= s.render.height) continue;
            const double skyL = luminance(r.picture[size_t(lastSky) * size_t(W) + size_t(px)]);
            const double groundL = luminance(r.picture[size_t(lastSky + 1) * size_t(W) + size_t(px)]);
            worst = std::max(worst, std::abs(groundL - skyL) / skyL);
            ++columns;
        }
        qInfo("%d columns, largest luminance step from sky to ground at the horizon %.2f%%", columns, 100.0 * worst);
        QCOMPARE(columns, W);
        QVERIFY2(worst < 0.005, qPrintable(QString("step %1").arg(worst)));
        // without air the same ground is far from the sky's colour (the test can tell)
        Scene bare = s;
        bare.skyModel.aerialPerspective = false;
        const Rendered b = render(bare, m_shrub);
        const size_t mid = size_t(s.render.height / 2 + 2) * size_t(W) + size_t(W / 2);
        QVERIFY(std::abs(luminance(b.picture[mid]) - luminance(r.picture[mid])) > 0.1 * luminance(r.picture[mid]));
    }

    // sky.aerial_perspective read and written back; turbidity with a constant sky only beside it; the presets
    // set it on scenes with a terrain and leave other scenes as the file had them.
    void sceneKeyAndPresets()
    {
        QTemporaryDir dir;
        const std::string head = R"({"version": 1, "species": [{"name": "b", "grow": {}}], "instances": [{"species": "b", "position": [0, 0, 0]}], "sky": )";
        const Scene s = parseScene(head + R"({"aerial_perspective": true, "turbidity": 5}})", dir.path().toStdString(), "air.json");
        QVERIFY(s.skyModel.aerialPerspective);
        QCOMPARE(s.skyModel.turbidity, 5.0);
        const std::string text = sceneToJson(s, dir.path().toStdString());
        QVERIFY(text.find("\"aerial_perspective\": true") != std::string::npos);
        const Scene back = parseScene(text, dir.path().toStdString(), "back.json");
        QVERIFY(back.skyModel.aerialPerspective);
        QCOMPARE(back.skyModel.turbidity, 5.0);
        const Scene plain = parseScene(head + "{}}", dir.path().toStdString(), "plain.json");
        QVERIFY(!plain.skyModel.aerialPerspective);
        QVERIFY(sceneToJson(plain, dir.path().toStdString()).find("aerial_perspective") == std::string::npos);
        try {
            (void)parseScene(head + R"({"turbidity": 5}})", dir.path().toStdString(), "bad.json");
            QFAIL("turbidity with a constant sky and no aerial perspective was accepted");
        } catch (const Error& e) {
            QVERIFY2(std::string(e.what()).find("sky.turbidity") != std::string::npos, e.what());
        }
        for (const QualityPreset& q : qualityPresets()) {
            Scene forest = plain;
            applyQuality(forest, q);
            QVERIFY(!forest.skyModel.aerialPerspective);
            Scene land = plain;
            land.terrain.dem = "heights.png";
            applyQuality(land, q);
            QCOMPARE(land.skyModel.aerialPerspective, q.aerialPerspective);
        }
    }
};

QTEST_GUILESS_MAIN(TestAerialPerspective)
#include "tst_aerial_perspective.moc"
