// The sky in the renderer: a white diffuse ground under an HDRI and nothing
// else renders albedo / pi x the map's upper-hemisphere irradiance (integrated here over the map's pixels);
// a uniform map gives the closed form L; interleaved subsets accumulated over samples equal / converge to
// the all-lights picture; plants shade the floor under the sky lights; camera rays that leave the scene see
// the map, filtered: the bilinear map integrated over each pixel, magnified and minified (its mip chain keeps
// the map's integral); `sky.kind` uniform lights like a map of its colour; a Preetham sky renders finite and lit; old constant-sky files keep their meaning; bad sky keys
// are refused.
#include <QDir>
#include <QTemporaryDir>
#include <QTest>

#include <algorithm>
#include <cmath>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "core/base/error.h"
#include "core/lb/lb_solver.h"
#include "core/render/render_cpu.h"
#include "core/render/render_scene.h"
#include "core/sky/env_map.h"
#include "core/sky/sky_light.h"
#include "pipeline/grow/tree_grower.h"
#include "pipeline/io/env_map_io.h"
#include "pipeline/render/frame_build.h"
#include "pipeline/render/render_job.h"
#include "pipeline/scene/scene_file.h"
#include "tests/common/pinhole.h"
#include "tests/common/scenes.h"

using namespace sylva;

namespace {

constexpr double kPi = 3.14159265358979323846;

using test::oneShrub;

// A white ground plane seen from above, the one shrub the renderer needs far below it (never in view,
// never in a shadow ray's way: those all go up); the sun off. The sky is set by the caller.
Scene openGround()
{
    Scene s = test::shrubUnderGround();
    s.ground.color = glm::vec3(1.0f);
    s.camera.position = {0.0, 5.0, -2.0};
    s.camera.target = {0.0, 0.0, 2.0};
    s.camera.fovY = 40.0f;
    s.sun.intensity = 0.0f;
    s.render.width = 8;
    s.render.height = 8;
    return s;
}

// Shrubs on the ground (the floor under them in their shadows), seen from above at an angle.
Scene shrubPatch()
{
    Scene s = openGround();
    s.instances = test::patchOfNine(1.6);
    s.camera.position = {0.0, 5.0, -3.0};
    s.camera.target = {0.0, 0.0, 3.6};
    s.render.width = 40;
    s.render.height = 30;
    return s;
}

Film film(const Scene& s, const std::vector<SpeciesAssets>& assets)
{
    return renderFilm(buildRenderScene(s, assets, glm::vec3(0.0f)).view());
}

std::vector<glm::vec3> picture(const Scene& s, const std::vector<SpeciesAssets>& assets)
{
    return composeMode(film(s, assets), RenderMode::Full, composeSky(s));
}

QString hdriPath(const char* name) { return QString(SYLVA_RESOURCES) + "/hdri/" + name; }

// A map sky on the scene from a file (cleaned as sylva reads it), N lights, K subsets.
void useMap(Scene& s, const std::string& path, int lights, int interleave, bool sunFromMap)
{
    s.skyModel = SkyDesc{};
    s.skyModel.kind = sky::SkyKind::Map;
    s.skyModel.path = path;
    s.skyModel.lights = lights;
    s.skyModel.interleave = interleave;
    s.skyModel.sunFromMap = sunFromMap;
    loadSceneSky(s);
}

// The irradiance of an upward-facing plane under the map, integrated in the test over its pixels: each
// pixel's radiance x its solid angle (2 pi / W)(cos theta_top - cos theta_bottom) x the cosine at its
// centre, the upper half's rows only (Rec. 709 luminance weights to compare one number).
glm::dvec3 upperIrradiance(const sky::EnvMap& m)
{
    glm::dvec3 e(0.0);
    for (int y = 0; y < m.height / 2; ++y) {
        const double t0 = kPi * y / m.height, t1 = kPi * (y + 1) / m.height, tc = kPi * (y + 0.5) / m.height;
        const double w = 2.0 * kPi / m.width * (std::cos(t0) - std::cos(t1)) * std::cos(tc);
        for (int x = 0; x < m.width; ++x) e += glm::dvec3(m.at(x, y)) * w;
    }
    return e;
}

double luminance(glm::dvec3 c) { return 0.2126 * c.x + 0.7152 * c.y + 0.0722 * c.z; }

// Mean over the pixels of |a - b| (luminance) over the mean luminance of b.
double relativeError(const std::vector<glm::vec3>& a, const std::vector<glm::vec3>& b)
{
    double diff = 0.0, sum = 0.0;
    for (size_t i = 0; i < a.size(); ++i) {
        diff += std::abs(luminance(glm::dvec3(a[i])) - luminance(glm::dvec3(b[i])));
        sum += luminance(glm::dvec3(b[i]));
    }
    return diff / sum;
}

// The map as a continuous function, written here: bilinear between texel centres (u wraps, v clamps at the
// poles), at a unit direction (the equirectangular convention of core/sky/sky.h, unrotated).
glm::dvec3 bilinearMap(const sky::EnvMap& m, const glm::dvec3& d)
{
    double u = 0.5 * (1.0 - std::atan2(d.x, d.z) / kPi);
    u -= std::floor(u);
    const double v = std::acos(std::clamp(d.y, -1.0, 1.0)) / kPi;
    const double fx = u * m.width - 0.5, fy = v * m.height - 0.5;
    const double x0 = std::floor(fx), y0 = std::floor(fy), ax = fx - x0, ay = fy - y0;
    auto at = [&](double x, double y) {
        const int xi = ((int(x) % m.width) + m.width) % m.width, yi = std::clamp(int(y), 0, m.height - 1);
        return glm::dvec3(m.at(xi, yi));
    };
    return (at(x0, y0) * (1.0 - ax) + at(x0 + 1, y0) * ax) * (1.0 - ay) + (at(x0, y0 + 1) * (1.0 - ax) + at(x0 + 1, y0 + 1) * ax) * ay;
}

} // namespace

class TestSkyRender : public QObject {
    Q_OBJECT

    std::vector<SpeciesAssets> m_shrub;

private Q_SLOTS:
    void initTestCase() { m_shrub = oneShrub(); }

    // White ground, the HDRI's light through 1024 virtual lights (its sun left in the map), then with its
    // sun taken out as the directional sun: every pixel albedo / pi x the upper-hemisphere irradiance of
    // the map read from the file, within 1%.
    void whiteGroundUnderHdri()
    {
        for (const char* name : {"sky.exr", "park.exr", "sunset.exr"}) {
            const QString file = hdriPath(name);
            QVERIFY2(QFile::exists(file), qPrintable(file));
            const EnvMapFile raw = readEnvMap(file.toStdString());
            const double want = luminance(upperIrradiance(raw.map)) / kPi;
            QVERIFY(want > 0.0);
            for (bool sunFromMap : {false, true}) {
                Scene s = openGround();
                s.sun.intensity = sunFromMap ? 1.0f : 0.0f;   // 1: the map's own sun, as found
                useMap(s, file.toStdString(), 1024, 1, sunFromMap);
                const std::vector<glm::vec3> img = picture(s, m_shrub);
                for (size_t i = 0; i < img.size(); ++i) {
                    const double got = luminance(glm::dvec3(img[i]));
                    QVERIFY2(std::abs(got - want) <= 0.01 * want,
                             qPrintable(QString("%1 sun_from_map %2 pixel %3: %4, the map's irradiance / pi %5")
                                            .arg(name).arg(sunFromMap).arg(i).arg(got).arg(want)));
                }
            }
        }
    }

    // A uniform map of radiance L: the white ground shows L (albedo / pi x pi L) at any N, the sky pixels L.
    void uniformMapClosedForm()
    {
        const glm::vec3 L(0.3f, 0.5f, 0.9f);
        sky::EnvMap m;
        m.width = 64;
        m.height = 32;
        m.rgb.resize(size_t(m.width) * m.height * 3);
        for (size_t i = 0; i < m.rgb.size(); ++i) m.rgb[i] = L[int(i % 3)];
        for (int n : {16, 256}) {
            Scene s = openGround();
            s.skyModel.kind = sky::SkyKind::Map;
            s.skyModel.lights = n;
            s.skyModel.interleave = 1;
            s.skyModel.built = std::make_shared<const sky::Sky>(sky::mapSky(m, 0.0f, 1.0f, false));
            const std::vector<glm::vec3> img = picture(s, m_shrub);
            // The ground's irradiance from n lights at their regions' power-weighted centres: the cosine
            // there, not the region's mean cosine, so the error falls with n.
            const float tol = n == 16 ? 0.1f : 0.01f;
            for (const glm::vec3& c : img)
                for (int k = 0; k < 3; ++k) QVERIFY2(std::abs(c[k] - L[k]) <= tol * L[k], qPrintable(QString("N %1: %2 vs %3").arg(n).arg(c[k]).arg(L[k])));
            // Looking up: every pixel is sky, the map's radiance, skyCover 1 (alpha 0), nothing composed twice.
            s.camera.position = {0.0, 1.0, 0.0};
            s.camera.target = {0.0, 5.0, 1.0};
            const Film up = film(s, m_shrub);
            const std::vector<glm::vec3> sky = composeMode(up, RenderMode::Full, composeSky(s));
            for (size_t i = 0; i < sky.size(); ++i) {
                QCOMPARE(up.pixels[i].skyCover, 1.0f);
                for (int k = 0; k < 3; ++k) QCOMPARE(sky[i][k], L[k]);
            }
        }
    }

    // `sky.kind` uniform: the constant colour as a map. It reads and writes back; the scene's sun stays (no sun
    // search in a uniform map); the white ground shows the colour L (the constant sky's closed form, within 1% at
    // 256 lights) and the sky pixels L; and unlike the constant sky it lights the plants: with the sun off, the
    // constant sky leaves every plant pixel's local part 0, the uniform sky lights them all.
    void uniformSkyLightsPlants()
    {
        QTemporaryDir dir;
        const std::string text = R"({"version": 1, "species": [{"name": "b", "grow": {"species": "shrub", "triangles": 1500}}],
            "instances": [{"species": "b", "position": [0, -1000, 0]}],
            "sky": {"kind": "uniform", "color": [0.3, 0.5, 0.9], "lights": 256, "interleave": 1}})";
        const Scene parsed = parseScene(text, dir.path().toStdString(), "uniform.json");
        QCOMPARE(parsed.skyModel.kind, sky::SkyKind::Uniform);
        const glm::vec3 L(0.3f, 0.5f, 0.9f);
        QCOMPARE(parsed.sky, L);
        const Scene again = parseScene(sceneToJson(parsed, dir.path().toStdString()), dir.path().toStdString(), "again.json");
        QCOMPARE(again.skyModel.kind, sky::SkyKind::Uniform);
        QCOMPARE(again.sky, L);
        QCOMPARE(again.skyModel.lights, 256);

        Scene s = openGround();
        s.sky = L;
        s.skyModel = parsed.skyModel;
        s.sun.direction = glm::vec3(0.3f, 0.5f, 0.6f);
        s.sun.intensity = 1.0f;
        loadSceneSky(s);
        QVERIFY(s.skyModel.built && s.skyModel.built->kind == sky::SkyKind::Map);
        QCOMPARE(composeSky(s), glm::vec3(0.0f));
        const FrameSun fs = frameSun(s, glm::vec3(0.7f));
        QCOMPARE(fs.direction, glm::normalize(s.sun.direction));
        QCOMPARE(fs.radiance, glm::vec3(0.7f));
        s.sun.intensity = 0.0f;
        for (const glm::vec3& c : picture(s, m_shrub))
            for (int k = 0; k < 3; ++k) QVERIFY2(std::abs(c[k] - L[k]) <= 0.01f * L[k], qPrintable(QString("%1 vs %2").arg(c[k]).arg(L[k])));
        s.camera.position = {0.0, 1.0, 0.0};
        s.camera.target = {0.0, 5.0, 1.0};
        for (const glm::vec3& c : composeMode(film(s, m_shrub), RenderMode::Full, composeSky(s)))
            for (int k = 0; k < 3; ++k) QCOMPARE(c[k], L[k]);

        Scene constant = shrubPatch();
        constant.sky = L;
        Scene uniform = constant;
        uniform.skyModel = s.skyModel;
        const Film fc = film(constant, m_shrub), fu = film(uniform, m_shrub);
        int plants = 0, lit = 0;
        for (size_t i = 0; i < fc.pixels.size(); ++i) {
            const SampleParts &c = fc.pixels[i], &u = fu.pixels[i];
            if (c.skyCover != 0.0f || c.normal.y == 1.0f) continue;   // sky or floor
            ++plants;
            QCOMPARE(c.local, glm::vec3(0.0f));
            lit += luminance(glm::dvec3(u.local)) > 0.0 ? 1 : 0;   // a leaf every light's shadow ray misses stays dark
        }
        QVERIFY(plants > 100);
        QVERIFY2(lit >= plants * 95 / 100, qPrintable(QString("%1 of %2 plant pixels lit by the uniform sky").arg(lit).arg(plants)));
    }

    // The sky in the LB boundary (`lighting.boundary` sun_sky): the key reads and writes
    // back; in open space the boundary's free field, as the renderer scales it, is the sun's radiance plus
    // 2 x the sky's (fluence / pi: the sun's E = pi S, the upper hemisphere's 2 pi L); with the sun dark a
    // Preetham sky lights the plants' LB part, which the sun's boundary leaves at 0; with the sun on, the
    // sky only adds (superposition) to every plant pixel's LB part.
    void skyInTheLbBoundary()
    {
        QTemporaryDir dir;
        const std::string base = dir.path().toStdString();
        const std::string text = R"({"version": 1, "species": [{"name": "b", "grow": {"species": "shrub", "triangles": 1500, "seed": 3},
            "lighting": {"grid": 16}}], "instances": [{"species": "b", "position": [0, 0, 0]}], "lighting": {"boundary": "sun_sky"}})";
        const Scene parsed = parseScene(text, base, "b.json");
        QCOMPARE(parsed.lighting.boundary, LbBoundary::SunSky);
        QCOMPARE(parseScene(sceneToJson(parsed, base), base, "again.json").lighting.boundary, LbBoundary::SunSky);
        QCOMPARE(Scene{}.lighting.boundary, LbBoundary::Sun);
        std::string bad = text;
        bad.replace(bad.find("\"sun_sky\""), 9, "\"sky\"");
        try {
            parseScene(bad, base, "bad.json");
            QFAIL("lighting.boundary \"sky\" was accepted");
        } catch (const Error& e) {
            QVERIFY2(std::string(e.what()).find("boundary") != std::string::npos, e.what());
        }

        // The units, with the constant sky L (any kind can go into the boundary).
        Scene c = parsed;
        const glm::vec3 L(0.2f, 0.3f, 0.5f);
        c.sky = L;
        c.sun.direction = glm::vec3(0.2f, 0.9f, 0.3f);
        for (float intensity : {1.0f, 0.0f}) {
            c.sun.intensity = intensity;
            lb::LbParams p = c.species[0].lighting;
            p.sun = lbSunDirection(c);
            const std::optional<lb::BoundaryWeights> w = speciesBoundary(c, p);
            QVERIFY(w.has_value());
            const FrameSun fs = frameSun(c, sunRadiance(c.sun));
            const glm::vec3 unit = lbRadiance(c, fs);
            if (intensity == 0.0f) QCOMPARE(unit, glm::vec3(1.0f));
            const std::vector<float> f = lb::boundaryDistribution(p.sun);
            float free = 0.0f;
            for (float v : f) free += v;
            for (int k = 0; k < 3; ++k) {
                const double shown = double(w->totals()[k]) / double(p.intensity[k] * free) * double(unit[k]);
                const double expect = double(fs.radiance[k]) + 2.0 * double(L[k]);
                QVERIFY2(std::abs(shown - expect) < 1e-4 * expect, qPrintable(QString("channel %1: %2 vs %3").arg(k).arg(shown).arg(expect)));
            }
            Scene sunOnly = c;
            sunOnly.lighting.boundary = LbBoundary::Sun;
            QVERIFY(!speciesBoundary(sunOnly, p).has_value());
            QCOMPARE(lbRadiance(sunOnly, fs), fs.radiance);
        }

        // Shrubs under a Preetham sky, their LB part in the picture.
        Scene r = shrubPatch();
        r.species = parsed.species;
        r.skyModel.kind = sky::SkyKind::Preetham;
        r.skyModel.turbidity = 4.0;
        r.sun.direction = glm::vec3(0.3f, 0.5f, 0.6f);
        loadSceneSky(r);
        auto lbParts = [&](LbBoundary boundary, float sunIntensity) {
            Scene q = r;
            q.lighting.boundary = boundary;
            q.sun.intensity = sunIntensity;
            const std::vector<SpeciesAssets> assets = loadSpeciesAssets(q, nullptr, true);
            return renderFilm(buildRenderScene(q, assets, sunRadiance(q.sun)).view());
        };
        const Film darkSun = lbParts(LbBoundary::Sun, 0.0f), darkSky = lbParts(LbBoundary::SunSky, 0.0f);
        const Film litSun = lbParts(LbBoundary::Sun, 1.0f), litSky = lbParts(LbBoundary::SunSky, 1.0f);
        int plants = 0, skyLit = 0;
        double sumSun = 0.0, sumSky = 0.0;
        for (size_t i = 0; i < darkSun.pixels.size(); ++i) {
            if (darkSun.pixels[i].skyCover != 0.0f || darkSun.pixels[i].normal.y == 1.0f) continue;   // sky or floor
            ++plants;
            QCOMPARE(darkSun.pixels[i].indirect, glm::vec3(0.0f));
            skyLit += luminance(glm::dvec3(darkSky.pixels[i].indirect)) > 0.0 ? 1 : 0;
            for (int k = 0; k < 3; ++k) {
                const float a = litSun.pixels[i].indirect[k], b = litSky.pixels[i].indirect[k];
                QVERIFY2(b >= a * (1.0f - 1e-4f), qPrintable(QString("pixel %1 channel %2: %3 with the sky, %4 without").arg(i).arg(k).arg(b).arg(a)));
            }
            sumSun += luminance(glm::dvec3(litSun.pixels[i].indirect));
            sumSky += luminance(glm::dvec3(litSky.pixels[i].indirect));
        }
        QVERIFY(plants > 100);
        QVERIFY2(skyLit >= plants * 95 / 100, qPrintable(QString("%1 of %2 plant pixels").arg(skyLit).arg(plants)));
        qInfo("  shrubs' LB part under a Preetham sky (T 4): sun + sky / sun alone %.3f", sumSky / sumSun);
        QVERIFY(sumSky > 1.05 * sumSun);
    }

    // Interleaved sampling: on the open ground (every light visible everywhere) K subsets cycled over
    // spp = K samples give the all-lights picture to float rounding; under plants, accumulated samples
    // converge to the all-lights, many-sample picture, closer with more samples.
    // With the ground plane every direction below the horizon ends on the ground, so the frame's lights are
    // the upper hemisphere's alone: N of them, all above the horizon, their powers the upper half's integral
    // (summed here over the map's pixels); without the plane (ground off) the whole sphere's, powers the
    // whole map's. The lit picture loses nothing (the lower lights were all shadowed), and the N lights
    // spent on the upper sky place its light closer to the 1024-light picture than the whole sphere's N.
    void lightsAboveTheHorizonWithTheGround()
    {
        const QString file = hdriPath("park.exr");
        QVERIFY2(QFile::exists(file), qPrintable(file));
        Scene s = shrubPatch();
        useMap(s, file.toStdString(), 32, 1, true);
        const sky::EnvMap& m = *s.skyModel.built->map;
        glm::dvec3 upper(0.0), whole(0.0);
        for (int y = 0; y < m.height; ++y) {
            const double omega = sky::envMapPixelSolidAngle(m.width, m.height, y);
            for (int x = 0; x < m.width; ++x) (y < m.height / 2 ? upper : whole) += glm::dvec3(m.at(x, y)) * omega;
        }
        whole += upper;
        QVERIFY(luminance(whole - upper) > 0.05 * luminance(whole));   // the map's lower half holds light
        for (bool ground : {true, false}) {
            Scene g = s;
            g.ground.enabled = ground;
            const RenderScene rs = buildRenderScene(g, m_shrub, glm::vec3(0.0f));
            QCOMPARE(rs.skyLights.size(), size_t(32));
            glm::dvec3 sum(0.0);
            int below = 0;
            for (const sky::VirtualLight& l : rs.skyLights) {
                sum += glm::dvec3(l.power);
                below += l.direction.y > 0.0f ? 0 : 1;
            }
            const glm::dvec3 want = ground ? upper : whole;
            QVERIFY2(glm::length(sum - want) < 1e-5 * glm::length(want), qPrintable(QString("ground %1").arg(ground)));
            if (ground) QCOMPARE(below, 0);
            else QVERIFY(below > 0);
        }
        // Against 1024 lights: N lights on the upper sky, and N over the whole sphere (the frame built with
        // the ground, its lights then set as if it had none).
        Scene ref = s;
        ref.skyModel.lights = 1024;
        const std::vector<glm::vec3> want = picture(ref, m_shrub);
        for (int n : {16, 64}) {
            RenderScene rs = buildRenderScene(s, m_shrub, glm::vec3(0.0f));
            SkyDesc d = s.skyModel;
            d.lights = n;
            setFrameSky(rs, d, true);
            const double eUpper = relativeError(composeMode(renderFilm(rs.view()), RenderMode::Full, composeSky(s)), want);
            setFrameSky(rs, d, false);
            const double eWhole = relativeError(composeMode(renderFilm(rs.view()), RenderMode::Full, composeSky(s)), want);
            qInfo("park.exr on the shrub patch, %d lights: mean pixel error %.4f (upper hemisphere) against %.4f (whole sphere), "
                  "1024 lights the reference",
                  n, eUpper, eWhole);
            QVERIFY2(eUpper < eWhole, qPrintable(QString("%1 lights: %2 >= %3").arg(n).arg(eUpper).arg(eWhole)));
        }
    }

    void interleavedConverges()
    {
        const QString file = hdriPath("forest.exr");
        QVERIFY2(QFile::exists(file), qPrintable(file));
        Scene open = openGround();
        useMap(open, file.toStdString(), 64, 1, false);
        const std::vector<glm::vec3> all = picture(open, m_shrub);
        for (int k : {4, 8, 16}) {
            Scene s = open;
            s.skyModel.interleave = k;
            s.render.spp = k;
            const double e = relativeError(picture(s, m_shrub), all);
            QVERIFY2(e < 1e-5, qPrintable(QString("open ground, K %1, %1 spp: %2 off the all-lights picture").arg(k).arg(e)));
            s.render.spp = 1;   // one subset per pixel: each pixel off, but not by more than the subsets differ
            QVERIFY(relativeError(picture(s, m_shrub), all) > 1e-4);
        }

        Scene patch = shrubPatch();
        useMap(patch, file.toStdString(), 64, 1, false);
        patch.render.spp = 64;
        const std::vector<glm::vec3> ref = picture(patch, m_shrub);
        Scene il = patch;
        il.skyModel.interleave = 8;
        // Per pixel the error falls (each subset sees fewer sample positions than the reference's lights:
        // the shadow edges differ), at least 2x per 8x the samples; the mean stays the reference's (unbiased).
        auto mean = [](const std::vector<glm::vec3>& img) {
            double m = 0.0;
            for (const glm::vec3& c : img) m += luminance(glm::dvec3(c));
            return m / double(img.size());
        };
        double previous = 1e30;
        for (int spp : {1, 8, 64}) {
            il.render.spp = spp;
            const std::vector<glm::vec3> img = picture(il, m_shrub);
            const double e = relativeError(img, ref), bias = std::abs(mean(img) / mean(ref) - 1.0);
            qInfo("K 8, %d spp: mean pixel error %.4f, mean luminance off by %.5f against 64 lights x 64 spp", spp, e, bias);
            QVERIFY2(e < 0.5 * previous, qPrintable(QString("%1 spp: %2, not below half of %3").arg(spp).arg(e).arg(previous)));
            if (spp >= 8) QVERIFY2(bias < 0.01, qPrintable(QString("%1 spp: the mean luminance %2 off").arg(spp).arg(bias)));
            previous = e;
        }
        QVERIFY2(previous < 0.04, qPrintable(QString("64 spp: %1").arg(previous)));
    }

    // Progressive refinement (item 5): frames of samples [0, 8), [8, 16), ... of a 64-spp frame (new pixel
    // positions and sky-light subsets each), averaged by accumulateFilm, are the 64-spp frame `sylva render
    // --spp 64` traces at once, to float rounding; the running mean after each frame converges to the
    // N-light, 64-sample reference of an uninterleaved frame (all N lights in every sample), its error at
    // least halving per 8x the samples.
    void progressiveAccumulationIsTheFullFrame()
    {
        const QString file = hdriPath("forest.exr");
        QVERIFY2(QFile::exists(file), qPrintable(file));
        Scene patch = shrubPatch();
        useMap(patch, file.toStdString(), 64, 8, false);
        patch.render.spp = 64;
        const RenderScene rs = buildRenderScene(patch, m_shrub, glm::vec3(0.0f));
        const Film whole = renderFilm(rs.view());
        Scene allLights = patch;
        allLights.skyModel.interleave = 1;
        const std::vector<glm::vec3> reference = picture(allLights, m_shrub);
        Film sum;
        int done = 0;
        double previous = 1e30;
        for (int chunk : {1, 7, 8, 16, 32}) {
            RenderView v = rs.view();
            v.sampleBegin = done;
            v.sampleEnd = done + chunk;
            accumulateFilm(sum, done, renderFilm(v), chunk);
            done += chunk;
            const double e = relativeError(composeMode(sum, RenderMode::Full, composeSky(patch)), reference);
            qInfo("progressive, %d of 64 samples: mean pixel error %.4f against 64 lights x 64 spp, all lights per sample", done, e);
            if (done == 8 || done == 64) {
                QVERIFY2(e < 0.5 * previous, qPrintable(QString("%1 samples: %2, not below half of %3").arg(done).arg(e).arg(previous)));
                previous = e;
            }
        }
        QCOMPARE(done, 64);
        QVERIFY2(previous < 0.04, qPrintable(QString("64 samples: %1").arg(previous)));
        double worst = 0.0;
        for (size_t i = 0; i < whole.pixels.size(); ++i) {
            const SampleParts &a = sum.pixels[i], &b = whole.pixels[i];
            worst = std::max({worst, double(glm::length(a.local - b.local)) / (1e-6 + glm::length(b.local)),
                              double(glm::length(a.background - b.background)) / (1e-6 + glm::length(b.background)),
                              double(std::abs(a.skyCover - b.skyCover))});
            QCOMPARE(a.depth, b.depth);
        }
        QVERIFY2(worst < 1e-4, qPrintable(QString("accumulated frames off the 64-spp frame by %1").arg(worst)));
        QVERIFY_THROWS_EXCEPTION(Error, accumulateFilm(sum, 64, Film{3, 1, std::vector<SampleParts>(3)}, 1));
    }

    // Sky light on the floor through the same lights, occluded by plants: the floor between the shrubs is
    // darker than open ground (the same lights, no plants), and never brighter.
    void floorDarkerUnderPlants()
    {
        const QString file = hdriPath("sky.exr");
        QVERIFY2(QFile::exists(file), qPrintable(file));
        Scene patch = shrubPatch();
        useMap(patch, file.toStdString(), 256, 1, false);
        const Film f = film(patch, m_shrub);
        Scene bare = patch;
        bare.instances = {openGround().instances[0]};
        const Film g = film(bare, m_shrub);
        int floor = 0, darker = 0;
        for (size_t i = 0; i < f.pixels.size(); ++i) {
            // The same ground point in both (a plant's leaf can be white too): the floor.
            const bool isFloor = f.pixels[i].skyCover == 0.0f && f.pixels[i].depth == g.pixels[i].depth && f.pixels[i].normal.y == 1.0f;
            if (!isFloor) continue;
            ++floor;
            const double a = luminance(glm::dvec3(f.pixels[i].local)), b = luminance(glm::dvec3(g.pixels[i].local));
            QVERIFY2(a <= b * (1.0 + 1e-5), qPrintable(QString("pixel %1: %2 under plants, %3 open").arg(i).arg(a).arg(b)));
            darker += a < 0.95 * b ? 1 : 0;
        }
        QVERIFY(floor > 100);
        QVERIFY2(darker > floor / 10, qPrintable(QString("%1 of %2 floor pixels darker").arg(darker).arg(floor)));
    }

    // A Preetham sky: finite, non-negative, the sky visible above the horizon and the ground lit by the sky
    // lights alone when its sun is off (sun.intensity 0), more with the sun on.
    void preethamRenders()
    {
        Scene s = openGround();
        s.skyModel.kind = sky::SkyKind::Preetham;
        s.skyModel.turbidity = 4.0;
        s.sun.direction = glm::vec3(0.3f, 0.5f, 0.6f);
        loadSceneSky(s);
        QVERIFY(s.skyModel.built && s.skyModel.built->sun.present);
        s.camera.position = {0.0, 2.0, 0.0};
        s.camera.target = {0.0, 1.9, 5.0};   // the horizon across the picture
        s.camera.fovY = 60.0f;
        s.render.width = s.render.height = 24;
        const Film dark = film(s, m_shrub);
        s.sun.intensity = 1.0f;
        const Film lit = film(s, m_shrub);
        int skyPixels = 0, groundPixels = 0;
        for (size_t i = 0; i < dark.pixels.size(); ++i) {
            const glm::vec3 a = composeSample(dark.pixels[i], RenderMode::Full, composeSky(s), 0.0f);
            const glm::vec3 b = composeSample(lit.pixels[i], RenderMode::Full, composeSky(s), 0.0f);
            for (int k = 0; k < 3; ++k) QVERIFY(std::isfinite(a[k]) && a[k] >= 0.0f && std::isfinite(b[k]) && b[k] >= 0.0f);
            if (dark.pixels[i].skyCover == 1.0f) {
                ++skyPixels;
                QVERIFY(luminance(glm::dvec3(a)) > 0.0);
                QCOMPARE(a, b);   // the sun is a light, not in the background
            } else {
                ++groundPixels;
                QVERIFY(luminance(glm::dvec3(a)) > 0.0);
                QVERIFY(luminance(glm::dvec3(b)) > luminance(glm::dvec3(a)));
            }
        }
        QVERIFY(skyPixels > 50 && groundPixels > 50);
    }

    // Old files: a sky block with only `color` is the constant sky, written back without the new keys, and
    // renders no background part (the constant sky composes as skyCover x colour, as before).
    // The mip chain of a map keeps its integral over the sphere at every level (the solid-angle weights).
    void mipChainKeepsTheIntegral()
    {
        sky::EnvMap m;
        m.width = 128;
        m.height = 64;
        m.rgb.resize(size_t(m.width) * size_t(m.height) * 3);
        for (size_t k = 0; k < m.rgb.size(); ++k) m.rgb[k] = float((k * 2654435761u) % 1000) / 250.0f;
        int levels = 0;
        const std::vector<float> chain = sky::envMapMipChain(m, levels);
        QCOMPARE(levels, 7);   // 128 x 64 .. 2 x 1
        const glm::dvec3 whole = sky::envMapIntegral(m);
        size_t at = 0;
        for (int k = 0; k < levels; ++k) {
            sky::EnvMap level;
            level.width = m.width >> k;
            level.height = m.height >> k;
            const size_t n = size_t(level.width) * size_t(level.height) * 3;
            level.rgb.assign(chain.begin() + std::ptrdiff_t(at), chain.begin() + std::ptrdiff_t(at + n));
            at += n;
            const glm::dvec3 e = sky::envMapIntegral(level);
            for (int c = 0; c < 3; ++c) QVERIFY2(std::abs(e[c] - whole[c]) < 1e-5 * whole[c], qPrintable(QString("level %1").arg(k)));
        }
        QCOMPARE(at, chain.size());
    }

    // The background of a map sky is the bilinear map integrated over each pixel (64 x 64 points a pixel in the
    // test) at 1 sample a pixel: magnified (a 16 x 8 map, 22.5-degree texels, through 0.8-degree pixels: no hard
    // squares) and minified (a 1024 x 512 one-texel checkerboard through 7-degree pixels: grey, no aliasing).
    // The piecewise-constant lookup the sky's light uses (the pixel-centre texel) is far off in both.
    void backgroundIsTheMapOverEachPixel()
    {
        struct Case {
            const char* name;
            int mapWidth;
            float fovY;
            int pixels;
            double filteredBound, nearestAbove;
        };
        for (const Case& c : {Case{"magnified", 16, 40.0f, 48, 5e-4, 0.1}, Case{"minified", 1024, 90.0f, 16, 5e-3, 0.5}}) {
            sky::EnvMap m;
            m.width = c.mapWidth;
            m.height = c.mapWidth / 2;
            m.rgb.resize(size_t(m.width) * size_t(m.height) * 3);
            for (int y = 0; y < m.height; ++y)
                for (int x = 0; x < m.width; ++x)
                    for (int k = 0; k < 3; ++k)
                        m.ptr(x, y)[k] = c.mapWidth > 64 ? float(((x + y) % 2) * 2)
                                                         : 0.2f + float(((unsigned(x * 7 + y * 13 + k * 5) * 2654435761u) >> 8) % 1000) / 1000.0f;
            Scene s = openGround();
            s.ground.enabled = false;
            s.camera.position = {0.0, 5.0, 0.0};
            s.camera.target = {3.0, 7.0, 10.0};
            s.camera.fovY = c.fovY;
            s.render.width = s.render.height = c.pixels;
            s.render.spp = 1;
            s.skyModel = SkyDesc{};
            s.skyModel.kind = sky::SkyKind::Map;
            s.skyModel.path = "synthetic.exr";
            s.skyModel.built = std::make_shared<const sky::Sky>(sky::mapSky(m, 0.0f, 1.0f, false));
            const Film f = film(s, m_shrub);
            std::vector<glm::vec3> got, want, nearest;
            const sky::EnvMapView view = sky::envMapView(m, 0.0f, 1.0f);
            const int n = 64;
            for (int py = 0; py < c.pixels; ++py)
                for (int px = 0; px < c.pixels; ++px) {
                    glm::dvec3 sum(0.0);
                    for (int j = 0; j < n; ++j)
                        for (int i = 0; i < n; ++i) sum += bilinearMap(m, test::pinholeDirection(s, px + (i + 0.5) / n, py + (j + 0.5) / n));
                    want.push_back(glm::vec3(sum / double(n * n)));
                    got.push_back(f.pixels[size_t(py) * size_t(c.pixels) + size_t(px)].background);
                    nearest.push_back(sky::envMapRadiance(view, glm::vec3(test::pinholeDirection(s, px + 0.5, py + 0.5))));
                }
            const double e = relativeError(got, want), en = relativeError(nearest, want);
            qInfo("%s: filtered background %.3f%% from the map integrated over each pixel, the pixel-centre texel %.1f%%", c.name, 100.0 * e,
                  100.0 * en);
            QVERIFY2(e < c.filteredBound, c.name);
            QVERIFY2(en > c.nearestAbove, c.name);
        }
    }

    void constantSkyAsBefore()
    {
        QTemporaryDir dir;
        const std::string text = R"({"version": 1, "species": [{"name": "b", "grow": {"species": "shrub", "triangles": 1500}}],
            "instances": [{"species": "b", "position": [0, -1000, 0]}], "sky": {"color": [0.2, 0.3, 0.4]}})";
        const Scene s = parseScene(text, dir.path().toStdString(), "old.json");
        QCOMPARE(s.skyModel.kind, sky::SkyKind::Constant);
        QCOMPARE(s.sky, glm::vec3(0.2f, 0.3f, 0.4f));
        QCOMPARE(composeSky(s), s.sky);
        const std::string written = sceneToJson(s, dir.path().toStdString());
        QVERIFY2(written.find("\"sky\": {\"color\": [0.2, 0.3, 0.4]}") != std::string::npos, written.c_str());
        Scene r = openGround();
        r.sky = s.sky;
        const Film f = film(r, m_shrub);
        // The white ground as the constant sky always lit it: indirect = albedo x the sky colour, and no
        // sky lights in `local` (the sun is given radiance 0 here), no background part.
        for (const SampleParts& p : f.pixels) {
            QCOMPARE(p.background, glm::vec3(0.0f));
            QCOMPARE(p.indirect, r.sky);
            QCOMPARE(p.local, glm::vec3(0.0f));
        }
    }

    // Bad sky keys: each refused with a message naming the key.
    void badSkyKeysRefused()
    {
        QTemporaryDir dir;
        const QString exr = hdriPath("sky.exr");
        auto parse = [&](const std::string& sky) {
            const std::string text = R"({"version": 1, "species": [{"name": "b", "grow": {}}], "instances": [{"species": "b", "position": [0, 0, 0]}], "sky": )" +
                                     sky + "}";
            try {
                (void)parseScene(text, dir.path().toStdString(), "bad.json");
            } catch (const Error& e) {
                return std::string(e.what());
            }
            return std::string("(accepted)");
        };
        const std::string path = "\"" + exr.toStdString() + "\"";
        const std::vector<std::pair<std::string, std::string>> cases = {
            {R"({"kind": "cloudy"})", "sky.kind"},
            {R"({"kind": "hdri"})", "sky.path"},
            {R"({"kind": "hdri", "path": "nowhere.exr"})", "sky.path"},
            {R"({"kind": "preetham", "turbidity": 1.5})", "sky.turbidity"},
            {R"({"kind": "preetham", "turbidity": 11})", "sky.turbidity"},
            {R"({"turbidity": 3})", "sky.turbidity"},
            {R"({"kind": "preetham", "color": [1, 1, 1]})", "sky.color"},
            {R"({"kind": "preetham", "path": )" + path + "}", "sky.path"},
            {R"({"kind": "uniform", "path": )" + path + "}", "sky.path"},
            {R"({"kind": "uniform", "turbidity": 3})", "sky.turbidity"},
            {R"({"kind": "preetham", "lights": 0})", "sky.lights"},
            {R"({"kind": "preetham", "lights": 70000})", "sky.lights"},
            {R"({"kind": "preetham", "lights": 16, "interleave": 32})", "sky.interleave"},
            {R"({"kind": "preetham", "interleave": 0})", "sky.interleave"},
            {R"({"kind": "preetham", "scale": 0})", "sky.scale"},
            {R"({"kind": "hdri", "path": )" + path + R"(, "intensity": -1})", "sky.intensity"},
            {R"({"lights": 64})", "sky.lights"},
            {R"({"kind": "hdri", "path": )" + path + R"(, "sun_from_map": 1})", "sky.sun_from_map"},
        };
        for (const auto& [sky, key] : cases) {
            const std::string got = parse(sky);
            QVERIFY2(got.find(key) != std::string::npos, qPrintable(QString::fromStdString(sky + " -> " + got)));
        }
        // A good one reads, and round-trips through the writer.
        const std::string good = R"({"kind": "hdri", "path": )" + path + R"(, "rotation_deg": 90, "intensity": 2, "lights": 128, "interleave": 4, "sun_from_map": false})";
        QCOMPARE(parse(good), std::string("(accepted)"));
        const std::string text = R"({"version": 1, "species": [{"name": "b", "grow": {}}], "instances": [{"species": "b", "position": [0, 0, 0]}], "sky": )" + good + "}";
        const Scene a = parseScene(text, dir.path().toStdString(), "good.json");
        const Scene b = parseScene(sceneToJson(a, dir.path().toStdString()), dir.path().toStdString(), "again.json");
        QCOMPARE(b.skyModel.kind, sky::SkyKind::Map);
        QCOMPARE(b.skyModel.path, exr.toStdString());
        QCOMPARE(b.skyModel.rotationDeg, 90.0f);
        QCOMPARE(b.skyModel.intensity, 2.0f);
        QCOMPARE(b.skyModel.lights, 128);
        QCOMPARE(b.skyModel.interleave, 4);
        QCOMPARE(b.skyModel.sunFromMap, false);
    }
};

QTEST_GUILESS_MAIN(TestSkyRender)
#include "tst_sky_render.moc"
