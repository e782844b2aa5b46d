// The reference path tracer (render.integrator path, core/render/path_trace.h) against oracles of its own:
// the sunlit ground under a constant sky (closed form, within the estimate's standard error), the white furnace
// (a white sphere over the white ground under a uniform sky of radiance 1: every bounce counted, every pixel 1),
// the LB integrator's direct light (0 bounces under the sun alone, leaves without transmission: the same
// picture), a leaf lit from behind (its transmission, closed form), more light with every bounce and the sum
// converged by 8 bounces, the bits the same on every run, and the settings refused. The LB integrator's radiance
// cache (lighting.bounces) against the same oracles: the ground's closed form, the path tracer's direct light,
// and the path tracer's picture as the traced bounces grow; with bounce samples (render.bounce_samples) the ground's
// closed form, whole paths' direct light and a picture between 4 and 16 whole samples'.
#include <QTest>

#include <algorithm>
#include <cmath>
#include <vector>

#include "core/base/error.h"
#include "core/lb/leaf_optics.h"
#include "core/render/path_trace.h"
#include "core/render/render_cpu.h"
#include "core/render/tonemap.h"
#include "pipeline/io/env_map_io.h"
#include "pipeline/render/frame_build.h"
#include "pipeline/render/render_job.h"
#include "tests/common/files.h"
#include "tests/common/scenes.h"

using namespace sylva;

namespace {

struct Stats {
    double mean = 0.0, stderr_ = 0.0;
};

// Mean and standard error over the pixels of channel k (every pixel the same expectation).
Stats channelStats(const std::vector<glm::vec3>& img, int k)
{
    double s = 0.0, s2 = 0.0;
    for (const glm::vec3& c : img) {
        s += double(c[k]);
        s2 += double(c[k]) * double(c[k]);
    }
    const double n = double(img.size()), m = s / n;
    return {m, std::sqrt(std::max(0.0, s2 / n - m * m) / n)};
}

std::vector<glm::vec3> render(const Scene& s, const std::vector<SpeciesAssets>& assets, RenderMode mode = RenderMode::Full)
{
    return composeMode(renderFilm(buildRenderScene(s, assets, sunRadiance(s.sun)).view()), mode, s.sky);
}

// The open ground seen from above under the sun and a constant sky.
Scene groundScene()
{
    Scene s;
    s.ground.color = {0.5f, 0.3f, 0.2f};
    s.sun.direction = sunDirection(50.0, 30.0);
    s.sun.temperature = 5000.0;
    s.sky = {0.3f, 0.4f, 0.6f};
    s.camera.position = {0.0, 6.0, 0.0};
    s.camera.target = {0.0, 0.0, 2.0};
    s.camera.fovY = 30.0f;
    s.render.width = 16;
    s.render.height = 12;
    s.render.spp = 64;
    s.render.integrator = Integrator::Path;
    return s;
}

double mean(const std::vector<glm::vec3>& img)
{
    double s = 0.0;
    for (const glm::vec3& c : img) s += double(luminance(c));
    return s / double(img.size());
}

// Relative L2 of luminance of `img` against `ref` (docs/ACCURACY.md's measure).
double relativeL2(const std::vector<glm::vec3>& img, const std::vector<glm::vec3>& ref)
{
    double d = 0.0, r = 0.0;
    for (size_t i = 0; i < img.size(); ++i) {
        const double a = double(luminance(img[i])), b = double(luminance(ref[i]));
        d += (a - b) * (a - b);
        r += b * b;
    }
    return std::sqrt(d / r);
}

// The open ground's picture against albedo x (sunRadiance x cos + sky): the sun's share exact (a delta light),
// the sky's an estimate, within 4 standard errors.
void checkGround(const Scene& s, const char* what)
{
    const std::vector<glm::vec3> img = render(s, {});
    const glm::vec3 rad = sunRadiance(s.sun);
    const double cosSun = double(glm::normalize(s.sun.direction).y);
    for (int k = 0; k < 3; ++k) {
        const double expected = double(s.ground.color[k]) * (double(rad[k]) * cosSun + double(s.sky[k]));
        const Stats st = channelStats(img, k);
        qInfo("%s, channel %d: %.5f +- %.5f, closed form %.5f", what, k, st.mean, st.stderr_, expected);
        QVERIFY2(std::fabs(st.mean - expected) < 4.0 * st.stderr_ + 1e-5 * expected,
                 qPrintable(QString("%1: %2 against %3").arg(what).arg(st.mean).arg(expected)));
        QVERIFY(st.stderr_ < 0.01 * expected);   // the estimate is tight enough to mean something
    }
}

} // namespace

class TestPathTrace : public QObject {
    Q_OBJECT

private Q_SLOTS:
    // albedo x (sunRadiance x cos + sky) at every bounce count (at the last vertex, which draws no direction, the
    // sky's sample counts whole), and with the LB integrator's radiance cache (the ground has no grid: the paths'
    // own next-event estimation and escaping rays are all its light).
    void groundAgainstClosedForm()
    {
        Scene s = groundScene();
        checkGround(s, "path, 64 bounces");
        s.render.maxBounces = 0;
        checkGround(s, "path, 0 bounces");
        s.render.integrator = Integrator::Lb;
        checkGround(s, "lb, the grid at the camera's hit");
        for (int b : {1, 3}) {
            s.lighting.bounces = b;
            checkGround(s, b == 1 ? "lb, 1 bounce before the grid" : "lb, 3 bounces before the grid");
        }
    }

    // The sky's importance sampling: its density integrates to 1 over the sphere, and the open ground under a
    // Preetham sky shows albedo x (sun x cos + E / pi), E the sky's irradiance integrated by quadrature.
    void skySamplingAgainstQuadrature()
    {
        Scene s = groundScene();
        s.skyModel.kind = sky::SkyKind::Preetham;
        loadSceneSky(s);
        s.render.maxBounces = 0;
        const RenderScene rs = buildRenderScene(s, {}, sunRadiance(s.sun));
        const RenderView v = rs.view();
        QVERIFY(v.sky.samplingRows > 0);
        QCOMPARE(int(v.lights[1].kind), int(LightKind::Sky));
        const int rows = 512, cols = 1024;
        const double dw = 4.0 * double(sky::kPi) / double(rows * cols);
        double total = 0.0;
        glm::dvec3 e(0.0);
        for (int j = 0; j < rows; ++j) {
            const float y = 1.0f - 2.0f * (float(j) + 0.5f) / float(rows);
            for (int i = 0; i < cols; ++i) {
                const float phi = 2.0f * sky::kPi * (float(i) + 0.5f) / float(cols);
                const float r = std::sqrt(1.0f - y * y);
                const glm::vec3 d(r * std::cos(phi), y, r * std::sin(phi));
                total += double(pdfSky(v, v.lights[1], d)) * dw;
                if (y > 0.0f) e += glm::dvec3(viewSkyRadiance(v, d)) * double(y) * dw;
            }
        }
        qInfo("the sky's density over the sphere: %.6f", total);
        QVERIFY(std::fabs(total - 1.0) < 1e-3);
        const std::vector<glm::vec3> img = composeMode(renderFilm(v), RenderMode::Full, composeSky(s));
        const double cosSun = double(glm::dot(v.lights[0].direction, glm::vec3(0.0f, 1.0f, 0.0f)));
        for (int k = 0; k < 3; ++k) {
            const double expected = double(s.ground.color[k]) * (double(v.lights[0].radiance[k]) * cosSun + e[k] / double(sky::kPi));
            const Stats st = channelStats(img, k);
            qInfo("channel %d: %.5f +- %.5f, quadrature %.5f", k, st.mean, st.stderr_, expected);
            QVERIFY2(std::fabs(st.mean - expected) < 4.0 * st.stderr_ + 2e-4 * expected, qPrintable(QString::number(st.mean)));
            QVERIFY(st.stderr_ < 0.01 * expected);
        }
    }

    // The LB grid as a radiance cache (lighting.bounces): a path cut after N bounces and ended in the grid's
    // scattered light. Its first surface's direct light is the path tracer's, bit for bit (the same samples);
    // each traced bounce brings the picture closer to the path tracer's (the same paths up to the cut: what
    // differs is the grid standing for the tail), within 1% by 6 bounces; without the grid's light (indirect
    // scale 0) a cut after N bounces is the path tracer at max_bounces N.
    void cacheConvergesToThePathTracer()
    {
        Scene s = test::smallForest();
        s.render.width = 60;
        s.render.height = 40;
        s.render.spp = 16;
        s.lighting.direct = DirectLight::Once;
        const std::vector<SpeciesAssets> assets = loadSpeciesAssets(s, nullptr, false);
        auto film = [&](const Scene& sc) { return renderFilm(buildRenderScene(sc, assets, sunRadiance(sc.sun)).view()); };
        Scene path = s;
        path.render.integrator = Integrator::Path;
        const Film truth = film(path);
        const std::vector<glm::vec3> truthFull = composeMode(truth, RenderMode::Full, s.sky);
        std::vector<double> err;
        for (int b : {0, 1, 2, 6}) {
            s.lighting.bounces = b;
            const Film f = film(s);
            err.push_back(relativeL2(composeMode(f, RenderMode::Full, s.sky), truthFull));
            qInfo("%d bounces before the grid: %.4f relative L2 of luminance from the path tracer", b, err.back());
            if (b == 0) continue;
            for (size_t i = 0; i < f.pixels.size(); ++i)
                QVERIFY2(f.pixels[i].local == truth.pixels[i].local, qPrintable(QString("pixel %1's direct light").arg(i)));
        }
        QVERIFY(err[1] < err[0]);
        QVERIFY(err[2] < err[1]);
        QVERIFY2(err[3] < 0.01, qPrintable(QString::number(err[3])));
        // No grid light: the cut path is the path tracer's at that depth, bit for bit.
        s.lighting.bounces = 2;
        s.render.indirectScale = 0.0f;
        path.render.maxBounces = 2;
        const Film cut = film(s), short_ = film(path);
        for (size_t i = 0; i < cut.pixels.size(); ++i) {
            QVERIFY(cut.pixels[i].local == short_.pixels[i].local);
            QVERIFY(cut.pixels[i].indirect == short_.pixels[i].indirect);
        }
    }

    // render.bounce_samples: the ground's closed form still holds (its albedo is one colour, so the shared bounced
    // light is exact in expectation); every sample still gets a whole path's direct light (the same numbers, to float
    // rounding of the sum's order); bounce_samples = spp is the picture bit for bit; on a small forest at 16 spp with 4
    // bounce samples the picture is closer to the converged one than 4 whole samples (the same paths, 4x the pixel's
    // geometry), its mean within 1%.
    void bounceSamplesShareTheBouncedLight()
    {
        Scene g = groundScene();
        g.render.integrator = Integrator::Lb;
        g.lighting.bounces = 2;
        g.render.bounceSamples = 4;
        checkGround(g, "lb, 2 bounces on 4 of 64 samples");

        Scene s = test::smallForest();
        s.render.width = 60;
        s.render.height = 40;
        s.lighting.direct = DirectLight::Once;
        s.lighting.bounces = 2;
        const std::vector<SpeciesAssets> assets = loadSpeciesAssets(s, nullptr, false);
        auto film = [&](int spp, int bounceSamples) {
            Scene sc = s;
            sc.render.spp = spp;
            sc.render.bounceSamples = bounceSamples;
            return renderFilm(buildRenderScene(sc, assets, sunRadiance(sc.sun)).view());
        };
        const Film whole = film(16, 0), all = film(16, 16), shared = film(16, 4);
        for (size_t i = 0; i < whole.pixels.size(); ++i) {
            QVERIFY(all.pixels[i].local == whole.pixels[i].local && all.pixels[i].indirect == whole.pixels[i].indirect);
            const glm::vec3 a = shared.pixels[i].local, b = whole.pixels[i].local;
            for (int c = 0; c < 3; ++c)
                QVERIFY2(std::fabs(a[c] - b[c]) <= 1e-5f * std::max(1.0f, std::fabs(b[c])),
                         qPrintable(QString("pixel %1's direct light: %2 against %3").arg(i).arg(a[c]).arg(b[c])));
        }
        const std::vector<glm::vec3> truth = composeMode(film(256, 0), RenderMode::Full, s.sky);
        const std::vector<glm::vec3> four = composeMode(film(4, 0), RenderMode::Full, s.sky);
        const std::vector<glm::vec3> pic = composeMode(shared, RenderMode::Full, s.sky);
        const double eFour = relativeL2(four, truth), eShared = relativeL2(pic, truth), eWhole = relativeL2(composeMode(whole, RenderMode::Full, s.sky), truth);
        qInfo("relative L2 from 256 whole samples: 4 whole %.4f, 16 with 4 bounce samples %.4f, 16 whole %.4f", eFour, eShared, eWhole);
        QVERIFY2(eShared < eFour, qPrintable(QString("%1 against %2").arg(eShared).arg(eFour)));
        QVERIFY(eWhole < eShared);
        QVERIFY2(std::fabs(mean(pic) / mean(truth) - 1.0) < 0.01, qPrintable(QString::number(mean(pic) / mean(truth))));
    }

    // The white furnace: with every albedo 1 under a sky of radiance 1 and no sun, whatever the paths do the
    // radiance everywhere is 1; the sphere's underside sees the ground and the ground the sphere, so it takes
    // every bounce (and the roulette's weights) to get it.
    void whiteFurnace()
    {
        Scene s = groundScene();
        s.ground.color = glm::vec3(1.0f);
        s.sky = glm::vec3(1.0f);
        s.sun.intensity = 0.0f;
        s.camera.position = {0.0, 1.2, -3.0};
        s.camera.target = {0.0, 0.5, 0.0};
        s.camera.fovY = 30.0f;
        s.render.maxBounces = kMaxPathBounces;
        RenderScene rs = buildRenderScene(s, {}, sunRadiance(s.sun));
        // A white sphere just above the ground, in the frame's camera-relative coordinates (the camera at (0, 1.2, -3)).
        rs.sphereRecords = {SphereRecord{glm::vec3(0.0f, -0.6f, 3.0f), 0.55f, glm::vec3(1.0f), 0u}};
        RenderView v = rs.view();
        const std::vector<glm::vec3> img = composeMode(renderFilm(v), RenderMode::Full, s.sky);
        int sphere = 0;
        for (const SampleParts& p : renderFilm(v).pixels) sphere += p.depth < kSkyDepth && p.normal.y < 0.9f;
        QVERIFY2(sphere > int(img.size()) / 4, "the sphere fills too little of the frame");
        for (int k = 0; k < 3; ++k) {
            const Stats st = channelStats(img, k);
            qInfo("channel %d: %.5f +- %.5f (1 expected), %d sphere pixels", k, st.mean, st.stderr_, sphere);
            QVERIFY2(std::fabs(st.mean - 1.0) < 4.0 * st.stderr_ + 1e-4, qPrintable(QString::number(st.mean)));
        }
        // Without the bounces the sphere's underside and the ground under it are darker.
        v.maxBounces = 0;
        QVERIFY(channelStats(composeMode(renderFilm(v), RenderMode::Full, s.sky), 1).mean < 0.97);
    }

    // Under the sun alone with 0 bounces, the path tracer's picture is the LB integrator's direct light (local
    // mode): the same shadow rays, the same Lambert and Phong terms, once the leaves transmit nothing (g = -1).
    void zeroBouncesIsTheDirectLight()
    {
        Scene s = test::smallForest();
        s.sky = glm::vec3(0.0f);
        for (SpeciesDesc& sp : s.species)
            for (lb::ChannelParams& ch : sp.lighting.channels) ch.g = -1.0f;
        for (const SpeciesDesc& sp : s.species) QCOMPARE(lb::leafOptics(sp.lighting).ratio, glm::vec3(0.0f));
        const std::vector<SpeciesAssets> assets = loadSpeciesAssets(s, nullptr, false);
        const std::vector<glm::vec3> lb = render(s, assets, RenderMode::Local);
        s.render.integrator = Integrator::Path;
        s.render.maxBounces = 0;
        const std::vector<glm::vec3> path = render(s, assets);
        double worst = 0.0;
        int lit = 0;
        for (size_t i = 0; i < lb.size(); ++i) {
            for (int k = 0; k < 3; ++k) worst = std::max(worst, double(std::fabs(path[i][k] - lb[i][k])) / std::max(1e-3, double(lb[i][k])));
            lit += luminance(lb[i]) > 0.0f;
        }
        qInfo("largest relative difference %.2e over %zu pixels (%d lit)", worst, lb.size(), lit);
        QVERIFY(lit > int(lb.size()) / 10);
        QVERIFY2(worst < 1e-4, qPrintable(QString::number(worst)));
    }

    // A leaf lit from behind shows its transmission: kd x ratio (capped) x sunRadiance x |cos|.
    void leafTransmitsTheSun()
    {
        Scene s;
        s.species.resize(1);
        s.species[0].name = "card";
        s.species[0].lighting = lb::paramsFromPreset(*lb::findPreset("leaf"));
        InstanceDesc card;
        card.position = {0.0, 0.0, 0.0};
        s.instances = {card};
        s.ground.enabled = false;
        s.sky = glm::vec3(0.0f);
        s.camera.position = {0.0, 0.5, -4.0};
        s.camera.target = {0.0, 0.5, 0.0};
        s.camera.fovY = 20.0f;
        s.sun.direction = glm::normalize(glm::vec3(0.3f, 0.2f, 1.0f));   // behind the card, seen from the camera
        s.render.width = 24;
        s.render.height = 24;
        s.render.spp = 1;
        s.render.integrator = Integrator::Path;
        s.render.maxBounces = 0;
        std::vector<SpeciesAssets> assets(1);
        // One opaque leaf quad facing -z, 1 m square, no texture.
        TriangleMesh& m = assets[0].mesh;
        m.positions = {{-0.5f, 0.0f, 0.0f}, {0.5f, 0.0f, 0.0f}, {0.5f, 1.0f, 0.0f}, {-0.5f, 1.0f, 0.0f}};
        m.normals = std::vector<glm::vec3>(4, glm::vec3(0.0f, 0.0f, -1.0f));
        m.uvs = std::vector<glm::vec2>(4, glm::vec2(0.0f));
        m.triangles = {{0, 1, 2}, {0, 2, 3}};
        m.triangleMaterial = {0, 0};
        Material leaf;
        leaf.name = "leaf";
        leaf.diffuse = {0.2f, 0.5f, 0.1f};
        leaf.isLeaf = true;
        m.materials = {leaf};
        const std::vector<glm::vec3> img = render(s, assets);
        const glm::vec3 ratio = lb::leafOptics(s.species[0].lighting).ratio;
        const glm::vec3 rad = sunRadiance(s.sun);
        const float cosBack = glm::normalize(s.sun.direction).z;   // the card's back faces +z
        const glm::vec3 centre = img[size_t(12 * 24 + 12)];
        for (int k = 0; k < 3; ++k) {
            const float t = std::min(leaf.diffuse[k] * ratio[k], lb::kMaxLeafScattering - leaf.diffuse[k]);
            const float expected = t * rad[k] * cosBack;
            qInfo("channel %d: %.6f, closed form %.6f", k, double(centre[k]), double(expected));
            QVERIFY(expected > 0.0f);
            QVERIFY2(std::fabs(centre[k] / expected - 1.0f) < 1e-5f, qPrintable(QString::number(centre[k])));
        }
    }

    // More light with each bounce, converged by 8 (the 64-bounce picture within 1%); the same bits twice.
    void bouncesAddLight()
    {
        Scene s = test::smallForest();
        s.render.integrator = Integrator::Path;
        s.render.width = 60;
        s.render.height = 40;
        s.render.spp = 16;
        const std::vector<SpeciesAssets> assets = loadSpeciesAssets(s, nullptr, false);
        std::vector<double> means;
        for (int b : {0, 1, 8, 64}) {
            s.render.maxBounces = b;
            means.push_back(mean(render(s, assets)));
            qInfo("%d bounces: mean luminance %.5f", b, means.back());
        }
        QVERIFY(means[1] > means[0] * 1.01);
        QVERIFY(means[2] > means[1]);
        QVERIFY2(std::fabs(means[3] / means[2] - 1.0) < 0.01, qPrintable(QString::number(means[3] / means[2])));
        const std::vector<glm::vec3> again = render(s, assets);
        QCOMPARE(mean(again), means[3]);
    }

    void refusals()
    {
        Scene s = groundScene();
        s.render.maxBounces = kMaxPathBounces + 1;
        QVERIFY_THROWS_EXCEPTION(Error, buildRenderScene(s, {}, glm::vec3(1.0f)));
        s.render.maxBounces = 4;
        s.lighting.bounces = -1;
        QVERIFY_THROWS_EXCEPTION(Error, buildRenderScene(s, {}, glm::vec3(1.0f)));
        s.lighting.bounces = 0;
        s.render.maxBounces = 4;
        s.volumes.resize(1);
        s.volumes[0].name = "cloud";
        const std::string e = test::errorOf([&] { (void)buildRenderScene(s, {}, glm::vec3(1.0f)); });
        QVERIFY2(e.find("does not trace volumes") != std::string::npos, e.c_str());
    }
};

QTEST_GUILESS_MAIN(TestPathTrace)
#include "tst_path_trace.moc"
