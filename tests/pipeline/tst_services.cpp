// The pipeline services the sylva commands print from (pipeline/services): grid and mesh statistics,
// the reference's normalized summary and comparison, sidecar parameters, accel sizes and the file
// description, each against numbers worked out by hand for a small input.
#include <QDir>
#include <QFile>
#include <QJsonArray>
#include <QJsonDocument>
#include <QJsonObject>
#include <QTest>

#include <algorithm>
#include <cmath>

#include "core/base/error.h"
#include "core/lb/lb_params.h"
#include "core/reference/mc_reference.h"
#include "core/backend/backend.h"
#include "pipeline/io/file_extension.h"
#include "pipeline/io/image_io.h"
#include "pipeline/io/npy.h"
#include "pipeline/render/render_job.h"
#include "pipeline/services/exports.h"
#include "pipeline/services/file_info.h"
#include "pipeline/services/material_list.h"
#include "pipeline/services/grid_stats.h"
#include "pipeline/services/mesh_stats.h"
#include "pipeline/services/reference_stats.h"
#include "pipeline/services/render_stats.h"
#include "pipeline/services/sidecars.h"
#include "tests/common/files.h"
#include "tests/common/scenes.h"

using namespace sylva;

namespace {

GridGeometry cube(int n)
{
    GridGeometry g;
    g.dims = {n, n, n};
    return g;
}

bool near(double a, double b, double tol = 1e-12) { return std::fabs(a - b) <= tol * std::max(1.0, std::fabs(b)); }

// One small grown shrub (grid 12) on the ground, a close camera, 40x30 pixels.
Scene shrubScene(RenderMode mode)
{
    Scene s;
    s.species = {test::shrubSpecies(12, 3, 3000, 1.5f)};
    s.species[0].name = "shrub a";
    s.instances.resize(1);
    s.camera.position = {0.0, 1.0, -4.0};
    s.camera.target = {0.0, 0.7, 0.0};
    s.sun.direction = sunDirection(40.0, 120.0);
    s.render.width = 40;
    s.render.height = 30;
    s.render.spp = 1;
    s.render.mode = mode;
    return s;
}

void writeText(const QString& path, const char* text)
{
    QFile f(path);
    QVERIFY(f.open(QIODevice::WriteOnly));
    f.write(text);
}

lb::LbParams testParams()
{
    lb::LbParams p = lb::paramsFromPreset(*lb::findPreset("leaf"));
    p.sun = {0.3f, 1.0f, 0.2f};
    p.intensity = {1.0f, 0.5f, 2.0f};
    return p;
}

} // namespace

class TestServices : public QObject {
    Q_OBJECT

    QString m_dir;

private Q_SLOTS:
    void initTestCase()
    {
        m_dir = test::outputDir("services");
    }

    void dimsText() { QCOMPARE(gridDimsText(GridGeometry{{4, 5, 6}, {}, 1.0}), std::string("4x5x6")); }

    // 27 nodes: densities 1, 0.5, 0.25 at nodes 0..2, wood fractions 0.8, 0.2, 0.9, 1 at nodes 0..3
    // (node 3 is empty, so its wood does not make it brown): 3 occupied, 2 brown, mean 1.75 / 27.
    void densityStatistics()
    {
        DensityGrid d{cube(3), std::vector<float>(27, 0.0f), std::vector<float>(27, 0.0f)};
        d.density[0] = 1.0f, d.density[1] = 0.5f, d.density[2] = 0.25f;
        d.woodFraction[0] = 0.8f, d.woodFraction[1] = 0.2f, d.woodFraction[2] = 0.9f, d.woodFraction[3] = 1.0f;
        DensityStats s = densityStats(d);
        QCOMPARE(s.nodes, size_t(27));
        QCOMPARE(s.occupied, size_t(3));
        QCOMPARE(s.brown, size_t(2));
        QVERIFY(near(s.mean, 1.75 / 27.0));
        QVERIFY(near(s.occupiedPercent(), 300.0 / 27.0));
        d.woodFraction.clear();   // a grid without wood fraction has no brown nodes
        s = densityStats(d);
        QCOMPARE(s.brown, size_t(0));
        QCOMPARE(s.occupied, size_t(3));
        QCOMPARE(densityStats(DensityGrid{}).mean, 0.0);
    }

    // R = n, G = 2n, B = 1 at node 5 only, n = 0..26: means 13, 26, 1/27; maxima 26, 52, 1.
    void channelStatistics()
    {
        LightingGrid l{cube(3), std::vector<float>(27 * 3, 0.0f)};
        for (size_t n = 0; n < 27; ++n) l.rgb[n * 3] = float(n), l.rgb[n * 3 + 1] = 2.0f * float(n);
        l.rgb[5 * 3 + 2] = 1.0f;
        const ChannelStats s = channelStats(l);
        QCOMPARE(s.nodes, size_t(27));
        QVERIFY(near(s.mean.x, 13.0) && near(s.mean.y, 26.0) && near(s.mean.z, 1.0 / 27.0));
        QCOMPARE(s.max.x, 26.0);
        QCOMPARE(s.max.y, 52.0);
        QCOMPARE(s.max.z, 1.0);
        const ChannelStats empty = channelStats(LightingGrid{});
        QCOMPARE(empty.nodes, size_t(0));
        QCOMPARE(empty.mean.x, 0.0);
    }

    void valueStatistics()
    {
        const ValueStats s = valueStats({3.0f, -1.0f, 2.5f, 0.5f});
        QCOMPARE(s.count, size_t(4));
        QCOMPARE(s.min, -1.0);
        QCOMPARE(s.max, 3.0);
        QCOMPARE(s.mean, 1.25);
        const ValueStats e = valueStats({});
        QCOMPARE(e.count, size_t(0));
        QCOMPARE(e.mean, 0.0);
        QVERIFY(std::isinf(e.min) && e.min > 0 && std::isinf(e.max) && e.max < 0);
    }

    // Two leaf triangles and one wood triangle spanning x -1..2, y 0..5, z 0..1: 5 m tall, 3 m wide.
    void meshStatistics()
    {
        TriangleMesh m;
        m.positions = {{-1, 0, 0}, {0, 5, 0}, {2, 1, 1}, {0, 0, 0.5f}};
        m.triangles = {{0, 1, 2}, {0, 1, 3}, {1, 2, 3}};
        m.materials.resize(2);
        m.materials[0].name = "bark";
        m.materials[1].name = "leaves";
        m.materials[1].isLeaf = true;
        m.triangleMaterial = {1, 0, 1};
        const MeshStats s = meshStats(m);
        QCOMPARE(s.triangles, size_t(3));
        QCOMPARE(s.leafTriangles, size_t(2));
        QCOMPARE(s.woodTriangles, size_t(1));
        QCOMPARE(s.height(), 5.0f);
        QCOMPARE(s.width(), 3.0f);
        m.triangleMaterial.clear();   // no materials: every triangle is wood
        QCOMPARE(meshStats(m).leafTriangles, size_t(0));
    }

    void accelSummary()
    {
        AccelStats st;
        st.tlasBytes = 100, st.instanceBytes = 60, st.blasBytes = 1000, st.triangleBytes = 2000, st.wideTlasBytes = 40,
        st.wideBlasBytes = 800;
        st.instances = 4;
        st.instancedTriangles = 1000.0;
        AccelSummary s = summarizeAccel(st);
        QCOMPARE(s.totalBytes, 4000.0);
        QCOMPARE(s.bytesPerInstancedTriangle, 4.0);
        QCOMPARE(s.bytesPerInstance, 40.0);
        st.instances = 0, st.instancedTriangles = 0.0;   // an empty scene divides by one, not by zero
        s = summarizeAccel(st);
        QCOMPARE(s.bytesPerInstancedTriangle, 4000.0);
        QCOMPARE(s.bytesPerInstance, 160.0);
    }

    void standardErrorPaths()
    {
        QCOMPARE(standardErrorPath("out/ref.npy"), std::string("out/ref.stderr.npy"));
        QCOMPARE(standardErrorPath("ref.bin"), std::string("ref.bin.stderr.npy"));
        QCOMPARE(standardErrorPath(".npy"), std::string(".npy.stderr.npy"));
    }

    void referenceSidecar()
    {
        const lb::LbParams p = testParams();
        ReferenceSettings s;
        s.paths = 12345, s.seed = 7, s.maxBounces = 3, s.incidence = Incidence::Collimated;
        for (const auto quantity : {ReferenceQuantity::Mean, ReferenceQuantity::StandardError}) {
            QJsonParseError err;
            const QJsonDocument doc = QJsonDocument::fromJson(QByteArray::fromStdString(referenceParamsJson(p, "leaf", s, quantity)), &err);
            QVERIFY2(err.error == QJsonParseError::NoError, qPrintable(err.errorString()));
            const QJsonObject o = doc.object();
            QCOMPARE(o["solver"].toString(), QString("reference"));
            QCOMPARE(o["preset"].toString(), QString("leaf"));
            QCOMPARE(o["paths"].toInteger(), 12345);
            QCOMPARE(o["seed"].toInteger(), 7);
            QCOMPARE(o["max_bounces"].toInteger(), 3);
            QCOMPARE(o["incidence"].toString(), QString("collimated"));
            QCOMPARE(o["quantity"].toString(), quantity == ReferenceQuantity::Mean ? QString("mean fluence") : QString("standard error of the mean"));
            QCOMPARE(o["intensity"].toArray()[2].toDouble(), 2.0);
            QCOMPARE(o["sun"].toArray()[1].toDouble(), 1.0);
        }
        s.incidence = Incidence::LatticeBeams;
        const QJsonObject o = QJsonDocument::fromJson(QByteArray::fromStdString(referenceParamsJson(p, "leaf", s, ReferenceQuantity::Mean))).object();
        QCOMPARE(o["incidence"].toString(), QString("lattice"));
    }

    // A 4^3 reference whose node n holds (1 + n % 3) x the unobstructed value U_c in channel c, with a
    // standard error of 0.1 U_c everywhere. Normalized, the mean over the 64 nodes is (22*1 + 21*2 +
    // 21*3) / 64 = 127/64; the 8 interior nodes (21, 22, 25, 26, 37, 38, 41, 42) hold 1,2,2,3,2,3,3,1,
    // squares summing to 41, so the relative noise is 0.1 sqrt(8/41). An LB grid of (1 + c) x the
    // reference errs by 0, 1, 2 per channel, sqrt(5/3) overall, and its interior mean is 2x.
    void referenceSummaryAndComparison()
    {
        const lb::LbParams p = testParams();
        ReferenceResult ref;
        ref.mean = LightingGrid{cube(4), std::vector<float>(64 * 3)};
        ref.standardError.resize(64 * 3);
        double unobstructed[3];
        for (int c = 0; c < 3; ++c) unobstructed[c] = unobstructedValue(p, c);
        for (size_t n = 0; n < 64; ++n)
            for (int c = 0; c < 3; ++c) {
                ref.mean.rgb[n * 3 + size_t(c)] = float((1.0 + double(n % 3)) * unobstructed[c]);
                ref.standardError[n * 3 + size_t(c)] = float(0.1 * unobstructed[c]);
            }
        const ReferenceSummary s = summarizeReference(ref, p);
        for (int c = 0; c < 3; ++c) QVERIFY2(near(s.meanNormalized[c], 127.0 / 64.0, 1e-6), qPrintable(QString::number(s.meanNormalized[c])));
        QVERIFY(near(s.relativeNoise, 0.1 * std::sqrt(8.0 / 41.0), 1e-6));
        QVERIFY(near(s.normalized.at(1, 1, 1, 2), 1.0, 1e-6));   // node 21
        QVERIFY(near(s.normalizedError[5], 0.1, 1e-6));

        LightingGrid lb = ref.mean;
        for (size_t n = 0; n < 64; ++n)
            for (int c = 0; c < 3; ++c) lb.rgb[n * 3 + size_t(c)] *= float(1 + c);
        const ReferenceComparison cmp = compareWithReference(lb, s, p);
        QVERIFY(near(cmp.relativeL2PerChannel.x, 0.0, 1e-6));
        QVERIFY(near(cmp.relativeL2PerChannel.y, 1.0, 1e-6));
        QVERIFY(near(cmp.relativeL2PerChannel.z, 2.0, 1e-6));
        QVERIFY(near(cmp.relativeL2, std::sqrt(5.0 / 3.0), 1e-6));
        QVERIFY(near(cmp.meanRatio, 2.0, 1e-6));
        QCOMPARE(cmp.noise, s.relativeNoise);
        QVERIFY(near(cmp.withoutNoise, std::sqrt(5.0 / 3.0 - s.relativeNoise * s.relativeNoise), 1e-6));

        LightingGrid other{cube(3), std::vector<float>(27 * 3, 1.0f)};
        QVERIFY_THROWS_EXCEPTION(Error, compareWithReference(other, s, p));
    }

    // A (2,3) array of 1, 2, 3, 4, 5, -6: min -6, max 5, mean 9/6; its sidecar is shown as stored.
    void describeNpyFile()
    {
        const std::string path = (m_dir + "/a.npy").toStdString();
        writeNpy(path, NpyArray{{2, 3}, {1, 2, 3, 4, 5, -6}});
        QCOMPARE(describeFile(path), path + ": NumPy float32 array, shape (2, 3), 6 values, min -6, max 5, mean 1.5\n");
        QFile side(QString::fromStdString(path + ".json"));
        QVERIFY(side.open(QIODevice::WriteOnly));
        side.write("{\"kind\": \"test\"}");
        side.close();
        Progress progress;
        double last = -1.0;
        progress.setCallback([&](double f, const std::string&) { last = f; });
        QCOMPARE(describeFile(path, &progress), path + ": NumPy float32 array, shape (2, 3), 6 values, min -6, max 5, mean 1.5\n" +
                                                    "placement (" + path + ".json): {\"kind\": \"test\"}\n");
        QCOMPARE(last, 1.0);
        progress.cancel();
        QVERIFY_THROWS_EXCEPTION(Cancelled, describeFile(path, &progress));
    }

    void describeMeshFile()
    {
        const QString obj = m_dir + "/tri.obj";
        QFile f(obj);
        QVERIFY(f.open(QIODevice::WriteOnly));
        f.write("v 0 0 0\nv 1 0 0\nv 0 2 0\nf 1 2 3\n");
        f.close();
        const std::string text = describeFile(obj.toStdString());
        QVERIFY2(text.rfind(obj.toStdString() + ": mesh\n", 0) == 0, text.c_str());
        QVERIFY2(text.find('1') != std::string::npos, text.c_str());
    }

    void describeRefusesWhatItDoesNotRead()
    {
        const std::string missing = (m_dir + "/missing.npy").toStdString();
        auto messageOf = [](const std::string& path) {
            try {
                describeFile(path);
            } catch (const Error& e) {
                return std::string(e.what());
            }
            return std::string("no error");
        };
        QCOMPARE(messageOf(missing), missing + ": no such file");
        QCOMPARE(messageOf(m_dir.toStdString()), m_dir.toStdString() + ": is a folder, not a file");
        const std::string png = (m_dir + "/p.png").toStdString();
        QFile pf(QString::fromStdString(png));
        QVERIFY(pf.open(QIODevice::WriteOnly));
        pf.close();
        const std::string m = messageOf(png);
        QVERIFY2(m.rfind(png + ": not a scene, mesh, .npy or .vdb grid or cache entry", 0) == 0, m.c_str());
    }

    // One lowerExtension for the commands and the services.
    void lowerCaseExtension()
    {
        QCOMPARE(lowerExtension("out/A.PNG"), std::string(".png"));
        QCOMPARE(lowerExtension("grid.density.NPY"), std::string(".npy"));
        QCOMPARE(lowerExtension("dir.d/noext"), std::string());
    }

    void speciesLogLinesNameTheSpecies()
    {
        JobLog log;
        log.stages = {"grow", "tree: import", "light (cache hit)"};
        log.warnings = {"cache entry unreadable"};
        QCOMPARE(speciesLogLines("tree", log), (std::vector<std::string>{"tree: grow", "tree: import", "tree: light (cache hit)",
                                                                         "warning: cache entry unreadable"}));
    }

    void gridExportNames()
    {
        QCOMPARE(gridFileBase("Tree 1 (2)/x"), std::string("Tree_1__2__x"));
        QCOMPARE(gridFileBase("a.b-c_D9"), std::string("a.b-c_D9"));
        QCOMPARE(gridFileBase(""), std::string("species"));
        QCOMPARE(gridFileBase("B\xc3\xa4um"), std::string("B_um"));   // one '_' for the two bytes of one character
        const GridExportFiles f = gridExportFiles("/tmp/out", "Tree 1");
        QCOMPARE(f.density, std::string("/tmp/out/Tree_1.density.npy"));
        QCOMPARE(f.lighting, std::string("/tmp/out/Tree_1.lighting.npy"));
    }

    // The files exportSpeciesGrids writes, read back, hold the grids loadSpeciesGrids returns for the
    // same species (solved separately, no cache), and the sidecar the LB parameters as solved.
    void exportSpeciesGridsWritesTheGrids()
    {
        const Scene s = shrubScene(RenderMode::Full);
        const SpeciesGrids oracle = loadSpeciesGrids(s, 0, nullptr);
        const QString folder = m_dir + "/grid_export";
        CpuBackend cpu;
        JobLog log;
        std::vector<double> seen;
        Progress progress([&](double f, const std::string&) { seen.push_back(f); });
        const GridExportFiles files = exportSpeciesGrids(s, 0, folder.toStdString(), nullptr, &cpu, &progress, &log);
        QCOMPARE(files.density, (folder + "/shrub_a.density.npy").toStdString());
        QCOMPARE(files.lighting, (folder + "/shrub_a.lighting.npy").toStdString());
        QVERIFY(!seen.empty());
        QCOMPARE(seen.back(), 1.0);
        QVERIFY(std::is_sorted(seen.begin(), seen.end()));
        QVERIFY(std::find(log.stages.begin(), log.stages.end(), "light") != log.stages.end());
        const DensityGrid density = readDensityGrid(files.density);
        QCOMPARE(density.geometry, oracle.density.geometry);
        QVERIFY(density.density == oracle.density.density);
        QVERIFY(density.woodFraction == oracle.density.woodFraction);
        const LightingGrid light = readLightingGrid(files.lighting);
        QCOMPARE(light.geometry, oracle.lighting.geometry);
        QCOMPARE(light.rgb.size(), oracle.lighting.rgb.size());
        for (size_t i = 0; i < light.rgb.size(); ++i)
            QVERIFY2(near(light.rgb[i], oracle.lighting.rgb[i], 1e-5), qPrintable(QString::number(i)));
        QFile side(QString::fromStdString(files.lighting) + ".json");
        QVERIFY(side.open(QIODevice::ReadOnly));
        const QJsonObject p = QJsonDocument::fromJson(side.readAll()).object()["parameters"].toObject();
        QCOMPARE(p["preset"].toString(), QStringLiteral("leaf"));
        for (int c = 0; c < 3; ++c) QCOMPARE(float(p["sun"].toArray()[c].toDouble()), oracle.params.sun[c]);
        // A species the scene lacks: an error, no file.
        QVERIFY_THROWS_EXCEPTION(Error, exportSpeciesGrids(s, 1, (folder + "/none").toStdString(), nullptr));
        QVERIFY(!QDir(folder + "/none").exists());
    }

    // exportRender's picture equals renderScene's film composed and tone-mapped by hand.
    void exportRenderWritesThePicture()
    {
        const Scene s = shrubScene(RenderMode::Local);
        const std::vector<SpeciesAssets> assets = loadSpeciesAssets(s, nullptr, false);
        const std::string path = (m_dir + "/export.png").toStdString();
        CpuBackend cpu;
        double last = -1.0;
        Progress progress([&](double f, const std::string&) { last = f; });
        exportRender(s, assets, path, &cpu, &progress);
        QCOMPARE(last, 1.0);
        const RenderOutput ref = renderScene(s, nullptr);
        const ImageRgba expected =
            toneMapped(composeMode(ref.film, s.render.mode, s.sky), ref.film.width, ref.film.height, s.render.exposureKey);
        const ImageRgba got = readImage(path);
        QCOMPARE(got.width, 40);
        QCOMPARE(got.height, 30);
        QCOMPARE(got.pixels.size(), expected.pixels.size());
        int lit = 0;
        for (size_t i = 0; i < got.pixels.size(); ++i) {
            QVERIFY2(std::fabs(got.pixels[i] - expected.pixels[i]) <= 0.5f / 255.0f + 1e-6f, qPrintable(QString::number(i)));
            lit += i % 4 != 3 && got.pixels[i] > 0.02f;
        }
        QVERIFY(lit > 0);
        // Without a backend: the CPU, the same picture.
        const std::string path2 = (m_dir + "/export_nobackend.png").toStdString();
        exportRender(s, assets, path2, nullptr);
        QVERIFY(readImage(path2).pixels == got.pixels);
        QVERIFY_THROWS_EXCEPTION(Error, exportRender(s, assets, (m_dir + "/export.bmp").toStdString(), &cpu));
    }

    // The materials of a hand-written OBJ + MTL: the rules mark the leaf-named one, a species list
    // (any case) replaces the rules.
    void listMaterialsOfAMesh()
    {
        const QString dir = m_dir + "/materials";
        QDir().mkpath(dir);
        writeText(dir + "/m.mtl", "newmtl Bark\nKd 0.4 0.3 0.2\nnewmtl Tree_Leaves\nKd 0.2 0.6 0.2\n");
        writeText(dir + "/m.obj", "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\n"
                                  "usemtl Bark\nf 1 2 3\nusemtl Tree_Leaves\nf 1 3 4\n");
        const std::string obj = (dir + "/m.obj").toStdString();
        auto byName = [](const std::vector<MaterialAssignment>& v, const std::string& n) {
            for (const MaterialAssignment& m : v)
                if (m.name == n) return m;
            return MaterialAssignment{"(missing)", false, false};
        };
        const std::vector<MaterialAssignment> rules = listMaterials(obj, {});
        QCOMPARE(rules.size(), size_t(2));
        QCOMPARE(byName(rules, "Bark").leafByRules, false);
        QCOMPARE(byName(rules, "Bark").leaf, false);
        QCOMPARE(byName(rules, "Tree_Leaves").leafByRules, true);
        QCOMPARE(byName(rules, "Tree_Leaves").leaf, true);
        const std::vector<MaterialAssignment> listed = listMaterials(obj, {"bARK"});
        QCOMPARE(byName(listed, "Bark").leafByRules, false);
        QCOMPARE(byName(listed, "Bark").leaf, true);
        QCOMPARE(byName(listed, "Tree_Leaves").leafByRules, true);
        QCOMPARE(byName(listed, "Tree_Leaves").leaf, false);
        QVERIFY_THROWS_EXCEPTION(Error, listMaterials((dir + "/missing.obj").toStdString(), {}));
    }
};

QTEST_GUILESS_MAIN(TestServices)
#include "tst_services.moc"
