// Render passes: `sylva render --passes` and exportRender write one multi-layer EXR
// whose layers carry Cycles' names; Combined is the documented composition of the others; the depth
// and normal of a known plane (a tilted quad and the ground) against the ray-plane intersection
// computed here from the pinhole camera.
#include <QDir>
#include <QProcess>
#include <QTemporaryDir>
#include <QTest>

#include <cmath>
#include <map>
#include <numeric>

#include <OpenImageIO/imageio.h>

#include "core/base/error.h"
#include "core/lb/lb_solver.h"
#include "core/render/render_cpu.h"
#include "core/render/render_scene.h"
#include "core/voxel/voxelize.h"
#include "pipeline/grow/obj_writer.h"
#include "pipeline/lighting_job.h"
#include "pipeline/render/frame_build.h"
#include "pipeline/render/render_job.h"
#include "pipeline/render/render_passes.h"
#include "pipeline/scene/scene_file.h"
#include "pipeline/services/exports.h"
#include "tests/common/run_program.h"

using namespace sylva;

namespace {

// The quad's plane: through kCentre with unit normal kNormal (facing the camera, which looks along +z).
const glm::vec3 kCentre(0.0f, 1.5f, 1.0f);
const glm::vec3 kNormal = glm::normalize(glm::vec3(0.4f, 0.3f, -1.0f));
const glm::vec3 kQuadColour(0.2f, 0.7f, 0.4f);
constexpr float kHalf = 1.5f;   // half the quad's side

glm::vec3 quadU() { return glm::normalize(glm::cross(kNormal, glm::vec3(0.0f, 1.0f, 0.0f))); }
glm::vec3 quadW() { return glm::cross(quadU(), kNormal); }

// A square of side 2 kHalf on the plane, two triangles, normals = the plane's, a shiny leaf material.
TriangleMesh quadMesh()
{
    TriangleMesh m;
    const glm::vec3 u = quadU(), w = quadW();
    for (auto [a, b] : {std::pair{-1.0f, -1.0f}, std::pair{1.0f, -1.0f}, std::pair{1.0f, 1.0f}, std::pair{-1.0f, 1.0f}}) {
        m.positions.push_back(kCentre + kHalf * (a * u + b * w));
        m.normals.push_back(kNormal);
    }
    m.triangles = {{0, 1, 2}, {0, 2, 3}};
    m.triangleMaterial = {0, 0};
    m.materials.resize(1);
    m.materials[0].name = "card";
    m.materials[0].isLeaf = true;
    m.materials[0].diffuse = kQuadColour;
    m.materials[0].specular = glm::vec3(0.3f);
    m.materials[0].shininess = 20.0f;
    return m;
}

Scene quadScene(int spp)
{
    Scene sc;
    sc.species.resize(1);
    sc.species[0].name = "card";
    sc.species[0].lighting = lb::paramsFromPreset(*lb::findPreset("leaf"));
    sc.species[0].grid = 16;
    sc.instances = {InstanceDesc{}};
    sc.ground.enabled = true;
    sc.ground.height = 0.0;
    sc.sun.direction = sunDirection(45.0, 30.0);
    sc.camera.position = glm::dvec3(0.3, 1.5, -4.0);
    sc.camera.target = glm::dvec3(0.3, 1.5, 1.0);
    sc.camera.fovY = 50.0f;
    sc.render.width = 64;
    sc.render.height = 48;
    sc.render.spp = spp;
    return sc;
}

std::vector<SpeciesAssets> quadAssets(const Scene& sc, bool lit)
{
    SpeciesAssets a;
    a.mesh = quadMesh();
    if (lit) {
        VoxelizeSettings vs;
        vs.longestAxisNodes = sc.species[0].grid;
        const DensityGrid d = voxelize(a.mesh, vs);
        lb::LbParams p = sc.species[0].lighting;
        p.sun = sc.sun.direction;
        a.lighting = lightingFor(d, p, nullptr);
        const std::vector<float> bc = lb::boundaryDistribution(p.sun);
        a.lightingNorm = p.intensity * std::accumulate(bc.begin(), bc.end(), 0.0f);
    }
    return {a};
}

Film renderQuad(const Scene& sc, bool lit)
{
    const std::vector<SpeciesAssets> assets = quadAssets(sc, lit);
    const RenderScene rs = buildRenderScene(sc, assets, sunRadiance(sc.sun));
    return renderFilm(rs.view());
}

// The EXR's channels by name (every channel of the file), as OpenImageIO reads them.
struct ExrChannels {
    int width = 0, height = 0;
    std::map<std::string, std::vector<float>> channels;
    const std::vector<float>& operator[](const std::string& name) const { return channels.at(name); }
};

ExrChannels readExr(const QString& path)
{
    ExrChannels out;
    auto in = OIIO::ImageInput::open(path.toStdString());
    if (!in) return out;
    const OIIO::ImageSpec spec = in->spec();
    out.width = spec.width;
    out.height = spec.height;
    std::vector<float> data(size_t(spec.width) * size_t(spec.height) * size_t(spec.nchannels));
    if (!in->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::FLOAT, data.data())) return out;
    for (int c = 0; c < spec.nchannels; ++c) {
        std::vector<float>& ch = out.channels[spec.channelnames[size_t(c)]];
        ch.resize(size_t(spec.width) * size_t(spec.height));
        for (size_t p = 0; p < ch.size(); ++p) ch[p] = data[p * size_t(spec.nchannels) + size_t(c)];
    }
    return out;
}

const std::vector<std::string> kExpectedChannels = {"Combined.R", "Combined.G", "Combined.B", "DiffDir.R", "DiffDir.G",
                                                    "DiffDir.B",  "DiffInd.R",  "DiffInd.G",  "DiffInd.B", "DiffCol.R",
                                                    "DiffCol.G",  "DiffCol.B",  "Env.R",      "Env.G",     "Env.B",
                                                    "Normal.X",   "Normal.Y",   "Normal.Z",   "Depth.Z",   "Alpha.A"};

// The Cryptomatte layers `--passes` and exportRender add (tst_cryptomatte checks what they hold): three
// types of 6 ranks, 3 RGBA layers each.
std::vector<std::string> cryptomatteChannels()
{
    std::vector<std::string> out;
    for (const char* type : {"CryptoObject", "CryptoMaterial", "CryptoAsset"})
        for (const char* layer : {"00", "01", "02"})
            for (const char* c : {".R", ".G", ".B", ".A"}) out.push_back(std::string(type) + layer + c);
    return out;
}

QString channelList(const ExrChannels& e)
{
    QStringList names;
    for (const auto& [name, values] : e.channels) names << QString::fromStdString(name);
    return names.join(' ');
}

// Checks, per pixel and channel of the file: Combined = DiffCol x (DiffDir + DiffInd) + Env to float
// rounding, and Env = (1 - Alpha) x sky. Returns the pixels with a non-zero direct and indirect term.
void checkComposition(const ExrChannels& e, const glm::vec3& sky, int* withDirect, int* withIndirect)
{
    const char* rgb[3] = {"R", "G", "B"};
    *withDirect = *withIndirect = 0;
    const size_t n = size_t(e.width) * size_t(e.height);
    for (size_t p = 0; p < n; ++p) {
        bool direct = false, indirect = false;
        for (int c = 0; c < 3; ++c) {
            const std::string k = rgb[c];
            const double col = e["DiffCol." + k][p], dir = e["DiffDir." + k][p], ind = e["DiffInd." + k][p];
            const double env = e["Env." + k][p], combined = e["Combined." + k][p];
            const double want = col * (dir + ind) + env;
            const double scale = std::abs(col * dir) + std::abs(col * ind) + std::abs(env);
            if (std::abs(combined - want) > 4e-7 * scale + 1e-30)
                QFAIL(qPrintable(QString("pixel %1 channel %2: Combined %3, DiffCol x (DiffDir + DiffInd) + Env = %4")
                                     .arg(p).arg(rgb[c]).arg(combined, 0, 'g', 9).arg(want, 0, 'g', 9)));
            const double alpha = e["Alpha.A"][p];
            QVERIFY(std::abs(env - (1.0 - alpha) * double(sky[c])) <= 1e-6 * double(sky[c]));
            direct |= col * dir > 0.0;
            indirect |= col * ind > 0.0;
        }
        *withDirect += direct ? 1 : 0;
        *withIndirect += indirect ? 1 : 0;
    }
}

test::Run runCli(const QStringList& args)
{
    return test::runProgram(SYLVA_CLI_PATH, args, QProcessEnvironment::systemEnvironment(), 300000);
}

} // namespace

class TestRenderPasses : public QObject {
    Q_OBJECT

    QTemporaryDir m_dir;

private Q_SLOTS:
    // Every layer in the file with its name; Combined is the mode's picture and the composition of the
    // other layers, in every mode, at 4 samples per pixel (edge pixels mix surfaces and sky).
    void layersAndComposition()
    {
        QVERIFY(m_dir.isValid());
        const Scene sc = quadScene(4);
        const std::vector<SpeciesAssets> assets = quadAssets(sc, true);
        const RenderScene rs = buildRenderScene(sc, assets, sunRadiance(sc.sun));
        const Film film = renderFilm(rs.view());
        for (RenderMode mode : {RenderMode::Full, RenderMode::Local, RenderMode::Ambient, RenderMode::Lb}) {
            const QString path = m_dir.filePath(QString("passes_%1.exr").arg(renderModeName(mode)));
            writeRenderPasses(path.toStdString(), renderPasses(film, mode, sc.sky));
            const ExrChannels e = readExr(path);
            QCOMPARE(e.width, sc.render.width);
            QCOMPARE(e.height, sc.render.height);
            QVERIFY2(e.channels.size() == kExpectedChannels.size(), qPrintable(channelList(e)));
            for (const std::string& name : kExpectedChannels)
                QVERIFY2(e.channels.count(name) == 1, qPrintable(QString::fromStdString(name) + " missing: " + channelList(e)));
            // Combined holds the mode's linear picture exactly (32-bit float).
            const std::vector<glm::vec3> picture = composeMode(film, mode, sc.sky);
            for (size_t p = 0; p < picture.size(); ++p) {
                QCOMPARE(e["Combined.R"][p], picture[p].x);
                QCOMPARE(e["Combined.G"][p], picture[p].y);
                QCOMPARE(e["Combined.B"][p], picture[p].z);
            }
            int withDirect = 0, withIndirect = 0;
            checkComposition(e, sc.sky, &withDirect, &withIndirect);
            if (QTest::currentTestFailed()) return;
            // Not vacuous: the modes' parts are where they belong.
            const int pixels = sc.render.width * sc.render.height;
            if (mode == RenderMode::Lb) QCOMPARE(withDirect, 0);
            else QVERIFY2(withDirect > pixels / 10, qPrintable(QString::number(withDirect)));
            if (mode == RenderMode::Local) QCOMPARE(withIndirect, 0);
            else QVERIFY2(withIndirect > pixels / 4, qPrintable(QString::number(withIndirect)));
        }
    }

    // Depth and normal, one sample per pixel: the quad's and the ground's from the intersection of the
    // pixel's pinhole ray with their planes; the sky's depth is kSkyDepth and its normal 0.
    void depthAndNormalOfPlanes()
    {
        const Scene sc = quadScene(1);
        const Film film = renderQuad(sc, false);
        const RenderPasses passes = renderPasses(film, RenderMode::Local, sc.sky);
        const int w = sc.render.width, h = sc.render.height;
        // The pinhole camera of docs/SCENE.md: vertical field of view, square pixels, y down.
        const glm::vec3 eye(sc.camera.position);
        const glm::vec3 fwd = glm::normalize(glm::vec3(sc.camera.target) - eye);
        const glm::vec3 right = glm::normalize(glm::cross(fwd, sc.camera.up));
        const glm::vec3 up = glm::cross(right, fwd);
        const float tanY = std::tan(glm::radians(sc.camera.fovY) * 0.5f), tanX = tanY * float(w) / float(h);
        const glm::vec3 groundColour = sc.ground.color;
        int quad = 0, ground = 0, sky = 0, predictedQuad = 0;
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x) {
                const size_t p = size_t(y) * size_t(w) + size_t(x);
                const float sx = (2.0f * (float(x) + 0.5f) / float(w) - 1.0f) * tanX;
                const float sy = (1.0f - 2.0f * (float(y) + 0.5f) / float(h)) * tanY;
                const glm::vec3 d = glm::normalize(fwd + sx * right + sy * up);
                const float tQuad = glm::dot(kNormal, kCentre - eye) / glm::dot(kNormal, d);
                const glm::vec3 onQuad = eye + tQuad * d - kCentre;
                const float a = glm::dot(onQuad, quadU()) / kHalf, b = glm::dot(onQuad, quadW()) / kHalf;
                const float tGround = d.y < 0.0f ? -eye.y / d.y : INFINITY;
                // Pixels well inside the quad and in front of the ground: the analytic classification.
                const bool insideQuad = tQuad > 0.0f && std::abs(a) < 0.95f && std::abs(b) < 0.95f && tQuad < tGround;
                const glm::vec3 col = passes.diffCol[p];
                const glm::vec3 n = passes.normal[p];
                if (glm::length(col - kQuadColour) < 1e-6f) {
                    ++quad;
                    const float want = tQuad * glm::dot(d, fwd);
                    QVERIFY2(std::abs(passes.depth[p] - want) <= 2e-5f * want,
                             qPrintable(QString("quad pixel %1,%2: depth %3, plane %4").arg(x).arg(y).arg(passes.depth[p]).arg(want)));
                    QVERIFY2(glm::length(n - kNormal) < 1e-5f, qPrintable(QString("quad pixel %1,%2: normal %3 %4 %5").arg(x).arg(y).arg(n.x).arg(n.y).arg(n.z)));
                    QCOMPARE(passes.alpha[p], 1.0f);
                } else if (glm::length(col - groundColour) < 1e-6f) {
                    ++ground;
                    const float want = tGround * glm::dot(d, fwd);
                    QVERIFY2(std::abs(passes.depth[p] - want) <= 2e-5f * want,
                             qPrintable(QString("ground pixel %1,%2: depth %3, plane %4").arg(x).arg(y).arg(passes.depth[p]).arg(want)));
                    QVERIFY(glm::length(n - glm::vec3(0.0f, 1.0f, 0.0f)) < 1e-6f);
                    QVERIFY(!insideQuad);
                } else {
                    QCOMPARE(col, glm::vec3(0.0f));
                    ++sky;
                    QCOMPARE(passes.depth[p], kSkyDepth);
                    QCOMPARE(n, glm::vec3(0.0f));
                    QCOMPARE(passes.alpha[p], 0.0f);
                    QVERIFY(!insideQuad);
                    QVERIFY(d.y >= 0.0f);
                }
                predictedQuad += insideQuad ? 1 : 0;
            }
        const int pixels = w * h;
        QVERIFY2(quad > pixels / 5 && ground > pixels / 20 && sky > pixels / 20,
                 qPrintable(QString("quad %1, ground %2, sky %3 of %4").arg(quad).arg(ground).arg(sky).arg(pixels)));
        QVERIFY2(predictedQuad > quad * 3 / 4, qPrintable(QString("%1 predicted, %2 found").arg(predictedQuad).arg(quad)));
    }

    // Depth is the nearest sample's, normal the samples' mean: at 16 spp the quad's interior keeps the
    // plane's normal and its depth is at most the centre ray's.
    void samplesOfDepthAndNormal()
    {
        const Scene one = quadScene(1), many = quadScene(16);
        const RenderPasses a = renderPasses(renderQuad(one, false), RenderMode::Local, one.sky);
        const RenderPasses b = renderPasses(renderQuad(many, false), RenderMode::Local, many.sky);
        int interior = 0, edges = 0;
        for (size_t p = 0; p < a.depth.size(); ++p) {
            if (b.alpha[p] == 1.0f && glm::length(b.diffCol[p] - kQuadColour) < 1e-5f) {
                ++interior;
                QVERIFY(glm::length(b.normal[p] - kNormal) < 1e-5f);
                QVERIFY(b.depth[p] <= a.depth[p] * (1.0f + 1e-6f));
            } else if (b.alpha[p] > 0.0f && b.alpha[p] < 1.0f) {
                ++edges;
                QVERIFY(b.depth[p] < kSkyDepth);   // some sample hit: the nearest one counts
                QVERIFY(glm::length(b.normal[p]) < 1.0f);
            }
        }
        QVERIFY2(interior > 300 && edges > 5, qPrintable(QString("%1 interior, %2 edge pixels").arg(interior).arg(edges)));
    }

    // The studio's export service writes the same file; a passes export to another extension is refused.
    void exportService()
    {
        const Scene sc = quadScene(1);
        const std::vector<SpeciesAssets> assets = quadAssets(sc, false);
        Scene local = sc;
        local.render.mode = RenderMode::Local;
        const QString path = m_dir.filePath("export.exr");
        exportRender(local, assets, path.toStdString(), nullptr, nullptr, true);
        const ExrChannels e = readExr(path);
        QVERIFY2(e.channels.size() == kExpectedChannels.size() + cryptomatteChannels().size(), qPrintable(channelList(e)));
        for (const std::string& name : kExpectedChannels) QVERIFY(e.channels.count(name) == 1);
        for (const std::string& name : cryptomatteChannels()) QVERIFY2(e.channels.count(name) == 1, name.c_str());
        const RenderPasses want = renderPasses(renderQuad(local, false), RenderMode::Local, local.sky);
        for (size_t p = 0; p < want.depth.size(); ++p) QCOMPARE(e["Depth.Z"][p], want.depth[p]);
        const QString png = m_dir.filePath("export.png");
        QVERIFY_THROWS_EXCEPTION(Error, exportRender(local, assets, png.toStdString(), nullptr, nullptr, true));
        QVERIFY(!QFile::exists(png));
    }

    // sylva render --passes on a scene file: the layers in the EXR; bad combinations exit 2 writing nothing.
    void commandLine()
    {
        Scene sc = quadScene(1);
        const QString obj = m_dir.filePath("card.obj");
        writeObj(obj.toStdString(), quadMesh());
        sc.species[0].meshPath = obj.toStdString();
        sc.render.mode = RenderMode::Local;
        const QString scene = m_dir.filePath("card.sylva.json");
        writeSceneFile(sc, scene.toStdString());
        const QString out = m_dir.filePath("cli.exr");
        const test::Run r = runCli({"render", scene, "--passes", "-o", out, "--quiet"});
        QVERIFY2(r.code == 0, qPrintable(r.err));
        const ExrChannels e = readExr(out);
        QVERIFY2(e.channels.size() == kExpectedChannels.size() + cryptomatteChannels().size(), qPrintable(channelList(e)));
        for (const std::string& name : kExpectedChannels) QVERIFY(e.channels.count(name) == 1);
        for (const std::string& name : cryptomatteChannels()) QVERIFY2(e.channels.count(name) == 1, name.c_str());
        int withDirect = 0, withIndirect = 0;
        checkComposition(e, sc.sky, &withDirect, &withIndirect);
        QVERIFY(withDirect > 0);

        const QString png = m_dir.filePath("cli.png");
        const test::Run bad = runCli({"render", scene, "--passes", "-o", png, "--quiet"});
        QCOMPARE(bad.code, 2);
        QVERIFY2(bad.err.contains("--passes") && bad.err.contains(".exr"), qPrintable(bad.err));
        QVERIFY(!QFile::exists(png));
        const QString banded = m_dir.filePath("banded.exr");
        const test::Run bands = runCli({"render", scene, "--passes", "--band-rows", "8", "-o", banded, "--quiet"});
        QCOMPARE(bands.code, 2);
        QVERIFY(!QFile::exists(banded));
    }
};

QTEST_GUILESS_MAIN(TestRenderPasses)
#include "tst_render_passes.moc"
