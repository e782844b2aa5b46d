// The renderer's extension points as lists: the spheres surface kind and the point light, the smallest entries
// of the surface and light lists (core/render/surfaces, core/render/lights), against closed forms: the
// ray/sphere distance and silhouette, Lambert's cosine law, the inverse-square law, a sphere's geometric shadow,
// superposition over the light list, and the lights' sample / eval / pdf against each other.
#include <QTest>

#include <cmath>
#include <random>

#include "core/render/render_cpu.h"
#include "core/render/render_scene.h"
#include "core/render/shade.h"

using namespace sylva;

namespace {

constexpr int kW = 64, kH = 48;

// A frame with no species: a camera at the origin looking down -z, the given spheres and lights, no sky.
RenderScene makeFrame(const std::vector<SphereRecord>& spheres, const std::vector<LightRecord>& lights, bool ground, float groundY = -1.0f)
{
    RenderScene rs;
    CameraDesc cam;
    cam.position = glm::dvec3(0.0);
    cam.target = glm::dvec3(0.0, 0.0, -1.0);
    cam.fovY = 40.0f;
    rs.frame.camera = makeCamera(cam, kW, kH);
    rs.frame.width = kW;
    rs.frame.height = kH;
    rs.frame.spp = 1;
    rs.frame.shadows = true;
    rs.frame.indirectScale = 1.0f;
    rs.frame.ground.enabled = ground;
    rs.frame.ground.y = groundY;
    rs.frame.ground.color = glm::vec3(0.5f, 0.4f, 0.3f);
    rs.sphereRecords = spheres;
    rs.lights = lights;
    return rs;
}

LightRecord distant(const glm::vec3& dir, const glm::vec3& radiance)
{
    LightRecord l{};
    l.kind = LightKind::Distant;
    l.direction = glm::normalize(dir);
    l.radiance = radiance;
    return l;
}

LightRecord point(const glm::vec3& at, const glm::vec3& radiance)
{
    LightRecord l{};
    l.kind = LightKind::Point;
    l.position = at;
    l.radiance = radiance;
    return l;
}

SphereRecord sphere(const glm::vec3& c, float r, const glm::vec3& albedo) { return SphereRecord{c, r, albedo, 0u}; }

// The closed-form first hit of a ray from the origin along unit d on a sphere (in double): -1 on a miss.
double sphereDistance(const glm::dvec3& d, const glm::dvec3& c, double r)
{
    const double b = glm::dot(d, c), disc = b * b - (glm::dot(c, c) - r * r);
    if (disc < 0.0) return -1.0;
    return b - std::sqrt(disc);
}

bool near(float a, float b, float rel) { return std::fabs(a - b) <= rel * std::max(std::fabs(a), std::fabs(b)) + 1e-7f; }

} // namespace

class TestRenderLists : public QObject {
    Q_OBJECT
private Q_SLOTS:
    // The spheres kind: every pixel's hit and distance as the closed form gives them, the surface Lambertian
    // under a distant light (albedo x radiance x cos), and dark where it faces away.
    void sphereKindMatchesClosedForm()
    {
        const glm::vec3 c(0.3f, -0.2f, -6.0f), albedo(0.8f, 0.5f, 0.2f), rad(2.0f, 1.5f, 1.0f);
        const float r = 1.25f;
        const LightRecord sun = distant(glm::vec3(1.0f, 1.0f, 1.0f), rad);
        const RenderScene rs = makeFrame({sphere(c, r, albedo)}, {sun}, false);
        const RenderView v = rs.view();
        QCOMPARE(v.spheres.count, 1u);
        int hits = 0, lit = 0, checked = 0;
        for (int y = 0; y < kH; ++y)
            for (int x = 0; x < kW; ++x) {
                const Ray ray = cameraRay(v, float(x) + 0.5f, float(y) + 0.5f);
                const double t = sphereDistance(glm::dvec3(ray.dir), glm::dvec3(c), double(r));
                Hit h{};
                const bool found = traceScene<false>(v, ray, h);
                // Grazing rays decide in float what double decides otherwise: leave the silhouette's edge out.
                const double b = glm::dot(glm::dvec3(ray.dir), glm::dvec3(c));
                if (std::fabs(b * b - (glm::dot(glm::dvec3(c), glm::dvec3(c)) - double(r) * r)) < 1e-3) continue;
                ++checked;
                QCOMPARE(found, t > 0.0);
                if (!found) continue;
                ++hits;
                QCOMPARE(hitKind(h), SurfaceKind::Spheres);
                QVERIFY(std::fabs(double(h.t) - t) < 1e-5 * t);
                const SampleParts p = shadeRay(v, ray, x, y, 0);
                const glm::vec3 n = glm::normalize(glm::vec3(glm::dvec3(ray.dir) * t - glm::dvec3(c)));
                const float cosine = glm::dot(n, sun.direction);
                // The normal from the float hit point: the cosine within 1e-4 absolute (terminator pixels included).
                for (int k = 0; k < 3; ++k)
                    QVERIFY(std::fabs(p.local[k] - (cosine > 0.0f ? albedo[k] * rad[k] * cosine : 0.0f)) <= 1e-4f * albedo[k] * rad[k]);
                lit += cosine > 0.0f;
            }
        // The disc covers about pi (r / d)^2 / (2 tan(fov/2))^2 x the image's height^2 pixels.
        QVERIFY(checked > kW * kH * 9 / 10);
        QVERIFY(hits > 200 && lit > 50 && lit < hits);
    }

    // The point light: the ground plane lit by albedo x radiance x cos / r^2, and a sphere between the lamp and
    // the ground casting exactly the shadow the segment/sphere test gives.
    void pointLightInverseSquareAndShadow()
    {
        const glm::vec3 lamp(0.0f, 3.0f, -8.0f), rad(40.0f, 30.0f, 20.0f);
        const glm::vec3 c(0.0f, 0.2f, -8.0f);
        const float r = 0.6f;
        const RenderScene rs = makeFrame({sphere(c, r, glm::vec3(0.5f))}, {point(lamp, rad)}, true, -1.0f);
        const RenderView v = rs.view();
        const glm::vec3 albedo = v.ground.color;
        int ground = 0, shadowed = 0;
        for (int y = kH / 2; y < kH; ++y)
            for (int x = 0; x < kW; ++x) {
                const Ray ray = cameraRay(v, float(x) + 0.5f, float(y) + 0.5f);
                Hit h{};
                if (!traceScene<false>(v, ray, h) || hitKind(h) != SurfaceKind::Ground) continue;
                const glm::dvec3 p = glm::dvec3(ray.dir) * double(h.t);
                // The oracle: does the segment p -> lamp cross the sphere (in double)?
                const glm::dvec3 d = glm::dvec3(lamp) - p, oc = p - glm::dvec3(c);
                const double a = glm::dot(d, d), b = glm::dot(oc, d), cc = glm::dot(oc, oc) - double(r) * r;
                const double disc = b * b - a * cc;
                const bool blocked = disc > 0.0 && (-b - std::sqrt(disc)) / a > 0.0 && (-b - std::sqrt(disc)) / a < 1.0;
                if (disc > 0.0 && std::fabs(disc) < 1e-3 * a) continue;   // the penumbra-free edge, left to float
                const SampleParts s = shadeRay(v, ray, x, y, 0);
                ++ground;
                if (blocked) {
                    ++shadowed;
                    QCOMPARE(s.local, glm::vec3(0.0f));
                    continue;
                }
                const double r2 = glm::dot(d, d), cosine = d.y / std::sqrt(r2);
                for (int k = 0; k < 3; ++k) QVERIFY(near(s.local[k], float(albedo[k] * rad[k] * cosine / r2), 2e-4f));
            }
        QVERIFY(ground > 500);
        QVERIFY(shadowed > 10);
    }

    // Superposition: a frame lit by two lights is the sum of the frames lit by each (the light stage adds the
    // list's entries), in every backend's shared stage; and the packet lights' answers match tracing alone.
    void lightListAdds()
    {
        const std::vector<SphereRecord> spheres{sphere(glm::vec3(-0.8f, 0.0f, -6.0f), 0.9f, glm::vec3(0.7f)),
                                                sphere(glm::vec3(0.9f, 0.3f, -7.0f), 1.1f, glm::vec3(0.3f, 0.6f, 0.4f))};
        const LightRecord a = distant(glm::vec3(-1.0f, 2.0f, 0.5f), glm::vec3(1.0f, 0.9f, 0.8f));
        const LightRecord b = point(glm::vec3(2.0f, 2.0f, -4.0f), glm::vec3(5.0f));
        const Film both = renderFilm(makeFrame(spheres, {a, b}, true).view());
        const Film onlyA = renderFilm(makeFrame(spheres, {a}, true).view());
        const Film onlyB = renderFilm(makeFrame(spheres, {b}, true).view());
        int litByBoth = 0;
        for (size_t i = 0; i < both.pixels.size(); ++i) {
            const glm::vec3 sum = onlyA.pixels[i].local + onlyB.pixels[i].local;
            for (int k = 0; k < 3; ++k) QVERIFY(near(both.pixels[i].local[k], sum[k], 1e-6f));
            litByBoth += onlyA.pixels[i].local.x > 0.0f && onlyB.pixels[i].local.x > 0.0f;
        }
        QVERIFY(litByBoth > 100);
    }

    // sample / eval / pdf agree: Monte Carlo irradiance from the sky light's samples is pi x its radiance on an
    // upward surface under a constant sky; eval over pdf is what a sample carries; delta lights carry their
    // irradiance at normal incidence (pi x radiance, / r^2 for the point light) and eval / pdf 0.
    void sampleEvalPdfAgree()
    {
        RenderScene rs = makeFrame({}, {}, false);
        rs.frame.sky.constant = glm::vec3(0.25f, 0.5f, 1.0f);
        LightRecord skyLight{};
        skyLight.kind = LightKind::Sky;
        const LightRecord sun = distant(glm::vec3(0.0f, 1.0f, 0.0f), glm::vec3(2.0f));
        const LightRecord lamp = point(glm::vec3(0.0f, 2.0f, 0.0f), glm::vec3(8.0f));
        rs.lights = {sun, skyLight, lamp};
        const RenderView v = rs.view();
        std::mt19937 rng(7);
        std::uniform_real_distribution<float> u01(0.0f, 1.0f);
        const int n = 200000;
        glm::dvec3 e(0.0);
        for (int i = 0; i < n; ++i) {
            const LightSample s = lightSample(v, v.lights[1], glm::vec3(0.0f), glm::vec2(u01(rng), u01(rng)));
            QVERIFY(!s.delta);
            QVERIFY(std::fabs(glm::length(s.wi) - 1.0f) < 1e-5f);
            const glm::vec3 expect = lightEval(v, v.lights[1], s.wi) / lightPdf(v, v.lights[1], s.wi);
            QVERIFY(near(s.value.x, expect.x, 1e-6f) && near(s.value.z, expect.z, 1e-6f));
            e += glm::dvec3(s.value) * double(std::max(0.0f, s.wi.y));
        }
        e /= double(n);
        for (int k = 0; k < 3; ++k) QVERIFY(std::fabs(e[k] - sky::kPi * rs.frame.sky.constant[k]) < 0.01 * sky::kPi * rs.frame.sky.constant[k]);
        const LightSample ss = lightSample(v, v.lights[0], glm::vec3(0.0f), glm::vec2(0.5f));
        QVERIFY(ss.delta && ss.wi == sun.direction && near(ss.value.x, sky::kPi * 2.0f, 1e-6f));
        QCOMPARE(lightPdf(v, v.lights[0], sun.direction), 0.0f);
        QCOMPARE(lightEval(v, v.lights[0], sun.direction), glm::vec3(0.0f));
        const LightSample ls = lightSample(v, v.lights[2], glm::vec3(0.0f, 0.0f, 0.0f), glm::vec2(0.5f));
        QVERIFY(ls.delta && near(ls.distance, 2.0f, 1e-6f) && near(ls.value.x, sky::kPi * 8.0f / 4.0f, 1e-6f));
        QCOMPARE(ls.wi, glm::vec3(0.0f, 1.0f, 0.0f));
    }
};

QTEST_GUILESS_MAIN(TestRenderLists)
#include "tst_render_lists.moc"
