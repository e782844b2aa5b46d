// `sylva study lb --quick` end to end (CI smoke test, label slow): the report, its kept sections, the plots or
// the note that they were skipped, and `sylva study report` from the stored numbers; `sylva study scene --quick`;
// `sylva study sky --quick`.
#include <QDir>
#include <QFile>
#include <QJsonArray>
#include <QJsonDocument>
#include <QJsonObject>
#include <QProcess>
#include <QStandardPaths>
#include <QTemporaryDir>
#include <QTest>

#include <cmath>
#include <map>
#include <tuple>

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

    // `sylva study scene --quick`: the forest-level grid against per-instance solves on a stand, and the
    // relighting basis against direct solves. What must hold whatever the numbers: the reference is sound
    // (a lone tree alone in its domain equals its species grid), the stand's interior is darker than its
    // edge in the reference and with the forest grid, the forest grid at 32 moves the factors and the
    // picture towards the reference, and relighting equals a direct solve to float (fp32) or fp16 rounding.
    void quickSceneStudy()
    {
        QTemporaryDir dir;
        QVERIFY(dir.isValid());
        const Run r = sylva({"study", "scene", "--quick", "--out", dir.path()});
        QVERIFY2(r.code == 0, qPrintable(r.err + r.out));
        const QString md = readAll(dir.filePath("ACCURACY.md"));
        QVERIFY(md.contains("## Scene scale: the forest-level grid and the relighting basis"));
        QVERIFY(md.contains("**default** resolution"));
        QVERIFY(md.contains("sylva study lb"));   // the LB part, not measured here, says how to measure it
        for (const char* png : {"scene_stand_reference.png", "scene_stand_off.png", "scene_stand_default.png"}) {
            QFile f(dir.filePath(QString("accuracy/") + png));
            QVERIFY2(f.open(QIODevice::ReadOnly), png);
            QVERIFY(f.read(8) == QByteArray("\x89PNG\r\n\x1a\n", 8));
        }
        QFile json(dir.filePath("accuracy/scene.json"));
        QVERIFY(json.open(QIODevice::ReadOnly));
        const QJsonObject d = QJsonDocument::fromJson(json.readAll()).object();
        QVERIFY2(d.value("floor_err").toDouble() < 1e-2, qPrintable(QString::number(d.value("floor_err").toDouble())));
        const double refInterior = d.value("reference_interior").toDouble(), refEdge = d.value("reference_edge").toDouble();
        QVERIFY(refInterior > 0.3 && refInterior < refEdge && refEdge < 1.0);
        QVERIFY(d.value("isolated_factor").toDouble() > 0.98);   // no tree shades the lone one (its neighbours light it)
        QJsonObject off, at32;
        for (const QJsonValue& v : d.value("forest").toArray()) {
            const QJsonObject row = v.toObject();
            if (row.value("resolution").toInt() == 0) off = row;
            if (row.value("resolution").toInt() == 32) at32 = row;
        }
        QVERIFY(!off.isEmpty() && !at32.isEmpty());
        QCOMPARE(off.value("interior").toDouble(), 1.0);
        QVERIFY(at32.value("interior").toDouble() < at32.value("edge").toDouble());
        QVERIFY(std::fabs(at32.value("interior").toDouble() - refInterior) < 0.05);
        QVERIFY(at32.value("factor_rms").toDouble() < 0.5 * off.value("factor_rms").toDouble());
        QVERIFY(at32.value("image_err").toDouble() < off.value("image_err").toDouble());
        int storages = 0;
        for (const QJsonValue& v : d.value("basis").toArray()) {
            const QJsonObject row = v.toObject();
            QCOMPARE(row.value("directions").toInt(), 18);
            QVERIFY(row.value("err_max").toDouble() < (row.value("fp16").toBool() ? 1e-3 : 1e-5));
            QVERIFY(row.value("relight_ms").toDouble() > 0.0);
            ++storages;
        }
        QCOMPARE(storages, 2);
    }

    // `sylva study sky --quick`: N lights x K subsets x spp on the default forest under a Preetham sky, and
    // the LB with the sky in its boundary against Monte Carlo. What must hold whatever the numbers: errors
    // finite in [0, 1); interleaved subsets cycled over more samples come closer to all the lights; the LB
    // stays near the reference with the sky in its boundary as with the sun alone; the sky adds light in
    // open space.
    void quickSkyStudy()
    {
        QTemporaryDir dir;
        QVERIFY(dir.isValid());
        const Run r = sylva({"study", "sky", "--quick", "--out", dir.path()});
        QVERIFY2(r.code == 0, qPrintable(r.err + r.out));
        const QString md = readAll(dir.filePath("ACCURACY.md"));
        QVERIFY(md.contains("## Sky light: virtual lights, interleaving and samples"));
        QVERIFY(md.contains("### Preetham"));
        QVERIFY(md.contains("sylva study lb"));   // the parts not measured say how to measure them
        std::map<std::tuple<int, int, int>, double> lightErr;
        std::map<QString, std::pair<double, double>> lbRows;   // boundary -> (error against Monte Carlo, open-space value)
        for (const QString& line : md.split('\n')) {
            QStringList cells = line.split('|');
            for (QString& c : cells) c = c.trimmed().remove('*');
            if (cells.size() == 11 && cells[1].toInt() > 0 && cells[3].toInt() > 0) {
                const double le = cells[7].toDouble(), e = cells[8].toDouble(), ratio = cells[6].toDouble();
                QVERIFY2(std::isfinite(le) && le >= 0.0 && le < 1.0 && e >= 0.0 && e < 1.0 && ratio > 0.0, qPrintable(line));
                lightErr[{cells[1].toInt(), cells[2].toInt(), cells[3].toInt()}] = le;
            }
            if (cells.size() == 6 && (cells[1] == "sun" || cells[1] == "sun_sky")) lbRows[cells[1]] = {cells[2].toDouble(), cells[4].toDouble()};
        }
        QCOMPARE(lightErr.size(), size_t(6));
        const double at4 = lightErr[std::make_tuple(64, 8, 4)], at1 = lightErr[std::make_tuple(64, 8, 1)];
        QVERIFY2(at4 < at1, qPrintable(QString("%1 vs %2").arg(at4).arg(at1)));
        QVERIFY(lightErr[std::make_tuple(16, 1, 1)] > 0.0);
        QCOMPARE(lbRows.size(), size_t(2));
        for (const auto& [name, row] : lbRows) QVERIFY2(row.first > 0.0 && row.first < 0.6, qPrintable(name + ": " + QString::number(row.first)));
        QVERIFY(lbRows["sun_sky"].second > lbRows["sun"].second);
    }
};

QTEST_GUILESS_MAIN(TestStudy)
#include "tst_study.moc"
