// The sylva command line: exit codes and messages for bad usage and bad input, and the whole path on a real tree.
#include <QDir>
#include <QFileInfo>
#include <QProcess>
#include <QRegularExpression>
#include <QTest>

#include <cmath>
#include <sys/stat.h>

#include "core/grid/grid.h"
#include "pipeline/io/npy.h"
#include "tests/common/run_program.h"

using namespace sylva;

namespace {

using test::Run;
using test::runSylva;

QString outDir()
{
    const QString dir = QString(SYLVA_TEST_OUTPUT) + "/cli";
    QDir().mkpath(dir);
    return dir;
}

} // namespace

class TestCli : public QObject {
    Q_OBJECT
private Q_SLOTS:
    void usageErrorsExitTwo_data()
    {
        QTest::addColumn<QStringList>("args");
        QTest::addColumn<QString>("mentions");
        QTest::newRow("no command") << QStringList{} << "usage";
        QTest::newRow("unknown command") << QStringList{"paint"} << "unknown command 'paint'";
        QTest::newRow("unknown option") << QStringList{"grow", "--colour", "red"} << "unknown option --colour";
        QTest::newRow("missing value") << QStringList{"grow", "--seed"} << "needs a value";
        QTest::newRow("bad number") << QStringList{"grow", "--triangles", "lots"} << "not a whole number";
        QTest::newRow("out of range") << QStringList{"grow", "--triangles", "10"} << "outside [1000, 1000000]";
        QTest::newRow("unknown species") << QStringList{"grow", "--species", "palm"} << "unknown species 'palm'";
        QTest::newRow("light without sun") << QStringList{"light", "--density", "x.npy", "-o", "y.npy"} << "needs --sun";
        QTest::newRow("light without input") << QStringList{"light", "--sun", "0,1,0", "-o", "y.npy"} << "exactly one of";
        QTest::newRow("bad triple") << QStringList{"light", "--density", "x.npy", "--sun", "0,1", "-o", "y.npy"} << "three comma-separated";
        QTest::newRow("bad preset") << QStringList{"light", "--density", "x.npy", "--sun", "0,1,0", "--preset", "glass", "-o", "y"} << "unknown preset 'glass'";
        QTest::newRow("voxelize without output") << QStringList{"voxelize", "mesh.obj"} << "needs --output";
        QTest::newRow("bad grid") << QStringList{"voxelize", "mesh.obj", "--grid", "2", "-o", "d.npy"} << "outside [3, 512]";
        QTest::newRow("empty output") << QStringList{"voxelize", "mesh.obj", "-o", ""} << "empty value";
        QTest::newRow("grid with density") << QStringList{"light", "--density", "x.npy", "--grid", "8", "--sun", "0,1,0", "-o", "y.npy"} << "applies to --mesh";
        QTest::newRow("bad axis") << QStringList{"light", "--density", "x.npy", "--sun", "0,1,0", "-o", "y.npy", "--picture", "p.png", "--axis", "w"} << "expected x, y or z";
        QTest::newRow("picture without extension") << QStringList{"light", "--density", "x.npy", "--sun", "0,1,0", "-o", "y.npy", "--picture", "pic"} << "image extension";
        QTest::newRow("render bad mode") << QStringList{"render", "--mode", "sketch"} << "expected full, local, ambient or lb";
        QTest::newRow("render bad accel") << QStringList{"render", "--accel", "octree"} << "expected bvh or kdtree";
        QTest::newRow("render bad quality") << QStringList{"render", "--quality", "draft"} << "expected preview, final or reference";
        QTest::newRow("render bad spp") << QStringList{"render", "--spp", "0"} << "outside [1, 4096]";
        QTest::newRow("render bad extension") << QStringList{"render", "-o", "forest.jpg2"} << "unknown image extension";
        QTest::newRow("render two scenes") << QStringList{"render", "a.json", "b.json"} << "unexpected argument 'b.json'";
        QTest::newRow("steps and tol") << QStringList{"light", "--density", "x.npy", "--sun", "0,1,0", "--steps", "5", "--tol", "1e-3", "-o", "y"} << "exclude each other";
    }
    void usageErrorsExitTwo()
    {
        QFETCH(QStringList, args);
        QFETCH(QString, mentions);
        const Run r = runSylva(args);
        QCOMPARE(r.code, 2);
        QVERIFY2((r.err + r.out).contains(mentions), qPrintable(r.err + r.out));
    }

    void helpExitsZero()
    {
        for (const QString cmd : {"grow", "voxelize", "light", "render", "info"}) {
            const Run r = runSylva({cmd, "--help"});
            QCOMPARE(r.code, 0);
            QVERIFY(r.out.contains("usage: sylva " + cmd));
        }
        QCOMPARE(runSylva({"--help"}).code, 0);
        const Run v = runSylva({"--version"});
        QCOMPARE(v.code, 0);
        QVERIFY(v.out.contains("backends: cpu"));
    }

    void badInputExitsOneNamingTheFile()
    {
        const QString dir = outDir();
        const QString garbage = dir + "/garbage.obj";
        QFile f(garbage);
        QVERIFY(f.open(QIODevice::WriteOnly));
        f.write("this is not a mesh \x01\x02\x03");
        f.close();
        const QString missing = dir + "/does_not_exist.obj";
        Run r = runSylva({"voxelize", missing, "-o", dir + "/d.npy"});
        QCOMPARE(r.code, 1);
        QVERIFY2(r.err.contains(missing), qPrintable(r.err));
        r = runSylva({"voxelize", garbage, "-o", dir + "/d.npy", "--no-cache"});
        QCOMPARE(r.code, 1);
        QVERIFY2(r.err.contains(garbage), qPrintable(r.err));
        r = runSylva({"light", "--density", missing, "--sun", "0,1,0", "-o", dir + "/l.npy"});
        QCOMPARE(r.code, 1);
        QVERIFY2(r.err.contains(missing), qPrintable(r.err));
        r = runSylva({"light", "--density", garbage, "--sun", "0,1,0", "-o", dir + "/l.npy"});
        QCOMPARE(r.code, 1);
        r = runSylva({"info", missing});
        QCOMPARE(r.code, 1);
        QVERIFY2(r.err.contains(missing), qPrintable(r.err));
        // Parameter values outside the stable region are bad input, refused with the bound named.
        r = runSylva({"light", "--density", garbage, "--sun", "0,1,0", "--sigma-a", "0.5", "--sigma-s", "0.8", "-o", dir + "/l.npy"});
        QCOMPARE(r.code, 1);
        QVERIFY2(r.err.contains("stability bound"), qPrintable(r.err));
        r = runSylva({"light", "--density", garbage, "--sun", "0,0,0", "-o", dir + "/l.npy"});
        QCOMPARE(r.code, 1);
        QVERIFY2(r.err.contains("sun"), qPrintable(r.err));
        // A device, pipe or other non-regular file is never replaced by an output (as root, renaming over
        // /dev/null replaced it). A FIFO of our own stands in for the device, so a regression cannot harm
        // the machine.
        const QString fifo = dir + "/fifo.obj";
        QFile::remove(fifo);
        QCOMPARE(::mkfifo(fifo.toLocal8Bit().constData(), 0600), 0);
        r = runSylva({"grow", "--triangles", "1000", "-o", fifo});
        QCOMPARE(r.code, 1);
        QVERIFY2(r.err.contains(fifo) && r.err.contains("not a regular file"), qPrintable(r.err));
        QVERIFY(QFileInfo(fifo).exists() && !QFileInfo(fifo).isFile());
        const QString gridFifo = dir + "/fifo.npy";   // light writes .npy or .vdb (another extension is a usage error)
        QFile::remove(gridFifo);
        QCOMPARE(::mkfifo(gridFifo.toLocal8Bit().constData(), 0600), 0);
        r = runSylva({"light", "--density", garbage, "--sun", "0,1,0", "-o", gridFifo});
        QCOMPARE(r.code, 1);
        QVERIFY(!QFileInfo(gridFifo).isFile());
        // Out-of-range density values are reported with the file's name.
        NpyArray bad;
        bad.shape = {4, 4, 4};
        bad.data.assign(64, -0.5f);
        const std::string badPath = (dir + "/negative.npy").toStdString();
        writeNpy(badPath, bad);
        r = runSylva({"light", "--density", QString::fromStdString(badPath), "--sun", "0,1,0", "--no-cache", "-o", dir + "/l.npy"});
        QCOMPARE(r.code, 1);
        QVERIFY2(r.err.contains(QString::fromStdString(badPath)) && r.err.contains("outside [0, 1]"), qPrintable(r.err));
    }

    // A small scene file renders to PNG and EXR at the size asked; sylva info reads it; a broken
    // scene is an error naming the file and the key, with exit code 1 and no output file.
    void renderSceneFile()
    {
        const QString dir = outDir() + "/render";
        QDir(dir).removeRecursively();
        QDir().mkpath(dir);
        const QString scene = dir + "/small.sylva.json";
        QFile f(scene);
        QVERIFY(f.open(QIODevice::WriteOnly));
        f.write(R"({"version": 1,
          "species": [{"name": "shrub", "grow": {"species": "shrub", "seed": 2, "triangles": 3000},
                       "lighting": {"grid": 16}}],
          "instances": [{"species": "shrub", "position": [0, 0, 0]}, {"species": "shrub", "position": [2, 0, 1], "rotation": 90}],
          "camera": {"position": [0, 1.5, -6], "target": [0, 0.8, 0], "fov": 40}})");
        f.close();
        const QString cache = dir + "/cache";
        Run r = runSylva({"render", scene, "--width", "48", "--height", "32", "-o", dir + "/small.png", "--quiet"}, cache);
        QVERIFY2(r.code == 0, qPrintable(r.err));
        QVERIFY(r.out.contains("rendered 48x32"));
        QVERIFY(QFileInfo(dir + "/small.png").size() > 100);
        r = runSylva({"render", scene, "--width", "40", "--height", "20", "--mode", "lb", "-o", dir + "/small.exr", "--quiet"}, cache);
        QVERIFY2(r.code == 0, qPrintable(r.err));
        QVERIFY(QFileInfo(dir + "/small.exr").exists());
        // A quality preset sets the species' grids: preview solves them at 32 nodes (the cache holds the
        // 16-node grids of the runs above and now a 32-node one too); --spp still overrides it.
        r = runSylva({"render", scene, "--quality", "preview", "--spp", "2", "--width", "40", "--height", "20", "-o", dir + "/preview.png"}, cache);
        QVERIFY2(r.code == 0, qPrintable(r.err));
        QVERIFY2(r.out.contains("2 spp"), qPrintable(r.out));
        r = runSylva({"info", scene});
        QCOMPARE(r.code, 0);
        QVERIFY2(r.out.contains("shrub"), qPrintable(r.out));

        const QString broken = dir + "/broken.sylva.json";
        QFile b(broken);
        QVERIFY(b.open(QIODevice::WriteOnly));
        b.write(R"({"version": 1, "species": [{"name": "s", "grow": {"species": "shrub"}}],
                    "instances": [{"species": "s", "position": [0, 0, 0], "scale": -1}]})");
        b.close();
        r = runSylva({"render", broken, "-o", dir + "/broken.png", "--quiet"}, cache);
        QCOMPARE(r.code, 1);
        QVERIFY2(r.err.contains("broken.sylva.json") && r.err.contains("scale"), qPrintable(r.err));
        QVERIFY(!QFileInfo::exists(dir + "/broken.png"));
        r = runSylva({"render", dir + "/missing.sylva.json", "--quiet"}, cache);
        QCOMPARE(r.code, 1);
        QVERIFY2(r.err.contains("missing.sylva.json"), qPrintable(r.err));
    }

    void growVoxelizeLightInfo()
    {
        const QString dir = outDir() + "/chain";
        const QString cache = outDir() + "/chain-cache";
        QDir(dir).removeRecursively();
        QDir(cache).removeRecursively();
        Run r = runSylva({"grow", "--species", "birch", "--triangles", "5000", "--seed", "3", "-o", dir + "/birch.obj"});
        QCOMPARE(r.code, 0);
        QVERIFY(QFile::exists(dir + "/birch.obj") && QFile::exists(dir + "/birch.mtl"));
        r = runSylva({"voxelize", dir + "/birch.obj", "--grid", "24", "-o", dir + "/d.npy", "--picture", dir + "/d.png"}, cache);
        QCOMPARE(r.code, 0);
        QVERIFY(QFile::exists(dir + "/d.npy") && QFile::exists(dir + "/d.npy.json") && QFile::exists(dir + "/d.png"));
        r = runSylva({"light", "--density", dir + "/d.npy", "--sun", "0.3,1,0.2", "-o", dir + "/l.npy", "--picture", dir + "/l.png"}, cache);
        QCOMPARE(r.code, 0);
        QVERIFY2(r.err.contains("light: done"), qPrintable(r.err));
        const LightingGrid light = readLightingGrid((dir + "/l.npy").toStdString());
        QCOMPARE(light.geometry.dims.y, 24);
        // The same job again is a cache hit.
        r = runSylva({"light", "--density", dir + "/d.npy", "--sun", "0.3,1,0.2", "-o", dir + "/l2.npy"}, cache);
        QCOMPARE(r.code, 0);
        QVERIFY2(r.err.contains("cache hit"), qPrintable(r.err));
        r = runSylva({"info", dir + "/l.npy"});
        QCOMPARE(r.code, 0);
        QVERIFY2(r.out.contains("shape (") && r.out.contains(", 3)"), qPrintable(r.out));
        r = runSylva({"info", dir + "/birch.obj"});
        QCOMPARE(r.code, 0);
        QVERIFY2(r.out.contains("leaf"), qPrintable(r.out));

        // sylva reference on the same density (and from the mesh, through the cache): the mean and
        // standard-error grids with sidecars, the LB grid compared; light never brighter than in
        // empty space by more than the noise allows.
        r = runSylva({"reference", "--density", dir + "/d.npy", "--sun", "0.3,1,0.2", "--paths", "40000", "-o", dir + "/ref.npy",
                      "--compare", dir + "/l.npy"},
                     cache);
        QVERIFY2(r.code == 0, qPrintable(r.err));
        QVERIFY(QFile::exists(dir + "/ref.npy") && QFile::exists(dir + "/ref.stderr.npy") && QFile::exists(dir + "/ref.npy.json"));
        QVERIFY2(r.out.contains("relative L2"), qPrintable(r.out));
        const LightingGrid ref = readLightingGrid((dir + "/ref.npy").toStdString());
        QCOMPARE(ref.geometry.dims, light.geometry.dims);
        r = runSylva({"reference", "--mesh", dir + "/birch.obj", "--grid", "24", "--sun", "0.3,1,0.2", "--paths", "20000", "-o",
                      dir + "/ref_mesh.npy"},
                     cache);
        QVERIFY2(r.code == 0, qPrintable(r.err));
        QVERIFY2(r.err.contains("voxelize (cache hit)"), qPrintable(r.err));
        QCOMPARE(readLightingGrid((dir + "/ref_mesh.npy").toStdString()).geometry.dims, light.geometry.dims);
        r = runSylva({"reference", "--density", dir + "/missing.npy", "--sun", "0,1,0", "-o", dir + "/ref_x.npy"});
        QCOMPARE(r.code, 1);
        QVERIFY2(r.err.contains("missing.npy"), qPrintable(r.err));
    }

    // An empty grid is empty space: the reference's fluence is the unobstructed value everywhere
    // (no path collides), so its mean over the interior is 1 within the estimator's noise (7% per
    // node here, ~0.4% for the mean of 336 nodes: 0.02 is 5 sigma).
    void referenceOfEmptyGridIsUnobstructed()
    {
        const QString dir = outDir() + "/reference";
        QDir().mkpath(dir);
        NpyArray d;
        d.shape = {10, 8, 9};
        d.data.assign(10 * 8 * 9, 0.0f);
        writeNpy((dir + "/empty.npy").toStdString(), d);
        const Run r = runSylva({"reference", "--density", dir + "/empty.npy", "--sun", "0.2,1,0.4", "--paths", "20000", "--no-cache",
                                "-o", dir + "/empty_ref.npy"});
        QVERIFY2(r.code == 0, qPrintable(r.err));
        QVERIFY2(r.out.contains("0.00 collisions per path"), qPrintable(r.out));
        const QRegularExpressionMatch m = QRegularExpression("mean RGB / unobstructed \\(([0-9.]+), ([0-9.]+), ([0-9.]+)\\)").match(r.out);
        QVERIFY2(m.hasMatch(), qPrintable(r.out));
        for (int c = 1; c <= 3; ++c) QVERIFY2(std::fabs(m.captured(c).toDouble() - 1.0) < 0.02, qPrintable(r.out));
    }

    void realTreeLightingLooksRight()
    {
        const QString tree = QString(SYLVA_RESOURCES) + "/trees/quaternius/OBJ_textured/Tree_1.obj";
        QVERIFY2(QFile::exists(tree), qPrintable(tree));
        const QString dir = outDir() + "/real";
        QDir().mkpath(dir);
        // Sun from +x and above: the +x side of the crown must be brighter than the -x side.
        Run r = runSylva({"voxelize", tree, "--grid", "48", "--no-cache", "-o", dir + "/tree1_density.npy"});
        QCOMPARE(r.code, 0);
        r = runSylva({"light", "--density", dir + "/tree1_density.npy", "--sun", "1,0.5,0", "--no-cache", "-o", dir + "/tree1.npy",
                      "--picture", dir + "/tree1.png"});
        QCOMPARE(r.code, 0);
        const LightingGrid light = readLightingGrid((dir + "/tree1.npy").toStdString());
        const DensityGrid density = readDensityGrid((dir + "/tree1_density.npy").toStdString());
        // Inside the crown (nodes with medium) light is dimmer than in open space (a boundary node).
        double inside = 0;
        size_t insideCount = 0;
        for (size_t node = 0; node < density.density.size(); ++node)
            if (density.density[node] > 0.3f) inside += light.rgb[node * 3 + 1], ++insideCount;
        QVERIFY(insideCount > 100);
        inside /= double(insideCount);
        const double open = light.at(0, 0, 0, 1);
        qInfo("mean green inside the crown %.3f, in open space %.3f", inside, open);
        QVERIFY(inside < 0.9 * open);
        const glm::ivec3 n = light.geometry.dims;
        double lit = 0, shaded = 0, sumG = 0, sumR = 0, sumB = 0;
        size_t litCount = 0, shadedCount = 0;
        for (int i = 1; i < n.x - 1; ++i)
            for (int j = 1; j < n.y - 1; ++j)
                for (int k = 1; k < n.z - 1; ++k) {
                    const double g = light.at(i, j, k, 1);
                    if (i > n.x * 2 / 3) lit += g, ++litCount;
                    if (i < n.x / 3) shaded += g, ++shadedCount;
                    sumR += light.at(i, j, k, 0);
                    sumG += g;
                    sumB += light.at(i, j, k, 2);
                }
        lit /= double(litCount);
        shaded /= double(shadedCount);
        qInfo("mean green: lit third %.3f, shaded third %.3f; interior sums R %.1f G %.1f B %.1f", lit, shaded, sumR, sumG, sumB);
        QVERIFY(lit > shaded * 1.05);
        QVERIFY(sumG > sumR && sumG > sumB);
    }
};

QTEST_GUILESS_MAIN(TestCli)
#include "tst_cli.moc"
