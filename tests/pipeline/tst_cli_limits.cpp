// `sylva light` at the edges of the stable region: values outside it are refused
// (exit 1, or 2 for text that is no number) with a message naming the parameter and its bound;
// values exactly on the bounds run and give a finite, non-negative grid. A frame larger than the memory
// renders in bands, the same picture as the whole frame.
#include <QDir>
#include <QFile>
#include <QProcessEnvironment>
#include <QProcess>
#include <QTest>

#include <algorithm>
#include <cmath>

#include "core/grid/grid.h"
#include "pipeline/io/image_io.h"
#include "pipeline/io/npy.h"
#include "tests/common/files.h"
#include "tests/common/run_program.h"

using namespace sylva;

namespace {

using test::Run;
using test::runSylva;

} // namespace

class TestCliLimits : public QObject {
    Q_OBJECT

    QString m_dir, m_density;

private Q_SLOTS:
    void initTestCase()
    {
        m_dir = test::outputDir("cli_limits");
        // A valid 6x5x7 density grid, half full: the refusals below are about the parameters alone.
        NpyArray d;
        d.shape = {6, 5, 7};
        d.data.resize(6 * 5 * 7);
        for (size_t i = 0; i < d.data.size(); ++i) d.data[i] = (i % 3 == 0) ? 1.0f : (i % 3 == 1 ? 0.0f : 0.37f);
        m_density = m_dir + "/density.npy";
        writeNpy(m_density.toStdString(), d);
    }

    void outsideStableRegionIsRefused_data()
    {
        QTest::addColumn<QStringList>("options");
        QTest::addColumn<int>("code");
        QTest::addColumn<QStringList>("mentions");
        QTest::newRow("sigma_s 2") << QStringList{"--sigma-s", "2"} << 1 << QStringList{"sigma_t", "stability bound 1"};
        QTest::newRow("sigma_t 1 + 1e-7") << QStringList{"--sigma-a", "0.5", "--sigma-s", "0.5000001"} << 1 << QStringList{"sigma_t", "stability bound 1"};
        QTest::newRow("sigma_a just above 1") << QStringList{"--sigma-a", "1.0000001", "--sigma-s", "0"} << 1 << QStringList{"stability bound 1"};
        QTest::newRow("sigma_t in one channel") << QStringList{"--sigma-a", "0.1,0.1,0.6", "--sigma-s", "0.9,0.9,0.5"} << 1
                                                << QStringList{"channel B", "stability bound 1"};
        QTest::newRow("negative sigma_a") << QStringList{"--sigma-a", "-0.1"} << 1 << QStringList{"sigma_a", ">= 0"};
        QTest::newRow("negative sigma_s") << QStringList{"--sigma-s", "-1e-9"} << 1 << QStringList{"sigma_s", ">= 0"};
        QTest::newRow("g 1.5") << QStringList{"--g", "1.5"} << 1 << QStringList{"g = 1.5", "[-1, 1]"};
        QTest::newRow("g just below -1") << QStringList{"--g", "-1.0000001"} << 1 << QStringList{"[-1, 1]"};
        QTest::newRow("sigma_s overflows float") << QStringList{"--sigma-s", "1e39"} << 1 << QStringList{"sigma_s"};
        QTest::newRow("NaN sigma_s") << QStringList{"--sigma-s", "nan"} << 2 << QStringList{"--sigma-s", "not a finite number"};
        QTest::newRow("NaN g") << QStringList{"--g", "0,NaN,0"} << 2 << QStringList{"--g", "not a finite number"};
        QTest::newRow("inf sigma_a") << QStringList{"--sigma-a", "inf"} << 2 << QStringList{"--sigma-a", "not a finite number"};
        QTest::newRow("fp16 intensity") << QStringList{"--fp16", "--intensity", "1e5"} << 1 << QStringList{"fp16", "fp32"};
    }
    void outsideStableRegionIsRefused()
    {
        QFETCH(QStringList, options);
        QFETCH(int, code);
        QFETCH(QStringList, mentions);
        const QString out = m_dir + "/refused.npy";
        const Run r = runSylva(QStringList{"light", "--density", m_density, "--sun", "0.3,1,0.2", "--no-cache", "-o", out} + options);
        QVERIFY2(r.code == code, qPrintable(QString("exit %1, expected %2: %3").arg(r.code).arg(code).arg(r.err)));
        for (const QString& m : mentions) QVERIFY2(r.err.contains(m), qPrintable(QString("'%1' not in: %2").arg(m, r.err)));
        QVERIFY(!QFile::exists(out));
    }

    // Exactly on the bounds: sigma_a + sigma_s = 1, g = -1 and 1, sigma_a = 0 and 1, grazing sun, fp16.
    void boundsRun_data()
    {
        QTest::addColumn<QStringList>("options");
        QTest::newRow("scatter only, g -1,0,1") << QStringList{"--sigma-a", "0", "--sigma-s", "1", "--g", "-1,0,1", "--keep-f0"};
        QTest::newRow("absorb only") << QStringList{"--sigma-a", "1", "--sigma-s", "0", "--g", "1"};
        QTest::newRow("decimal sum 1, g near 1") << QStringList{"--sigma-a", "0.118,0.6,0.3", "--sigma-s", "0.882,0.4,0.7", "--g", "0.999999,-0.999999,0"};
        QTest::newRow("fp16 at the bound") << QStringList{"--sigma-a", "1e-7", "--sigma-s", "0.9999999", "--g", "-1", "--fp16", "--keep-f0"};
    }
    void boundsRun()
    {
        QFETCH(QStringList, options);
        const QString out = m_dir + "/bound.npy";
        QFile::remove(out);
        const Run r = runSylva(QStringList{"light", "--density", m_density, "--sun", "1,0.0002,0.3", "--no-cache", "--quiet", "-o", out} + options);
        QVERIFY2(r.code == 0, qPrintable(r.err));
        const LightingGrid g = readLightingGrid(out.toStdString());
        QCOMPARE(g.rgb.size(), size_t(6 * 5 * 7 * 3));
        for (float v : g.rgb) QVERIFY2(std::isfinite(v) && v >= 0.0f, qPrintable(QString::number(double(v))));
    }

    // A frame too large for the memory (here: SYLVA_MEMORY_LIMIT_MB makes the machine small) is traced
    // and written in bands instead of refused, and the picture is the whole-frame one, pixel for pixel,
    // in every output kind and in ambient mode (whose constant needs the whole frame); --band-rows
    // forces bands of any height.
    void renderTooLargeGoesInBands()
    {
        const QString dir = m_dir + "/bands";
        QDir().mkpath(dir);
        const QString scene = dir + "/small.sylva.json";
        QFile f(scene);
        QVERIFY(f.open(QIODevice::WriteOnly));
        f.write(R"({"version": 1,
          "species": [{"name": "shrub", "grow": {"species": "shrub", "seed": 2, "triangles": 3000}, "lighting": {"grid": 16}}],
          "instances": [{"species": "shrub", "position": [0, 0, 0]}, {"species": "shrub", "position": [2, 0, 1], "rotation": 90}],
          "camera": {"position": [0, 1.5, -6], "target": [0, 0.8, 0], "fov": 40}})");
        f.close();
        const QString cache = dir + "/cache";
        struct Case {
            QString mode, ext;
            QStringList extra;
        };
        for (const Case& c : {Case{"full", "png", {}}, Case{"ambient", "png", {}}, Case{"ambient", "exr", {}},
                              Case{"lb", "tif", {"--band-rows", "7"}}}) {
            const QString whole = dir + "/whole_" + c.mode + "." + c.ext, banded = dir + "/banded_" + c.mode + "." + c.ext;
            const QStringList common{"render", scene, "--width", "320", "--height", "200", "--mode", c.mode, "--quiet", "--cache", cache};
            Run r = runSylva(common + QStringList{"-o", whole});
            QVERIFY2(r.code == 0, qPrintable(r.err));
            QVERIFY2(!r.err.contains("bands"), qPrintable(r.err));
            // 320x200 x 68 B = 4.4 MB of film does not fit in 80% of 2 MB; the grids come from the cache.
            // Bands: a quarter of 2 MB over 320 x (56 B of film + 24 B of pictures) per row = 20 rows, 16 in 8s.
            QProcessEnvironment env = QProcessEnvironment::systemEnvironment();
            if (c.extra.isEmpty()) env.insert("SYLVA_MEMORY_LIMIT_MB", "2");
            const Run bandedRun = test::runProgram(SYLVA_CLI_PATH, common + c.extra + QStringList{"-o", banded}, env);
            const QString& err = bandedRun.err;
            QVERIFY2(bandedRun.code == 0, qPrintable(err));
            QVERIFY2(err.contains(c.extra.isEmpty() ? "in 13 bands of 16 rows (the whole frame does not fit" : "in 29 bands of 7 rows"),
                     qPrintable(err));
            const ImageRgba a = readImage(whole.toStdString()), b = readImage(banded.toStdString());
            QCOMPARE(b.width, 320);
            QCOMPARE(b.height, 200);
            QVERIFY(a.pixels == b.pixels);
            float maxValue = 0.0f;
            for (float v : a.pixels) maxValue = std::max(maxValue, v);
            QVERIFY(maxValue > 0.05f);   // not two black pictures
        }
        QVERIFY(QDir(dir).entryList(QStringList{".sylva-bands-*"}, QDir::Hidden | QDir::Files).isEmpty());
    }
};

QTEST_GUILESS_MAIN(TestCliLimits)
#include "tst_cli_limits.moc"
