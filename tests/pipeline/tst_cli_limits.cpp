// `sylva light` at the edges of the stable region (issue 6, item 4): values outside it are refused
// (exit 1, or 2 for text that is no number) with a message naming the parameter and its bound;
// values exactly on the bounds run and give a finite, non-negative grid.
#include <QDir>
#include <QElapsedTimer>
#include <QFile>
#include <QProcess>
#include <QTest>

#include <cmath>

#include "core/grid/grid.h"
#include "pipeline/io/npy.h"

using namespace sylva;

namespace {

struct Run {
    int code = -1;
    QString out, err;
};

Run runSylva(const QStringList& args)
{
    QProcess p;
    p.start(SYLVA_CLI_PATH, args);
    p.waitForFinished(600000);
    return {p.exitStatus() == QProcess::NormalExit ? p.exitCode() : -1, QString::fromUtf8(p.readAllStandardOutput()),
            QString::fromUtf8(p.readAllStandardError())};
}

} // namespace

class TestCliLimits : public QObject {
    Q_OBJECT

    QString m_dir, m_density;

private Q_SLOTS:
    void initTestCase()
    {
        m_dir = QString(SYLVA_TEST_OUTPUT) + "/cli_limits";
        QDir(m_dir).removeRecursively();
        QDir().mkpath(m_dir);
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

    // `sylva render` of a frame too large for the machine's memory (32768 x 32768, the largest size it
    // takes: ~56 GB of film) fails at once with exit 1 and the memory named, writing nothing.
    void renderTooLargeIsRefused()
    {
        QFile f("/proc/meminfo");
        QVERIFY(f.open(QIODevice::ReadOnly));
        double available = 0.0;
        for (const QByteArray& line : f.readAll().split('\n'))
            if (line.startsWith("MemAvailable:")) available = line.mid(13).trimmed().split(' ').value(0).toDouble() * 1024.0;
        if (available > 0.8 * 52.0 * 32768.0 * 32768.0) QSKIP("this machine could render it");
        const QString out = m_dir + "/huge.png";
        QElapsedTimer t;
        t.start();
        const Run r = runSylva({"render", "--width", "32768", "--height", "32768", "--quiet", "-o", out});
        QVERIFY2(r.code == 1, qPrintable(r.err));
        QVERIFY2(r.err.contains("32768x32768") && r.err.contains("GB of memory is available"), qPrintable(r.err));
        QVERIFY(!QFile::exists(out));
        QVERIFY2(t.elapsed() < 20000, "the refusal came after the work");
    }
};

QTEST_GUILESS_MAIN(TestCliLimits)
#include "tst_cli_limits.moc"
