// Blender's compositor as a Cryptomatte client (label `blender`; skipped with a message when `blender` is
// absent): its Cryptomatte node, given a `--passes` EXR of the two-card scene (tests/common/matte_scene.h) as
// an image, extracts each species' matte from the file's CryptoAsset layers through the header's manifest;
// Blender writes that matte as a 32-bit EXR, which must equal the matte a compositor's sum of the ranks'
// coverage gives (and so the share of the pixel's samples that hit the species, tst_cryptomatte).
#include <QTemporaryDir>
#include <QTest>

#include <cmath>
#include <fstream>

#include <OpenImageIO/imageio.h>

#include "core/render/render_cpu.h"
#include "pipeline/render/frame_build.h"
#include "pipeline/render/render_job.h"
#include "pipeline/services/exports.h"
#include "tests/common/blender.h"
#include "tests/common/matte_scene.h"

using namespace sylva;

namespace {

// The compositor graph: Image (the passes EXR) -> Cryptomatte (source image, the type, the names) -> the
// output, rendered once with the render size equal to the image's and written as a 32-bit float EXR. Blender
// 5 keeps the compositor in a node group (scene.compositing_node_group, a Group Output); earlier versions in
// scene.node_tree with a Composite node.
const char* kScript = R"PY(
import bpy, sys
argv = sys.argv[sys.argv.index('--') + 1:]
exr, out, layer, names, width, height = argv[0], argv[1], argv[2], argv[3], int(argv[4]), int(argv[5])
img = bpy.data.images.load(exr)
print('IMAGE=%s %dx%d' % (img.type, img.size[0], img.size[1]))   # reading the size loads the file's layers and header
sc = bpy.context.scene
sc.render.engine = 'BLENDER_WORKBENCH'
sc.render.resolution_x = width
sc.render.resolution_y = height
sc.render.resolution_percentage = 100
sc.render.use_compositing = True
sc.render.use_sequencer = False
sc.render.image_settings.file_format = 'OPEN_EXR'
sc.render.image_settings.color_depth = '32'
sc.render.image_settings.color_mode = 'RGB'
sc.view_settings.view_transform = 'Standard'
sc.render.filepath = out
if hasattr(sc, 'compositing_node_group'):
    tree = bpy.data.node_groups.new('SylvaMattes', 'CompositorNodeTree')
    tree.interface.new_socket(name='Image', in_out='OUTPUT', socket_type='NodeSocketColor')
    sc.compositing_node_group = tree
    sink = tree.nodes.new('NodeGroupOutput').inputs[0]
else:
    sc.use_nodes = True
    tree = sc.node_tree
    for n in list(tree.nodes):
        tree.nodes.remove(n)
    sink = tree.nodes.new('CompositorNodeComposite').inputs['Image']
crypto = tree.nodes.new('CompositorNodeCryptomatteV2')
crypto.source = 'IMAGE'
crypto.image = img
try:
    crypto.layer_name = layer   # the types Blender found in the header's cryptomatte/<key>/name
except TypeError as e:
    print('LAYER_ERROR=%s' % e)
print('CRYPTO_LAYER=%s' % crypto.layer_name)
crypto.matte_id = names
print('MATTE_ID=%s' % crypto.matte_id)
tree.links.new(crypto.outputs['Matte'], sink)
bpy.ops.render.render(write_still=True)
print('WROTE=%s' % out)
)PY";

// The first channel of an EXR Blender wrote (the matte in R, G and B).
std::vector<float> readFirstChannel(const std::string& path, int* width, int* height)
{
    auto in = OIIO::ImageInput::open(path);
    if (!in) return {};
    const OIIO::ImageSpec spec = in->spec();
    *width = spec.width;
    *height = spec.height;
    std::vector<float> data(size_t(spec.width) * size_t(spec.height) * size_t(spec.nchannels));
    if (!in->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::FLOAT, data.data())) return {};
    std::vector<float> out(size_t(spec.width) * size_t(spec.height));
    for (size_t p = 0; p < out.size(); ++p) out[p] = data[p * size_t(spec.nchannels)];
    return out;
}

} // namespace

class TestCryptomatteBlender : public QObject {
    Q_OBJECT
    std::string m_blender;

private Q_SLOTS:
    void initTestCase()
    {
        m_blender = test::blenderProgram();
        if (m_blender.empty()) QSKIP("no `blender` on the PATH (set SYLVA_BLENDER): the Cryptomatte check in Blender's compositor is skipped");
    }

    // Each species' matte (CryptoAsset) from Blender's Cryptomatte node equals ours, pixel for pixel (1e-5),
    // with partial (anti-aliased) coverage along the cards' edges at 16 samples per pixel.
    void compositorExtractsSpeciesMatte()
    {
        QTemporaryDir tmp;
        QVERIFY(tmp.isValid());
        const std::string dir = tmp.path().toStdString();
        const Scene sc = test::matteScene(16);
        const std::string exr = dir + "/passes.exr";
        {
            const RenderScene rs = buildRenderScene(sc, test::matteAssets(), sunRadiance(sc.sun));
            const Film film = renderFilm(rs.view());
            const MatteFilm mattes = renderMatteFilm(rs.view());
            writeRenderFilm(exr, film, sc, true, &mattes);
        }
        const std::string script = dir + "/matte.py";
        std::ofstream(script) << kScript;
        const test::ExrCryptomatte ours = test::readCryptomatte(exr, "CryptoAsset");
        QVERIFY2(ours.error.empty(), ours.error.c_str());
        for (const char* species : {"aspen", "spruce"}) {
            const std::string out = dir + "/" + species + "_matte.exr";
            const std::string log = test::runBlender(m_blender, script,
                                                     "'" + exr + "' '" + out + "' CryptoAsset " + species + " " +
                                                         std::to_string(sc.render.width) + " " + std::to_string(sc.render.height));
            QVERIFY2(log.find("WROTE=") != std::string::npos, log.c_str());
            QVERIFY2(test::valueAfter(log, "CRYPTO_LAYER=").find("CryptoAsset") != std::string::npos, log.c_str());
            int w = 0, h = 0;
            const std::vector<float> blender = readFirstChannel(out, &w, &h);
            QCOMPARE(w, sc.render.width);
            QCOMPARE(h, sc.render.height);
            const std::vector<float> want = ours.matte({species});
            int partial = 0;
            float covered = 0.0f;
            for (size_t p = 0; p < want.size(); ++p) {
                if (std::abs(blender[p] - want[p]) > 1e-5f)
                    QFAIL(qPrintable(QString("%1, pixel %2,%3: Blender's matte %4, ours %5")
                                         .arg(species).arg(p % size_t(w)).arg(p / size_t(w)).arg(blender[p]).arg(want[p])));
                partial += want[p] > 0.0f && want[p] < 1.0f ? 1 : 0;
                covered += want[p];
            }
            QVERIFY2(partial > 10 && covered > 50.0f, qPrintable(QString("%1: %2 partial pixels, %3 covered").arg(species).arg(partial).arg(covered)));
        }
    }
};

QTEST_GUILESS_MAIN(TestCryptomatteBlender)
#include "tst_cryptomatte_blender.moc"
