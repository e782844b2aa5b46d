// Geometry and rendering at the extremes: degenerate, tiny (1e-6 m) and huge (1e5 m)
// meshes through voxelize + light + render; scenes 1e5-1e7 m from the origin drawing the same picture
// without acne or speckled shadows; a camera almost touching a leaf; 1x1 images, spp 1 to 4096.
#include <QDir>
#include <QElapsedTimer>
#include <QFile>
#include <sys/resource.h>
#include <QTest>

#include <cmath>
#include <cstring>
#include <numeric>

#include "core/base/error.h"
#include "core/lb/lb_solver.h"
#include "core/render/render_cpu.h"
#include "core/render/render_scene.h"
#include "core/render/shade.h"
#include "core/render/tonemap.h"
#include "core/voxel/voxelize.h"
#include "pipeline/cache/grid_cache.h"
#include "pipeline/grow/obj_writer.h"
#include "pipeline/lighting_job.h"
#include "pipeline/render/frame_build.h"
#include "pipeline/render/render_job.h"
#include "tests/common/files.h"

using namespace sylva;

namespace {

// A wooden "table": a horizontal top (2 x 2, at height 1) on one vertical wall (the "leg", 2 wide,
// facing -z) plus a small upright card in front; opaque, one material. Scaled by s (metres). The
// coordinates are binary fractions, so the 1e5 m copy is exact and the 1e-6 m one within an ulp: the
// grid sizing (a ceil of extent ratios) and the sub-cell marking see the same mesh at every scale.
TriangleMesh tableMesh(float s)
{
    TriangleMesh m;
    const glm::vec3 quads[3][4] = {
        {{-1, 1, -1}, {1, 1, -1}, {1, 1, 1}, {-1, 1, 1}},             // top
        {{-1, 0, 0.5f}, {1, 0, 0.5f}, {1, 1, 0.5f}, {-1, 1, 0.5f}},   // wall under the top
        {{-0.25f, 0, -1.75f}, {0.25f, 0, -1.75f}, {0.25f, 0.625f, -1.75f}, {-0.25f, 0.625f, -1.75f}},   // card in front
    };
    for (const auto& q : quads) {
        const uint32_t b = uint32_t(m.positions.size());
        for (const glm::vec3& p : q) m.positions.push_back(p * s);
        m.triangles.emplace_back(b, b + 1, b + 2);
        m.triangles.emplace_back(b, b + 2, b + 3);
    }
    m.triangleMaterial.assign(m.triangles.size(), 0);
    m.materials.resize(1);
    m.materials[0].name = "wood";
    m.materials[0].diffuse = glm::vec3(0.6f, 0.5f, 0.4f);
    return m;
}

// One species from `mesh` (leaf optics, grid 16), one instance at `shift`, ground at shift.y, a
// camera looking at the table from the front, everything scaled by s.
Scene tableScene(float s, const glm::dvec3& shift = glm::dvec3(0.0))
{
    Scene sc;
    sc.species.resize(1);
    sc.species[0].name = "table";
    sc.species[0].lighting = lb::paramsFromPreset(*lb::findPreset("leaf"));
    sc.species[0].grid = 16;
    InstanceDesc in;
    in.position = shift;
    sc.instances = {in};
    sc.ground.enabled = true;
    sc.ground.height = shift.y;
    sc.sun.direction = sunDirection(35.0, 30.0);   // shadows fall toward the camera
    sc.camera.position = shift + glm::dvec3(1.2, 2.6, -5.5) * double(s);
    sc.camera.target = shift + glm::dvec3(0.0, 0.4, 0.0) * double(s);
    sc.render.width = 64;
    sc.render.height = 48;
    sc.render.spp = 1;
    return sc;
}

struct Frame {
    Film film;
    std::vector<glm::vec3> linear;
    std::vector<int> what;   // per pixel (centre ray): 0 sky, 1 ground, 2 mesh
};

// The frame through the library: voxelize (grid 16) + light (when the mode needs it) + build + trace.
Frame renderDirect(const TriangleMesh& mesh, const Scene& scene)
{
    SpeciesAssets a;
    a.mesh = mesh;
    if (modeNeedsLighting(scene.render.mode)) {
        VoxelizeSettings vs;
        vs.longestAxisNodes = scene.species[0].grid;
        const DensityGrid d = voxelize(mesh, vs);
        lb::LbParams p = scene.species[0].lighting;
        p.sun = scene.sun.direction;
        a.lighting = lightingFor(d, p, nullptr);
        const std::vector<float> bc = lb::boundaryDistribution(p.sun);
        a.lightingNorm = p.intensity * std::accumulate(bc.begin(), bc.end(), 0.0f);
    }
    const std::vector<SpeciesAssets> assets{a};
    const RenderScene rs = buildRenderScene(scene, assets, sunRadiance(scene.sun));
    const RenderView v = rs.view();
    Frame f;
    f.film = renderFilm(v);
    f.linear = composeMode(f.film, scene.render.mode, scene.sky);
    f.what.resize(size_t(v.width) * size_t(v.height));
    for (int y = 0; y < v.height; ++y)
        for (int x = 0; x < v.width; ++x) {
            Hit h{};
            const bool hit = traceScene<false>(v, cameraRay(v, float(x) + 0.5f, float(y) + 0.5f), h);
            f.what[size_t(y) * size_t(v.width) + size_t(x)] = !hit ? 0 : (hitKind(h) == SurfaceKind::Ground ? 1 : 2);
        }
    return f;
}

bool allFinite(const std::vector<glm::vec3>& img)
{
    for (const glm::vec3& c : img)
        if (!std::isfinite(c.x) || !std::isfinite(c.y) || !std::isfinite(c.z) || c.x < 0.0f || c.y < 0.0f || c.z < 0.0f) return false;
    return true;
}

// MemAvailable (bytes, 0 when unknown) and this process's peak resident memory (bytes).
double availableMemory()
{
    QFile f("/proc/meminfo");
    if (!f.open(QIODevice::ReadOnly)) return 0.0;
    for (const QByteArray& line : f.readAll().split('\n'))
        if (line.startsWith("MemAvailable:")) return line.mid(13).trimmed().split(' ').value(0).toDouble() * 1024.0;
    return 0.0;
}
double peakRss()
{
    rusage u{};
    getrusage(RUSAGE_SELF, &u);
    return double(u.ru_maxrss) * 1024.0;
}

int count(const std::vector<int>& what, int value) { return int(std::count(what.begin(), what.end(), value)); }

// Pixels of a and b differing by more than tol (absolute, any channel).
int differing(const std::vector<glm::vec3>& a, const std::vector<glm::vec3>& b, float tol)
{
    int n = 0;
    for (size_t i = 0; i < a.size(); ++i)
        if (glm::any(glm::greaterThan(glm::abs(a[i] - b[i]), glm::vec3(tol)))) ++n;
    return n;
}

// Speckles on the ground: a shadowed ground pixel all of whose 8 neighbours are sunlit ground (acne
// or a missed shadow hit), or a sunlit one all of whose neighbours are shadowed ground (a leak).
// Lit / shadowed: local (sun) luminance above / below half the brightest ground pixel's.
struct Speckles {
    int darkInLight = 0, lightInDark = 0, shadowed = 0, lit = 0;
};
Speckles groundSpeckles(const Frame& f, int w, int h)
{
    float brightest = 0.0f;
    for (size_t i = 0; i < f.what.size(); ++i)
        if (f.what[i] == 1) brightest = std::max(brightest, luminance(f.film.pixels[i].local));
    auto state = [&](int x, int y) {   // -1 not ground, 0 shadowed, 1 lit
        const size_t i = size_t(y) * size_t(w) + size_t(x);
        if (f.what[i] != 1) return -1;
        return luminance(f.film.pixels[i].local) > 0.5f * brightest ? 1 : 0;
    };
    Speckles s;
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            const int c = state(x, y);
            if (c < 0) continue;
            (c ? s.lit : s.shadowed)++;
            if (x == 0 || y == 0 || x == w - 1 || y == h - 1) continue;
            bool allOther = true;
            for (int dy = -1; dy <= 1; ++dy)
                for (int dx = -1; dx <= 1; ++dx)
                    if ((dx || dy) && state(x + dx, y + dy) != 1 - c) allOther = false;
            if (allOther) (c ? s.lightInDark : s.darkInLight)++;
        }
    return s;
}

QString speckleText(const Speckles& s)
{
    return QString("%1 lit and %2 shadowed ground pixels; %3 isolated dark, %4 isolated lit")
        .arg(s.lit).arg(s.shadowed).arg(s.darkInLight).arg(s.lightInDark);
}

} // namespace

class TestGeometryExtremes : public QObject {
    Q_OBJECT

    QString m_dir;

    // Writes mesh as an OBJ under the test folder and returns a scene species reading it.
    std::string writeMesh(const TriangleMesh& mesh, const QString& name)
    {
        const std::string path = (m_dir + "/" + name + ".obj").toStdString();
        writeObj(path, mesh);
        return path;
    }

private Q_SLOTS:
    void initTestCase()
    {
        m_dir = test::outputDir("geometry_extremes");
    }

    // Zero-area triangles (repeated corners, collinear corners) next to one real triangle: the
    // degenerate ones mark what they touch in the density but are never hit; the real one covers
    // about its projected area. A mesh of nothing but degenerate triangles voxelizes, lights and
    // renders an image of ground and sky; one whose vertices all coincide is refused with a message.
    void degenerateMeshes()
    {
        TriangleMesh one;
        one.positions = {{-1, 0.2f, 0}, {1, 0.2f, 0}, {0, 1.8f, 0.3f}};
        one.triangles = {{0, 1, 2}};
        TriangleMesh withDegenerate = one;
        const uint32_t b = 3;
        withDegenerate.positions.insert(withDegenerate.positions.end(),
                                        {{-1, 0.5f, -1}, {0, 1, -0.5f}, {1, 1.5f, 0}, {0.5f, 0.3f, 0.5f}, {0.5f, 0.3f, 0.5f}});
        withDegenerate.triangles.push_back({b, b + 1, b + 2});       // collinear corners
        withDegenerate.triangles.push_back({b + 3, b + 4, b + 1});   // two coinciding corners
        withDegenerate.triangles.push_back({b + 1, b + 1, b + 1});   // one point three times
        TriangleMesh onlyDegenerate;
        onlyDegenerate.positions = {{-1, 0.5f, -1}, {0, 1, -0.5f}, {1, 1.5f, 0}, {0.5f, 0.3f, 0.5f}};
        onlyDegenerate.triangles = {{0, 1, 2}, {3, 3, 1}, {2, 2, 2}};

        Scene s = tableScene(1.0f);
        s.camera.position = {0.0, 1.0, -4.0};
        s.camera.target = {0.0, 1.0, 0.0};
        // Pixels whose centre falls inside the triangle's projection, for the coverage check.
        const CameraRecord cam = makeCamera(s.camera, s.render.width, s.render.height);
        auto project = [&](glm::vec3 p) {
            const glm::vec3 r = p - glm::vec3(s.camera.position);
            const float z = glm::dot(r, cam.forward);
            const float sx = glm::dot(r, cam.right) / z / cam.tanHalfX, sy = glm::dot(r, cam.up) / z / cam.tanHalfY;
            return glm::vec2((sx + 1.0f) * 0.5f * float(s.render.width), (1.0f - sy) * 0.5f * float(s.render.height));
        };
        const glm::vec2 a = project(one.positions[0]), bb = project(one.positions[1]), c = project(one.positions[2]);
        const float area = 0.5f * std::fabs((bb.x - a.x) * (c.y - a.y) - (c.x - a.x) * (bb.y - a.y));
        const float perimeter = glm::length(bb - a) + glm::length(c - bb) + glm::length(a - c);

        for (RenderMode mode : {RenderMode::Full, RenderMode::Local}) {
            s.render.mode = mode;
            const Frame f1 = renderDirect(one, s), f2 = renderDirect(withDegenerate, s);
            QVERIFY(allFinite(f1.linear) && allFinite(f2.linear));
            const int covered = count(f1.what, 2);
            qInfo("single triangle (%s): %d pixels hit, projected area %.1f, perimeter %.1f", renderModeName(mode), covered, double(area),
                  double(perimeter));
            QVERIFY2(std::fabs(float(covered) - area) <= perimeter, qPrintable(QString("%1 pixels for area %2").arg(covered).arg(double(area))));
            QCOMPARE(f2.what, f1.what);   // degenerate triangles are never hit
            const Frame f3 = renderDirect(onlyDegenerate, s);
            QVERIFY(allFinite(f3.linear));
            QCOMPARE(count(f3.what, 2), 0);
            QVERIFY(count(f3.what, 1) > 0 && count(f3.what, 0) > 0);
        }
        // Their density marks what they touch (docs/LB_MODEL.md "Voxelization").
        VoxelizeSettings vs;
        vs.longestAxisNodes = 16;
        const DensityGrid d = voxelize(onlyDegenerate, vs);
        QVERIFY(std::any_of(d.density.begin(), d.density.end(), [](float r) { return r > 0.0f; }));

        TriangleMesh point;
        point.positions = {{0.3f, 0.3f, 0.3f}};
        point.triangles = {{0, 0, 0}, {0, 0, 0}};
        try {
            voxelize(point, vs);
            QFAIL("a mesh of one point was voxelized");
        } catch (const Error& e) {
            QVERIFY2(QString(e.what()).contains("zero extent"), e.what());
        }

        // Through the whole pipeline (OBJ import, cache, voxelize, light, render): the import drops the
        // degenerate triangles; a file of nothing but degenerate ones is an error naming it.
        GridCache cache((m_dir + "/cache").toStdString());
        s.render.mode = RenderMode::Full;
        s.species[0].meshPath = writeMesh(withDegenerate, "with_degenerate");
        JobLog log;
        const RenderOutput out = renderScene(s, &cache, nullptr, &log);
        QVERIFY(allFinite(composeMode(out.film, RenderMode::Full, s.sky)));
        s.species[0].meshPath = writeMesh(onlyDegenerate, "only_degenerate");
        try {
            renderScene(s, &cache);
            QFAIL("a mesh of only degenerate triangles rendered");
        } catch (const Error& e) {
            QVERIFY2(QString(e.what()).contains("only_degenerate.obj"), e.what());
        }
    }

    // The same table at 1e-6 m, 1 m and 1e5 m (mesh, camera and grid scaled together) through the
    // whole pipeline draws the same picture in every mode: no missed hits, no lost or extra shadows.
    void tinyAndHugeMeshes()
    {
        GridCache cache((m_dir + "/cache").toStdString());
        std::vector<glm::vec3> reference[2];
        const RenderMode modes[2] = {RenderMode::Full, RenderMode::Local};
        for (float s : {1.0f, 1e-6f, 1e5f}) {
            Scene sc = tableScene(s);
            sc.species[0].meshPath = writeMesh(tableMesh(s), QString("table_%1").arg(double(s)));
            for (int m = 0; m < 2; ++m) {
                sc.render.mode = modes[m];
                JobLog log;
                const RenderOutput out = renderScene(sc, &cache, nullptr, &log);
                const std::vector<glm::vec3> img = composeMode(out.film, sc.render.mode, sc.sky);
                QVERIFY(allFinite(img));
                if (s == 1.0f) {
                    reference[m] = img;
                    continue;
                }
                const int diff = differing(img, reference[m], 0.02f);
                qInfo("scale %g, %s: %d of %zu pixels differ from scale 1", double(s), renderModeName(modes[m]), diff, img.size());
                QVERIFY2(diff <= int(img.size()) / 200, qPrintable(QString("scale %1 %2: %3 pixels differ").arg(double(s)).arg(renderModeName(modes[m])).arg(diff)));
            }
        }
        // The same with speckle counts on the ground (library path, local mode).
        for (float s : {1e-6f, 1.0f, 1e5f}) {
            Scene sc = tableScene(s);
            sc.render.mode = RenderMode::Local;
            sc.render.width = 96;
            sc.render.height = 64;
            const Frame f = renderDirect(tableMesh(s), sc);
            const Speckles sp = groundSpeckles(f, 96, 64);
            qInfo("scale %g: %s", double(s), qPrintable(speckleText(sp)));
            QVERIFY2(sp.shadowed > 100 && sp.lit > 100, qPrintable(speckleText(sp)));
            QVERIFY2(sp.darkInLight == 0 && sp.lightInDark == 0, qPrintable(speckleText(sp)));
        }
    }

    // The scene and its camera moved 1e5, 1e6 and 1e7 m (along x and z, and along all three axes with
    // the ground): the picture stays the same pixel by pixel (camera-relative coordinates keep the
    // precision), without self-shadowing acne on the lit faces or speckled shadows on the ground.
    void farFromOrigin()
    {
        auto frameAt = [&](const glm::dvec3& shift) {
            Scene sc = tableScene(1.0f, shift);
            sc.render.mode = RenderMode::Local;
            sc.render.width = 96;
            sc.render.height = 64;
            sc.instances[0].rotationDeg = {0.0f, 30.0f, 0.0f};
            sc.instances[0].scale = 1.3f;
            return renderDirect(tableMesh(1.0f), sc);
        };
        const Frame ref = frameAt(glm::dvec3(0.0));
        const Speckles refSp = groundSpeckles(ref, 96, 64);
        QVERIFY2(refSp.shadowed > 100 && refSp.lit > 100 && refSp.darkInLight == 0 && refSp.lightInDark == 0, qPrintable(speckleText(refSp)));
        for (double d : {1e5, 1e6, 1e7})
            for (const glm::dvec3& dir : {glm::dvec3(1.0, 0.0, -1.0), glm::dvec3(1.0, 1.0, 1.0)}) {
                const Frame f = frameAt(d * dir);
                QVERIFY(allFinite(f.linear));
                const int whatDiffers = int(std::inner_product(f.what.begin(), f.what.end(), ref.what.begin(), 0, std::plus<>(),
                                                               [](int a, int b) { return a != b ? 1 : 0; }));
                const int diff = differing(f.linear, ref.linear, 0.01f);
                const Speckles sp = groundSpeckles(f, 96, 64);
                qInfo("shift %g x (%g,%g,%g): %d pixels see something else, %d differ; %s", d, dir.x, dir.y, dir.z, whatDiffers, diff,
                      qPrintable(speckleText(sp)));
                QVERIFY2(whatDiffers <= 2, qPrintable(QString("%1 pixels see another surface at %2 m").arg(whatDiffers).arg(d)));
                QVERIFY2(diff <= int(f.linear.size()) / 500, qPrintable(QString("%1 pixels differ at %2 m").arg(diff).arg(d)));
                QVERIFY2(sp.darkInLight == 0 && sp.lightInDark == 0, qPrintable(speckleText(sp)));
                QVERIFY2(std::abs(sp.shadowed - refSp.shadowed) <= 3, qPrintable(speckleText(sp)));
            }
    }

    // A camera 1e-4 and 1e-6 m in front of a tilted leaf (inside its lighting grid, a metre from the
    // species origin): the leaf fills the view, every pixel is finite and sunlit (the shadow ray's
    // offset must cover the rounding of the metre-sized coordinates the hit came from, not just of the
    // micrometre to the eye), the picture is deterministic.
    void cameraVeryCloseToLeaf()
    {
        // A 10 cm leaf around c = (0.3, 1.05, 0.2), normal n tilted off every axis.
        const glm::vec3 c(0.3f, 1.05f, 0.2f), n = glm::normalize(glm::vec3(0.3f, 0.4f, -1.0f));
        const glm::vec3 u = glm::normalize(glm::cross(n, glm::vec3(0.0f, 1.0f, 0.0f))), w = glm::cross(n, u);
        TriangleMesh leaf;
        leaf.positions = {c - 0.05f * u - 0.05f * w, c + 0.05f * u - 0.05f * w, c + 0.05f * u + 0.05f * w, c - 0.05f * u + 0.05f * w};
        leaf.triangles = {{0, 1, 2}, {0, 2, 3}};
        leaf.triangleMaterial = {0, 0};
        leaf.materials.resize(1);
        leaf.materials[0].isLeaf = true;
        leaf.materials[0].diffuse = glm::vec3(0.2f, 0.6f, 0.1f);
        for (double dist : {1e-4, 1e-6}) {
            Scene sc = tableScene(1.0f);
            sc.camera.position = glm::dvec3(c) + dist * glm::dvec3(n);
            sc.camera.target = glm::dvec3(c) - glm::dvec3(n);
            sc.sun.direction = glm::normalize(n + glm::vec3(0.3f, 0.2f, 0.0f));   // on the camera's side of the leaf
            sc.render.mode = RenderMode::Full;
            const Frame f = renderDirect(leaf, sc), again = renderDirect(leaf, sc);
            QVERIFY(allFinite(f.linear));
            QCOMPARE(count(f.what, 2), int(f.what.size()));
            QVERIFY(std::memcmp(f.linear.data(), again.linear.data(), f.linear.size() * sizeof(glm::vec3)) == 0);
            // The leaf faces the sun and nothing is in the way: every pixel sunlit (no self-shadowing acne).
            int dark = 0;
            for (const SampleParts& px : f.film.pixels) dark += luminance(px.local) > 0.0f ? 0 : 1;
            QVERIFY2(dark == 0, qPrintable(QString("%1 of %2 pixels of a sunlit leaf seen from %3 m are in shadow").arg(dark).arg(f.film.pixels.size()).arg(dist)));
        }
    }

    // 1x1 images at spp 1, 2, 3, 16; a 2x2 image at spp 1, 2, 3, 16 and 4096: finite, deterministic
    // (two runs bit-identical), and more samples converge (4096 against 1024 within 1%).
    void imageSizeAndSamples()
    {
        GridCache cache((m_dir + "/cache").toStdString());
        Scene sc = tableScene(1.0f);
        sc.species[0].meshPath = writeMesh(tableMesh(1.0f), "table_spp");
        sc.render.mode = RenderMode::Full;
        for (int size : {1, 2})
            for (int spp : {1, 2, 3, 16, 1024, 4096}) {
                if (size == 1 && spp > 16) continue;
                sc.render.width = size;
                sc.render.height = size;
                sc.render.spp = spp;
                const auto a = composeMode(renderScene(sc, &cache).film, sc.render.mode, sc.sky);
                const auto b = composeMode(renderScene(sc, &cache).film, sc.render.mode, sc.sky);
                QCOMPARE(a.size(), size_t(size * size));
                QVERIFY(allFinite(a));
                QVERIFY2(std::memcmp(a.data(), b.data(), a.size() * sizeof(glm::vec3)) == 0,
                         qPrintable(QString("%1x%1 at %2 spp is not deterministic").arg(size).arg(spp)));
            }
        auto at = [&](int spp) {
            sc.render.spp = spp;
            return composeMode(renderScene(sc, &cache).film, sc.render.mode, sc.sky);
        };
        const auto s1024 = at(1024), s4096 = at(4096);
        for (size_t i = 0; i < s1024.size(); ++i)
            QVERIFY2(glm::all(glm::lessThanEqual(glm::abs(s4096[i] - s1024[i]), 0.01f * glm::max(s4096[i], glm::vec3(0.05f)))),
                     qPrintable(QString("pixel %1: %2 at 4096 spp, %3 at 1024").arg(i).arg(double(luminance(s4096[i]))).arg(double(luminance(s1024[i])))));
    }
    // Very large frames. 16384 x 8192 at 1 spp of a small scene renders when memory allows: every pixel
    // finite, the table where the 256 x 128 render puts it, and no more memory than the film and the
    // composed picture (kFrameBytesPerPixel, ~7 GB here; the frame is traced in 8 x 8 tiles into the
    // film). A frame too large for the machine (32768 x 32768 needs ~56 GB) is refused before any work
    // with a message naming the memory, not killed by the out-of-memory killer halfway.
    void veryLargeImages()
    {
        GridCache cache((m_dir + "/cache").toStdString());
        Scene sc = tableScene(1.0f);
        sc.species[0].meshPath = writeMesh(tableMesh(1.0f), "table_big");
        sc.render.width = 32768;
        sc.render.height = 32768;
        const double available = availableMemory();
        if (available > 0.0 && double(kFrameBytesPerPixel) * 32768.0 * 32768.0 > 0.8 * available) {
            JobLog log;
            try {
                renderScene(sc, &cache, nullptr, &log);
                QFAIL("a 32768x32768 frame was not refused");
            } catch (const Error& e) {
                QVERIFY2(QString(e.what()).contains("32768x32768") && QString(e.what()).contains("GB"), e.what());
            }
            QVERIFY2(log.stages.empty(), "work was done before the refusal");
        }

        const int w = 16384, h = 8192;
        const double frameBytes = double(kFrameBytesPerPixel) * w * h;
        if (!(available > frameBytes / 0.8 + 2e9))
            QSKIP(qPrintable(QString("%1x%2 needs %3 GB; %4 GB available").arg(w).arg(h).arg(frameBytes / 1e9).arg(available / 1e9)));
        sc.render.width = 256;
        sc.render.height = 128;
        const auto small = composeMode(renderScene(sc, &cache).film, sc.render.mode, sc.sky);
        sc.render.width = w;
        sc.render.height = h;
        const double before = peakRss();
        QElapsedTimer t;
        t.start();
        std::vector<glm::vec3> big;
        {
            const RenderOutput out = renderScene(sc, &cache);
            QCOMPARE(out.film.pixels.size(), size_t(w) * size_t(h));
            big = composeMode(out.film, sc.render.mode, sc.sky);
        }
        const double grew = peakRss() - before;
        qInfo("%dx%d at 1 spp: %lld ms, peak memory grew %.2f GB (film + picture %.2f GB)", w, h, t.elapsed(), grew / 1e9, frameBytes / 1e9);
        QVERIFY2(grew <= 1.1 * frameBytes + 3e8, qPrintable(QString("peak memory grew %1 GB").arg(grew / 1e9)));
        QVERIFY(allFinite(big));
        // Every 64th pixel of the big frame against the small one's pixel at the same place: the same
        // surfaces (a small share may differ where a small pixel straddles an edge).
        int differ = 0;
        for (int y = 0; y < 128; ++y)
            for (int x = 0; x < 256; ++x) {
                const glm::vec3 a = small[size_t(y) * 256 + size_t(x)], b = big[size_t(y * 64 + 32) * size_t(w) + size_t(x * 64 + 32)];
                if (glm::any(glm::greaterThan(glm::abs(a - b), glm::vec3(0.05f)))) ++differ;
            }
        QVERIFY2(differ <= 256 * 128 / 20, qPrintable(QString("%1 of %2 sampled pixels differ").arg(differ).arg(256 * 128)));
    }
};

QTEST_GUILESS_MAIN(TestGeometryExtremes)
#include "tst_geometry_extremes.moc"
