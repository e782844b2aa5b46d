// Blender as a client of Sylva's files and as the ground truth's renderer (label `blender`; skipped with a
// message when `blender` is absent): the grower's OBJ imports with its materials and textures, an exported
// .vdb opens with its grids, a --passes EXR with its layers; and the converter's scene in Cycles shows the
// closed-form radiance of a sunlit ground under a uniform sky, albedo x (sunRadiance x cos + sky), as
// Sylva's renderer does.
#include <QTemporaryDir>
#include <QTest>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <OpenImageIO/imageio.h>

#include "pipeline/io/image_io.h"
#include "pipeline/render/render_job.h"
#include "pipeline/study/blender_scene.h"
#include "tests/common/blender.h"
#include "tests/common/run_program.h"

using namespace sylva;

using test::blenderProgram;
using test::runBlender;
using test::valueAfter;

class TestBlender : public QObject {
    Q_OBJECT
    std::string m_blender;
private Q_SLOTS:
    void initTestCase()
    {
        m_blender = blenderProgram();
        if (m_blender.empty()) QSKIP("no `blender` on the PATH (set SYLVA_BLENDER): the Blender client checks are skipped");
    }

    // The converter's script in Cycles: a ground plane under the sun and the constant sky, seen from above.
    void cyclesGroundMatchesClosedForm()
    {
        QTemporaryDir tmp;
        Scene s;
        s.render.width = 16;
        s.render.height = 12;
        s.sun.direction = sunDirection(50.0, 30.0);
        s.sun.temperature = 5000.0;
        s.sky = {0.30f, 0.40f, 0.60f};
        s.ground.color = {0.50f, 0.30f, 0.20f};
        s.camera.position = {0.0, 6.0, 0.0};
        s.camera.target = {0.0, 0.0, 2.0};
        s.camera.fovY = 30.0f;
        const std::string dir = tmp.path().toStdString();
        study::BlenderOptions o;
        o.samples = 256;
        const std::string script = study::writeBlenderScene(s, {}, dir, o);
        const std::string exr = dir + "/ground.exr";
        const std::string out = runBlender(m_blender, script, "--out '" + exr + "'");
        QVERIFY2(out.find("SYLVA_CYCLES_SECONDS=") != std::string::npos, out.c_str());
        auto in = OIIO::ImageInput::open(exr);
        QVERIFY(in);
        const OIIO::ImageSpec& spec = in->spec();
        QCOMPARE(spec.width, 16);
        QCOMPARE(spec.height, 12);
        std::vector<float> px(size_t(spec.width) * size_t(spec.height) * size_t(spec.nchannels));
        QVERIFY(in->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::FLOAT, px.data()));
        int ch[3] = {-1, -1, -1};
        for (int c = 0; c < spec.nchannels; ++c)
            for (int k = 0; k < 3; ++k)
                if (spec.channelnames[size_t(c)] == std::string("ViewLayer.Combined.") + "RGB"[k]) ch[k] = c;
        QVERIFY(ch[0] >= 0 && ch[1] >= 0 && ch[2] >= 0);
        const glm::vec3 rad = sunRadiance(s.sun);
        const double cosSun = glm::normalize(s.sun.direction).y;
        for (int k = 0; k < 3; ++k) {
            double mean = 0.0;
            for (int p = 0; p < spec.width * spec.height; ++p) mean += px[size_t(p * spec.nchannels + ch[k])];
            mean /= double(spec.width * spec.height);
            const double expected = double(s.ground.color[k]) * (double(rad[k]) * cosSun + double(s.sky[k]));
            QVERIFY2(std::fabs(mean / expected - 1.0) < 0.015, qPrintable(QString("channel %1: Cycles %2, closed form %3").arg(k).arg(mean).arg(expected)));
        }
    }

    // A map sky as the world texture: looking along +X and +Z (Sylva's frame), Cycles' background shows the
    // map's texel that Sylva's equirectUv gives for that direction (u = 1/2 - atan2(x, z) / 2pi, v = acos(y) / pi).
    void cyclesSkyMapOrientation()
    {
        QTemporaryDir tmp;
        const std::string dir = tmp.path().toStdString();
        const int mw = 16, mh = 8;
        ImageRgba map(mw, mh);
        for (int y = 0; y < mh; ++y)
            for (int x = 0; x < mw; ++x) {
                float* p = &map.pixels[size_t(y * mw + x) * 4];
                p[0] = 0.05f * float(x + 1);
                p[1] = 0.1f * float(y + 1);
                p[2] = 0.5f;
                p[3] = 1.0f;
            }
        writeImage(dir + "/map.exr", map);
        for (glm::dvec3 d : {glm::dvec3(1, 0.2, 0.1), glm::dvec3(0.1, 0.2, 1), glm::dvec3(-0.6, 0.5, -0.7), glm::dvec3(0.3, -0.4, -1)}) {
            Scene s;
            s.render.width = 4;
            s.render.height = 4;
            s.skyModel.kind = sky::SkyKind::Map;
            s.ground.enabled = false;
            s.camera.position = {0.0, 0.0, 0.0};
            s.camera.target = d;
            s.camera.fovY = 1.0f;
            study::BlenderOptions o;
            o.samples = 4;
            const std::string script = study::writeBlenderScene(s, {}, dir, o, dir + "/map.exr");
            const std::string exr = dir + "/sky.exr";
            const std::string out = runBlender(m_blender, script, "--out '" + exr + "' --sun 0");
            QVERIFY2(out.find("SYLVA_CYCLES_SECONDS=") != std::string::npos, out.c_str());
            auto in = OIIO::ImageInput::open(exr);
            QVERIFY(in);
            const OIIO::ImageSpec& spec = in->spec();
            std::vector<float> px(size_t(spec.width * spec.height * spec.nchannels));
            QVERIFY(in->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::FLOAT, px.data()));
            int ch[3] = {-1, -1, -1};
            for (int c = 0; c < spec.nchannels; ++c)
                for (int k = 0; k < 3; ++k)
                    if (spec.channelnames[size_t(c)] == std::string("ViewLayer.Combined.") + "RGB"[k]) ch[k] = c;
            const glm::dvec3 n = glm::normalize(d);
            const double u = 0.5 - std::atan2(n.x, n.z) / (2.0 * M_PI), v = std::acos(n.y) / M_PI;
            const int tx = int((u - std::floor(u)) * mw), ty = int(v * mh);
            const size_t centre = size_t((1 * spec.width + 1) * spec.nchannels);   // pixel (1, 1), next to the axis
            const float r = px[centre + size_t(ch[0])], g = px[centre + size_t(ch[1])];
            QVERIFY2(std::fabs(r - 0.05f * float(tx + 1)) < 2e-3f && std::fabs(g - 0.1f * float(ty + 1)) < 2e-3f,
                     qPrintable(QString("direction (%1, %2, %3): Cycles (%4, %5), map texel (%6, %7)").arg(d.x).arg(d.y).arg(d.z).arg(r).arg(g).arg(tx).arg(ty)));
        }
    }

    // The grower's OBJ, an exported .vdb and a --passes EXR opened by Blender itself.
    void blenderReadsOurFiles()
    {
        QTemporaryDir tmp;
        const std::string dir = tmp.path().toStdString();
        QCOMPARE(test::runSylva({"grow", "--species", "shrub", "--triangles", "2000", "--quiet", "-o", QString::fromStdString(dir + "/shrub.obj")}).code, 0);
        {
            std::ofstream f(dir + "/scene.sylva.json");
            f << R"({"version": 1, "species": [{"name": "shrub", "grow": {"species": "shrub", "seed": 2, "triangles": 2000},
                  "lighting": {"preset": "leaf", "grid": 12}}], "instances": [{"species": "shrub", "position": [0, 0, 0]}],
                  "camera": {"position": [0, 1, -4], "target": [0, 0.5, 0]}, "render": {"width": 32, "height": 24}})";
        }
        QCOMPARE(test::runSylva({"export", QString::fromStdString(dir + "/scene.sylva.json"), "--out", QString::fromStdString(dir), "--no-cache", "--quiet"}).code, 0);
        QCOMPARE(test::runSylva({"render", QString::fromStdString(dir + "/scene.sylva.json"), "--passes", "--no-cache", "--quiet", "-o", QString::fromStdString(dir + "/passes.exr")}).code, 0);
        QVERIFY(std::filesystem::exists(dir + "/shrub.vdb"));
        const std::string py = dir + "/check.py";
        {
            std::ofstream f(py);
            f << "import bpy, sys\nD = " << "r'" << dir << "/'\n" << R"PY(
for ob in list(bpy.data.objects):
    bpy.data.objects.remove(ob, do_unlink=True)
bpy.ops.wm.obj_import(filepath=D + 'shrub.obj')
for m in bpy.data.materials:
    imgs = [n.image for n in m.node_tree.nodes if n.type == 'TEX_IMAGE' and n.image] if m.use_nodes else []
    print('MATERIAL=%s %s' % (m.name, ' '.join('%dx%d' % (i.size[0], i.size[1]) for i in imgs)))
print('FACES=%d' % sum(len(o.data.polygons) for o in bpy.data.objects if o.type == 'MESH'))
bpy.ops.object.volume_import(filepath=D + 'shrub.vdb')
vol = [o for o in bpy.data.objects if o.type == 'VOLUME'][0]
vol.data.grids.load()
print('GRIDS=%s' % ' '.join(sorted(g.name for g in vol.data.grids)))
img = bpy.data.images.load(D + 'passes.exr')
sc = bpy.context.scene
sc.use_nodes = True
n = sc.node_tree.nodes.new('CompositorNodeImage')
n.image = img
print('TYPE=%s' % img.type)
print('LAYERS=%s' % ' '.join(o.name for o in n.outputs if o.enabled))
)PY";
        }
        const std::string out = runBlender(m_blender, py);
        // OBJ: the bark and leaf materials with their textures loaded (pixels, not just names).
        std::string bark, leaf;
        for (size_t at = out.find("MATERIAL="); at != std::string::npos; at = out.find("MATERIAL=", at + 1)) {
            const std::string line = out.substr(at + 9, out.find('\n', at) - at - 9);
            if (line.rfind("bark", 0) == 0) bark = line;
            if (line.rfind("leaf", 0) == 0) leaf = line;
        }
        QVERIFY2(!bark.empty() && !leaf.empty(), out.c_str());
        QVERIFY2(bark.find('x') != std::string::npos && bark.find("0x0") == std::string::npos, bark.c_str());
        QVERIFY2(leaf.find('x') != std::string::npos && leaf.find("0x0") == std::string::npos, leaf.c_str());
        QVERIFY2(std::atoi(valueAfter(out, "FACES=").c_str()) > 500, out.c_str());
        // VDB: the density, wood fraction and lighting grids.
        const std::string grids = valueAfter(out, "GRIDS=");
        for (const char* g : {"density", "wood_fraction", "lighting", "lighting_r", "lighting_g", "lighting_b"})
            QVERIFY2((" " + grids + " ").find(std::string(" ") + g + " ") != std::string::npos, qPrintable(QString::fromStdString(grids)));
        // Passes: a multi-layer image with the layers `--passes` writes.
        QCOMPARE(QString::fromStdString(valueAfter(out, "TYPE=")), QString("MULTILAYER"));
        const std::string layers = std::string(" ") + valueAfter(out, "LAYERS=") + " ";
        for (const char* l : {"Combined", "DiffDir", "DiffInd", "DiffCol", "Env", "Normal", "Depth", "Alpha"})
            QVERIFY2(layers.find(l) != std::string::npos, qPrintable(QString::fromStdString(layers)));
    }
};

QTEST_GUILESS_MAIN(TestBlender)
#include "tst_blender.moc"
