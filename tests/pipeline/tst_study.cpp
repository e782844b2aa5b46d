// `sylva study lb --quick` end to end (CI smoke test, label slow): the report, its kept sections, the plots or
// the note that they were skipped, and `sylva study report` from the stored numbers.
#include <QDir>
#include <QFile>
#include <QProcess>
#include <QStandardPaths>
#include <QTemporaryDir>
#include <QTest>

namespace {

struct Run {
    int code = -1;
    QString out, err;
};

Run sylva(const QStringList& args, const QProcessEnvironment& env = QProcessEnvironment::systemEnvironment())
{
    QProcess p;
    p.setProcessEnvironment(env);
    p.start(SYLVA_CLI_PATH, args);
    Run r;
    if (!p.waitForFinished(1500 * 1000)) {
        p.kill();
        p.waitForFinished();
        r.err = "timed out";
        return r;
    }
    r.code = p.exitStatus() == QProcess::NormalExit ? p.exitCode() : -1;
    r.out = QString::fromUtf8(p.readAllStandardOutput());
    r.err = QString::fromUtf8(p.readAllStandardError());
    return r;
}

QString readAll(const QString& path)
{
    QFile f(path);
    if (!f.open(QIODevice::ReadOnly)) return {};
    return QString::fromUtf8(f.readAll());
}

} // namespace

class TestStudy : public QObject {
    Q_OBJECT

private Q_SLOTS:
    void quickLbStudy()
    {
        QTemporaryDir dir;
        QVERIFY(dir.isValid());
        // A hand-written section of an existing report survives the regeneration.
        {
            QFile f(dir.filePath("ACCURACY.md"));
            QVERIFY(f.open(QIODevice::WriteOnly));
            f.write("# Accuracy\n\nold intro\n\n## Normalization\n\nKept text 4711.\n\n## Old generated section\n\nold numbers\n");
        }
        const Run r = sylva({"study", "lb", "--quick", "--out", dir.path()});
        QVERIFY2(r.code == 0, qPrintable(r.err + r.out));
        const QString md = readAll(dir.filePath("ACCURACY.md"));
        QVERIFY(md.startsWith("# Accuracy\n"));
        QVERIFY(md.contains("## Normalization\n\nKept text 4711.\n"));
        QVERIFY(!md.contains("old numbers"));
        QVERIFY(md.contains("## LB lighting: grid, steps and storage against the reference"));
        QVERIFY(md.contains("Pareto front"));
        QVERIFY(md.contains("**default**"));
        QVERIFY(md.contains("| 32 |"));
        QVERIFY(md.contains("| 64 |"));
        QVERIFY(md.contains("## Quality presets"));
        QVERIFY(md.contains("sylva study voxel"));   // the parts not measured say how to measure them
        QVERIFY(QFile::exists(dir.filePath("accuracy/lb.json")));
        if (!QStandardPaths::findExecutable("gnuplot").isEmpty()) {
            const QStringList pngs = QDir(dir.filePath("accuracy")).entryList({"*.png"});
            QVERIFY2(!pngs.isEmpty(), qPrintable(r.out));
            QFile png(dir.filePath("accuracy/" + pngs.first()));
            QVERIFY(png.open(QIODevice::ReadOnly));
            QVERIFY(png.read(8) == QByteArray("\x89PNG\r\n\x1a\n", 8));
            QVERIFY(md.contains("](accuracy/lb_"));
            QVERIFY(!md.contains("Plots: skipped"));
        } else {
            QVERIFY(md.contains("Plots: skipped"));
            QVERIFY(r.out.contains("plots skipped"));
        }

        // Regenerating from the stored numbers without gnuplot: the tables stay, the plots are skipped and said so.
        QProcessEnvironment env = QProcessEnvironment::systemEnvironment();
        env.insert("SYLVA_GNUPLOT", dir.filePath("no-such-gnuplot"));
        const Run again = sylva({"study", "report", "--out", dir.path()}, env);
        QVERIFY2(again.code == 0, qPrintable(again.err + again.out));
        const QString md2 = readAll(dir.filePath("ACCURACY.md"));
        QVERIFY(md2.contains("Kept text 4711."));
        QVERIFY(md2.contains("| 64 |"));
        QVERIFY(md2.contains("Plots: skipped"));
        QVERIFY(again.out.contains("plots skipped"));

        // Bad usage.
        QCOMPARE(sylva({"study", "everything"}).code, 2);
    }
};

QTEST_GUILESS_MAIN(TestStudy)
#include "tst_study.moc"
