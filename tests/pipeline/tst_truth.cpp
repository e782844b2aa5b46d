// The ground-truth harness without Blender (CI): the leaf optics against a quadrature of the HG phase, the
// Blender camera against Sylva's camera rays, the script's sun, sky, camera and instance values against
// the scene, the mesh arrays and cut-out read back, and FLIP against the published formula's values.
#include <QTemporaryDir>
#include <QTest>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <regex>
#include <sstream>

#include "core/lb/leaf_optics.h"
#include "core/render/render_scene.h"
#include "core/render/shade.h"
#include "pipeline/io/image_io.h"
#include "pipeline/render/frame_build.h"
#include "pipeline/render/render_job.h"
#include "pipeline/scene/scene_file.h"
#include "pipeline/study/blender_scene.h"
#include "pipeline/study/flip.h"
#include "pipeline/study/study.h"

using namespace sylva;
using namespace sylva::study;

namespace {

// Forward share of the HG phase by Simpson's rule over mu in [0, 1] (the pdf in mu, normalized on [-1, 1]).
double hgForwardQuadrature(double g)
{
    const int n = 20000;
    auto p = [g](double mu) { return 0.5 * (1.0 - g * g) / std::pow(1.0 + g * g - 2.0 * g * mu, 1.5); };
    double s = p(0.0) + p(1.0);
    for (int i = 1; i < n; ++i) s += (i % 2 ? 4.0 : 2.0) * p(double(i) / n);
    return s / (3.0 * n);
}

std::string readText(const std::string& path)
{
    std::ifstream in(path);
    std::stringstream ss;
    ss << in.rdbuf();
    return ss.str();
}

// The number after `key` in the script ("sund.energy = 3.14 * SUN_ON").
double scriptNumber(const std::string& text, const std::string& key)
{
    const size_t at = text.find(key);
    if (at == std::string::npos) return std::nan("");
    return std::atof(text.c_str() + at + key.size());
}

std::vector<double> numbersIn(const std::string& s)
{
    std::vector<double> v;
    static const std::regex num(R"([-+]?[0-9]*\.?[0-9]+(?:[eE][-+]?[0-9]+)?)");
    for (auto it = std::sregex_iterator(s.begin(), s.end(), num); it != std::sregex_iterator(); ++it) v.push_back(std::stod(it->str()));
    return v;
}

std::vector<glm::vec3> uniform(int w, int h, glm::vec3 c) { return std::vector<glm::vec3>(size_t(w * h), c); }

} // namespace

class TestTruth : public QObject {
    Q_OBJECT
private Q_SLOTS:
    void forwardShareMatchesQuadrature()
    {
        for (double g : {-0.9, -0.333, -0.12, -0.01, 0.0, 1e-7, 0.091, 0.5, 0.9})
            QVERIFY2(std::fabs(forwardShare(g) - hgForwardQuadrature(g)) < 1e-6, qPrintable(QString::number(g)));
        QCOMPARE(forwardShare(1.0), 1.0);
        QCOMPARE(forwardShare(-1.0), 0.0);
        const LeafOptics o = leafOptics(lb::paramsFromPreset(*lb::findPreset("leaf")));
        for (int c = 0; c < 3; ++c) {
            QVERIFY(std::fabs(o.reflectance[c] + o.transmittance[c] - o.albedo[c]) < 1e-6f);
            QVERIFY(std::fabs(o.ratio[c] - o.transmittance[c] / o.reflectance[c]) < 1e-5f);
        }
        QVERIFY(std::fabs(o.albedo.y - 0.909f) < 1e-6f);
        QVERIFY(o.ratio.y > 1.0f && o.ratio.x < 1.0f && o.ratio.z < o.ratio.x);   // g > 0 green, g < 0 red and more so blue
    }

    // A world point lands on the same image position through Sylva's camera rays and Blender's camera
    // (local -Z forward, +Y up, vertical fit of angle_y), after the axis change.
    void cameraMatchesSylvaRays()
    {
        CameraDesc c;
        c.position = {3.0, 2.0, -7.0};
        c.target = {-1.0, 5.0, 9.0};
        c.fovY = 37.0f;
        const int w = 160, h = 120;
        const CameraRecord rec = makeCamera(c, w, h);
        const std::array<double, 16> m = blenderCameraMatrix(c);
        const double tanY = std::tan(double(c.fovY) * M_PI / 360.0), tanX = tanY * w / h;
        for (glm::dvec3 p : {glm::dvec3(0, 3, 4), glm::dvec3(-2, 6, 11), glm::dvec3(4, 1, 2)}) {
            const glm::dvec3 d = p - c.position;
            const double sx = glm::dot(d, glm::dvec3(rec.right)) / glm::dot(d, glm::dvec3(rec.forward)) / double(rec.tanHalfX);
            const double sy = glm::dot(d, glm::dvec3(rec.up)) / glm::dot(d, glm::dvec3(rec.forward)) / double(rec.tanHalfY);
            const glm::dvec3 b = toBlender(p) - glm::dvec3(m[3], m[7], m[11]);
            // local = R^T b (R orthonormal: the matrix's columns)
            const glm::dvec3 lx(m[0], m[4], m[8]), ly(m[1], m[5], m[9]), lz(m[2], m[6], m[10]);
            QVERIFY(std::fabs(glm::length(lx) - 1.0) < 1e-9 && std::fabs(glm::dot(glm::cross(lx, ly), lz) - 1.0) < 1e-9);
            const glm::dvec3 l(glm::dot(b, lx), glm::dot(b, ly), glm::dot(b, lz));
            QVERIFY(l.z < 0.0);
            QVERIFY(std::fabs(l.x / -l.z / tanX - sx) < 1e-6);
            QVERIFY(std::fabs(l.y / -l.z / tanY - sy) < 1e-6);
        }
    }

    void scriptCarriesTheScene()
    {
        QTemporaryDir tmp;
        Scene s;
        s.render.width = 64;
        s.render.height = 48;
        s.sun.direction = sunDirection(35.0, 70.0);
        s.sun.intensity = 2.5f;
        s.sky = {0.3f, 0.4f, 0.6f};
        s.camera.fovY = 33.0f;
        s.ground.color = {0.2f, 0.25f, 0.1f};
        SpeciesDesc sp;
        sp.name = "card one";
        sp.lighting = lb::paramsFromPreset(*lb::findPreset("leaf"));
        s.species = {sp};
        InstanceDesc in;
        in.position = {1.5, 0.0, 4.0};
        in.rotationDeg = {0.0f, 90.0f, 0.0f};
        in.scale = 2.0f;
        s.instances = {in};
        SpeciesAssets a;
        a.mesh.positions = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}};
        a.mesh.normals = {{0, 0, 1}, {0, 0, 1}, {0, 0, 1}, {0, 0, 1}};
        a.mesh.uvs = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
        a.mesh.triangles = {{0, 1, 2}, {0, 2, 3}};
        a.mesh.triangleMaterial = {0, 0};
        Material leaf;
        leaf.name = "leaf";
        leaf.isLeaf = true;
        leaf.diffuse = {0.5f, 0.6f, 0.7f};
        a.mesh.materials = {leaf};
        ImageRgba tex(2, 2, glm::vec4(0.2f, 0.5f, 0.1f, 1.0f));
        tex.pixels[3] = 0.3f;   // texel 0 transparent (alpha < 0.5)
        a.diffuse = {tex};
        a.cutout = {tex};
        const std::string dir = tmp.path().toStdString() + "/scene";
        const std::string script = writeBlenderScene(s, {a}, dir, BlenderOptions{});
        const std::string text = readText(script);

        // Camera: vertical field of view in radians; resolution.
        QVERIFY(std::fabs(scriptNumber(text, "camd.angle_y = ") - 33.0 * M_PI / 180.0) < 1e-7);
        QCOMPARE(int(scriptNumber(text, "sc.render.resolution_x = ")), 64);
        QCOMPARE(int(scriptNumber(text, "sc.render.resolution_y = ")), 48);
        // Sun: strength x colour = pi x sunRadiance (Cycles' Lambertian shows strength x colour x cos / pi).
        const glm::vec3 rad = sunRadiance(s.sun);
        const double strength = scriptNumber(text, "sund.energy = ");
        const size_t ci = text.find("sund.color = ");
        const std::vector<double> col = numbersIn(text.substr(ci + 13, text.find('\n', ci) - ci - 13));
        QCOMPARE(int(col.size()), 3);
        for (int c = 0; c < 3; ++c) QVERIFY(std::fabs(strength * col[size_t(c)] - M_PI * double(rad[c])) < 1e-5 * M_PI * double(rad[c]));
        // Sun direction: the lamp's local +Z (third column) is the direction toward the sun, in Blender's frame.
        const size_t si = text.find("suno.matrix_world = Matrix(");
        const std::vector<double> sm = numbersIn(text.substr(si + 27, text.find('\n', si) - si - 27));
        QCOMPARE(int(sm.size()), 16);
        const glm::dvec3 toSun = glm::normalize(toBlender(glm::dvec3(s.sun.direction)));
        QVERIFY(std::fabs(sm[2] - toSun.x) < 1e-7 && std::fabs(sm[6] - toSun.y) < 1e-7 && std::fabs(sm[10] - toSun.z) < 1e-7);
        // Sky colour, ground colour.
        QVERIFY(text.find("bg.inputs['Color'].default_value = (0.300000012, 0.400000006, 0.600000024, 1.0)") != std::string::npos);
        QVERIFY(text.find("material('ground', (0.200000003, 0.25, 0.100000001)") != std::string::npos);
        // Instance: Y rotation by 90 degrees, scale 2, at (1.5, 0, 4): species +X -> Sylva -Z x 2 -> Blender +Y x 2.
        const size_t ii = text.find("INSTANCES = [\n");
        const std::vector<double> im = numbersIn(text.substr(ii + 14, text.find("]\n", ii) - ii - 14));
        QCOMPARE(int(im.size()), 17);   // species index + 16
        QVERIFY(std::fabs(im[1 + 0] - 0.0) < 1e-9 && std::fabs(im[1 + 4] - 2.0) < 1e-9 && std::fabs(im[1 + 8]) < 1e-9);
        QVERIFY(std::fabs(im[1 + 3] - 1.5) < 1e-9 && std::fabs(im[1 + 7] + 4.0) < 1e-9 && std::fabs(im[1 + 11]) < 1e-9);
        // Leaf material: diffuse, translucent ratio from the preset, colour texture and cut-out named.
        const LeafOptics lo = leafOptics(sp.lighting);
        const size_t mi = text.find("material(r's0_card_one_leaf', ");
        QVERIFY(mi != std::string::npos);
        const std::vector<double> mv = numbersIn(text.substr(mi + 30, 120));
        QVERIFY(std::fabs(mv[0] - 0.5) < 1e-7 && std::fabs(mv[2] - 0.7) < 1e-7);
        for (int c = 0; c < 3; ++c) QVERIFY(std::fabs(mv[size_t(3 + c)] - double(lo.ratio[c])) < 1e-7);
        QVERIFY(text.find("r's0_card_one_m0_color.png', r's0_card_one_m0_mask.png')") != std::string::npos);
        // Mesh arrays read back bit for bit; the cut-out thresholded at 0.5.
        std::ifstream pf(dir + "/s0_card_one.pos.f32", std::ios::binary);
        std::vector<glm::vec3> pos(4);
        pf.read(reinterpret_cast<char*>(pos.data()), 4 * sizeof(glm::vec3));
        QVERIFY(pf.gcount() == 4 * sizeof(glm::vec3) && pos == a.mesh.positions);
        std::ifstream tf(dir + "/s0_card_one.tri.u32", std::ios::binary | std::ios::ate);
        QCOMPARE(int(tf.tellg()), int(2 * sizeof(glm::uvec3)));
        const ImageRgba mask = readImage(dir + "/s0_card_one_m0_mask.png");
        QCOMPARE(mask.pixels[0], 0.0f);
        QCOMPARE(mask.pixels[4], 1.0f);
    }

    void exportRefusesWhatItCannotExpress()
    {
        QTemporaryDir tmp;
        Scene s;
        s.groups.resize(1);
        QVERIFY_THROWS_EXCEPTION(Error, writeBlenderScene(s, {}, tmp.path().toStdString(), BlenderOptions{}));
        Scene t;
        t.skyModel.kind = sky::SkyKind::Preetham;
        QVERIFY_THROWS_EXCEPTION(Error, writeBlenderScene(t, {}, tmp.path().toStdString(), BlenderOptions{}));
    }

    // FLIP: published CIELAB of the sRGB primaries (D65), and uniform pictures, where the filters keep the
    // colour and no feature exists, against the paper's colour formula evaluated here.
    void flipAgainstThePublishedFormula()
    {
        const glm::dvec3 g = srgbToLab({0, 1, 0}), b = srgbToLab({0, 0, 1});
        QVERIFY(std::fabs(g.x - 87.7347) < 0.01 && std::fabs(g.y + 86.1827) < 0.01 && std::fabs(g.z - 83.1793) < 0.01);
        QVERIFY(std::fabs(b.x - 32.3026) < 0.01 && std::fabs(b.y - 79.1967) < 0.01 && std::fabs(b.z + 107.8637) < 0.01);
        // Black against white: HyAB = 100 (L only; Hunt-adjusted a, b are 0); cmax = HyAB(green, blue)^0.7.
        auto huntLab = [](glm::dvec3 l) { return glm::dvec3(l.x, 0.01 * l.x * l.y, 0.01 * l.x * l.z); };
        const glm::dvec3 hg = huntLab({87.7347, -86.1827, 83.1793}), hb = huntLab({32.3026, 79.1967, -107.8637});
        const double cmax = std::pow(std::fabs(hg.x - hb.x) + std::hypot(hg.y - hb.y, hg.z - hb.z), 0.7);
        const double e = std::pow(100.0, 0.7);
        const double expected = e < 0.4 * cmax ? 0.95 / (0.4 * cmax) * e : 0.95 + (e - 0.4 * cmax) / (cmax - 0.4 * cmax) * 0.05;
        const FlipResult bw = flip(uniform(24, 20, glm::vec3(0.0f)), uniform(24, 20, glm::vec3(1.0f)), 24, 20);
        QVERIFY2(std::fabs(bw.mean - expected) < 1e-3, qPrintable(QString("%1 vs %2").arg(bw.mean).arg(expected)));
        // A darker grey pair in the linear part of the remapping.
        const glm::vec3 c1(0.40f, 0.42f, 0.38f), c2(0.43f, 0.42f, 0.40f);
        const FlipResult gg = flip(uniform(24, 20, c1), uniform(24, 20, c2), 24, 20);
        const double ce = flipColorError(glm::dvec3(c1), glm::dvec3(c2));
        QVERIFY(ce > 0.0 && ce < 0.95);
        for (float v : gg.map) QVERIFY(std::fabs(v - ce) < 1e-4);
        // Identical pictures: 0; a moved edge: the feature term raises the error above the colour term alone.
        std::vector<glm::vec3> a(40 * 30, glm::vec3(0.2f)), sh = a;
        for (int y = 0; y < 30; ++y)
            for (int x = 0; x < 40; ++x) {
                if (x >= 20) a[size_t(y * 40 + x)] = glm::vec3(0.8f);
                if (x >= 22) sh[size_t(y * 40 + x)] = glm::vec3(0.8f);
            }
        QCOMPARE(flip(a, a, 40, 30).mean, 0.0);
        const FlipResult moved = flip(a, sh, 40, 30);
        const double colourOnly = flipColorError({0.2, 0.2, 0.2}, {0.8, 0.8, 0.8});
        QVERIFY(moved.map[size_t(15 * 40 + 21)] > colourOnly * 0.5);
        QCOMPARE(moved.map[size_t(15 * 40 + 5)], 0.0f);
        const FlipResult back = flip(sh, a, 40, 30);
        QVERIFY(std::fabs(back.mean - moved.mean) < 1e-9);   // symmetric
    }

    // The study's truth part without Blender or with --quick is skipped and the report says so.
    // lighting.direct once: each species' grid is the full LB solve less the uncollided one (the same LB with
    // scattering off, solved here on its own), so open space outside the crown holds no light (the seed's sum
    // holds the unobstructed value there), and the renderer's weights are (1 + t) / 4 on leaves, 1 / 4 on bark.
    void directOnceSubtractsTheUncollidedSun()
    {
        Scene s = parseScene(R"({"version": 1, "species": [{"name": "shrub", "grow": {"species": "shrub", "seed": 2, "triangles": 2000},
            "lighting": {"preset": "leaf", "grid": 12}}], "instances": [{"species": "shrub", "position": [0, 0, 0]}],
            "lighting": {"direct": "once"}})", ".", "once.sylva.json");
        QVERIFY(s.lighting.direct == DirectLight::Once);
        QVERIFY(sceneToJson(s, ".").find("\"direct\": \"once\"") != std::string::npos);
        Scene seed = s;
        seed.lighting.direct = DirectLight::Seed;
        QVERIFY(sceneToJson(seed, ".").find("\"lighting\": {\"direct") == std::string::npos);   // the default is not written
        const std::vector<SpeciesAssets> once = loadSpeciesAssets(s, nullptr, true);
        const std::vector<SpeciesAssets> sum = loadSpeciesAssets(seed, nullptr, true);
        const SpeciesGrids g = loadSpeciesGrids(seed, 0, nullptr);
        const LightingGrid unc = lightingFor(g.density, lb::uncollidedParams(g.params), nullptr);
        const std::vector<float>& a = once[0].lighting.rgb;
        QCOMPARE(a.size(), sum[0].lighting.rgb.size());
        double openSeed = 0.0, openOnce = 0.0;
        int open = 0;
        for (size_t i = 0; i < a.size(); ++i) {
            const float want = std::max(0.0f, sum[0].lighting.rgb[i] - unc.rgb[i]);
            QVERIFY2(std::fabs(a[i] - want) <= 1e-5f * std::max(1.0f, std::fabs(want)), qPrintable(QString("node value %1: %2 vs %3").arg(i).arg(a[i]).arg(want)));
            if (g.density.density[i / 3] == 0.0f && std::fabs(unc.rgb[i] / once[0].lightingNorm[int(i % 3)] - 1.0f) < 1e-3f) {
                openSeed += sum[0].lighting.rgb[i] / sum[0].lightingNorm[int(i % 3)];
                openOnce += a[i] / once[0].lightingNorm[int(i % 3)];
                ++open;
            }
        }
        QVERIFY(open > 0);
        QVERIFY2(openOnce / open < 0.2 && openSeed / open > 0.8, qPrintable(QString("unshadowed empty nodes: once %1, seed %2").arg(openOnce / open).arg(openSeed / open)));
        const lb::ScatteredWeights w = lb::scatteredWeights(s.species[0].lighting);
        const LeafOptics lo = leafOptics(s.species[0].lighting);
        for (int c = 0; c < 3; ++c) QVERIFY(std::fabs(w.leaf[c] - (1.0f + lo.ratio[c]) / 4.0f) < 1e-6f);
        QCOMPARE(w.bark, 0.25f);
        const RenderScene rs = buildRenderScene(s, once, sunRadiance(s.sun));
        QVERIFY(std::fabs(rs.species[0].leafIndirect.y - w.leaf.y) < 1e-6f && rs.species[0].barkIndirect == 0.25f);
        const RenderScene rsSeed = buildRenderScene(seed, sum, sunRadiance(seed.sun));
        QVERIFY(rsSeed.species[0].leafIndirect == glm::vec3(1.0f) && rsSeed.species[0].barkIndirect == 1.0f);
        QCOMPARE(rs.species[0].leafIndirectCap, lb::kMaxLeafScattering / 4.0f);
        QCOMPARE(rsSeed.species[0].leafIndirectCap, std::numeric_limits<float>::max());   // the seed's sum: uncapped
    }

    // Energy: under lighting.direct once a leaf face sends back at most kMaxLeafScattering of the scattered
    // light it receives, kd x (1 + t) / 4 <= 0.98 / 4 per channel, as the Blender export's translucent cap. With
    // g = 0.9 in green (t = 19) every leaf hit's green is capped and red and blue (the preset's t) are not;
    // the light stage's indirect part is albedo x weight x L x sunRadiance with that weight.
    void onceLeafScattersAtMostItsShare()
    {
        const Scene s = parseScene(R"({"version": 1, "species": [{"name": "shrub", "grow": {"species": "shrub", "seed": 2, "triangles": 2000},
            "lighting": {"preset": "leaf", "grid": 12, "g": [-0.12, 0.9, -0.333]}}], "instances": [{"species": "shrub", "position": [0, 0, 0]}],
            "lighting": {"direct": "once"}, "render": {"width": 48, "height": 32}})", ".", "cap.sylva.json");
        const std::vector<SpeciesAssets> assets = loadSpeciesAssets(s, nullptr, true);
        const RenderScene rs = buildRenderScene(s, assets, sunRadiance(s.sun));
        const RenderView v = rs.view();
        const float cap = lb::kMaxLeafScattering / 4.0f;
        const glm::vec3 w = rs.species[0].leafIndirect;
        QVERIFY(w.y * 0.05f > cap);   // green: capped for any kd above 0.05
        int leaves = 0, cappedGreen = 0;
        for (int y = 0; y < v.height; ++y)
            for (int x = 0; x < v.width; ++x) {
                const Ray ray = cameraRay(v, float(x) + 0.5f, float(y) + 0.5f);
                Hit hit{};
                if (!intersectStage(v, ray, hit) || hitKind(hit) == SurfaceKind::Ground || hitKind(hit) == SurfaceKind::Terrain) continue;
                if (!v.materials[v.triMaterial[hit.prim]].isLeaf) continue;
                const SurfacePoint sp = surfaceStage(v, ray, hit);
                ++leaves;
                for (int c = 0; c < 3; ++c) {
                    const float want = std::min(sp.albedo[c] * w[c], cap);
                    QVERIFY2(std::fabs(sp.albedo[c] * sp.indirectWeight[c] - want) <= 1e-5f * std::max(want, 1e-3f),
                             qPrintable(QString("pixel %1,%2 channel %3: kd %4 x weight %5, want %6").arg(x).arg(y).arg(c).arg(sp.albedo[c]).arg(sp.indirectWeight[c]).arg(want)));
                }
                if (sp.albedo.y * w.y > cap) ++cappedGreen;
                const SampleParts parts = lightStage(v, sp, x, y, 0);
                const glm::vec3 expect = sp.albedo * sp.lighting * sp.indirectWeight * lbLight(v).radiance * v.indirectScale;
                for (int c = 0; c < 3; ++c) QVERIFY(std::fabs(parts.indirect[c] - expect[c]) <= 1e-5f * std::max(expect[c], 1e-3f));
            }
        QVERIFY2(leaves > 20 && cappedGreen > leaves / 2, qPrintable(QString("%1 leaf hits, %2 capped in green").arg(leaves).arg(cappedGreen)));
    }

    void truthPartSkipsWithQuick()
    {
        QTemporaryDir tmp;
        Options o;
        o.parts = {Part::Truth};
        o.quick = true;
        o.outDir = tmp.path().toStdString();
        std::vector<std::string> lines;
        o.log = [&](const std::string& l) { lines.push_back(l); };
        const Result r = run(o);
        QVERIFY(!std::filesystem::exists(o.outDir + "/accuracy/truth.md"));
        QVERIFY(readText(r.markdown).find("Not measured yet: `sylva study truth`") != std::string::npos);
        bool said = false;
        for (const std::string& l : lines) said = said || l.find("truth: skipped") != std::string::npos;
        QVERIFY(said);
    }
};

QTEST_GUILESS_MAIN(TestTruth)
#include "tst_truth.moc"
