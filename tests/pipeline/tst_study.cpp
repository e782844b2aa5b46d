// `sylva study lb --quick` end to end (label slow: minutes): the numbers it measures (lb.json: every error
// finite, at least its reference's noise and below the LB's documented error; fp16 = fp32; a finer grid
// closer to the finest reference for the trees; the step counts each mode implies), the report, its kept
// sections, the plots or the note that they were skipped, and `sylva study report` from the stored numbers;
// `sylva study scene --quick`; `sylva study sky --quick`.
#include <QDir>
#include <QFile>
#include <QJsonArray>
#include <QJsonDocument>
#include <QJsonObject>
#include <QProcess>
#include <QStandardPaths>
#include <QTemporaryDir>
#include <QTest>

#include <algorithm>
#include <cmath>
#include <map>
#include <tuple>

#include "tests/common/files.h"
#include "tests/common/run_program.h"

namespace {

using sylva::test::readText;
using sylva::test::Run;

// `sylva ARGS`, with minutes to finish.
Run runStudy(const QStringList& args, const QProcessEnvironment& env = QProcessEnvironment::systemEnvironment())
{
    return sylva::test::runProgram(SYLVA_CLI_PATH, args, env, 1500 * 1000);
}

} // namespace

class TestStudy : public QObject {
    Q_OBJECT

    // What `sylva study lb --quick` measured (accuracy/lb.json), against what its own setup implies:
    // - each reference's noise (relative standard error over the interior) is positive and small, and an
    //   LB error measured against it is at least that noise (the noise adds in quadrature: e^2 = lb^2 +
    //   noise^2; 0.9 of it leaves room for the sampling of that sum over the nodes);
    // - every error is finite and below 0.12: the full study's largest same-grid error is 0.074 and its
    //   largest error against the finest grid 0.111 (docs/ACCURACY.md); the quick references' noise
    //   (a quarter of the paths: twice the full study's, ~0.02-0.03) adds to that in quadrature;
    // - fp16 storage changes an error by less than 1e-3 (the full study: at most 2.6e-4);
    // - for the two trees, the 64-node grid is closer to the finest (64) reference than the 32-node grid
    //   sampled at its nodes, in every steps mode and storage (the crown's detail is resolved better;
    //   the full study: 0.110 -> 0.085 and 0.111 -> 0.088);
    // - the steps run: `default` = 2 x the longest edge, `half` = the longest edge, the tolerances at
    //   most 4 x the longest edge, 1e-4 at least as many as 1e-3;
    // - exactly one row per case is the product's default, the one `default_config` names.
    void checkLbNumbers(const QString& path)
    {
        QFile f(path);
        QVERIFY(f.open(QIODevice::ReadOnly));
        const QJsonObject root = QJsonDocument::fromJson(f.readAll()).object();
        const QString defaultConfig = root.value("default_config").toString();
        QVERIFY2(defaultConfig.startsWith("grid "), qPrintable(defaultConfig));
        int casesRun = 0;
        for (const QJsonValue& cv : root.value("cases").toArray()) {
            const QJsonObject c = cv.toObject();
            const QString name = c.value("name").toString();
            // The real tree's mesh is in the repository (resources/trees): no case may be skipped.
            QVERIFY2(c.value("skipped").toString().isEmpty(), qPrintable(name + ": " + c.value("skipped").toString()));
            ++casesRun;
            QCOMPARE(c.value("fine_grid").toInt(), 64);
            std::map<int, double> noise;
            for (const QJsonValue& rv : c.value("references").toArray()) {
                const QJsonObject r = rv.toObject();
                const double n = r.value("noise").toDouble();
                QVERIFY2(n > 0.0 && n < 0.05, qPrintable(name + QString(": reference noise %1").arg(n)));
                noise[r.value("grid").toInt()] = n;
            }
            QCOMPARE(noise.size(), size_t(2));
            // (grid, steps, fp16) -> row
            std::map<std::tuple<int, QString, bool>, QJsonObject> rows;
            int defaults = 0;
            for (const QJsonValue& rv : c.value("rows").toArray()) {
                const QJsonObject r = rv.toObject();
                const int grid = r.value("grid").toInt();
                const QString steps = r.value("steps").toString();
                const bool fp16 = r.value("fp16").toBool();
                const QString what = QString("%1 grid %2 %3 %4").arg(name).arg(grid).arg(steps, fp16 ? "fp16" : "fp32");
                rows[{grid, steps, fp16}] = r;
                const double same = r.value("err_same").toDouble(), fine = r.value("err_fine").toDouble();
                QVERIFY2(std::isfinite(same) && std::isfinite(fine), qPrintable(what));
                QVERIFY2(same >= 0.9 * noise[grid] && same < 0.12, qPrintable(what + QString(": error %1, noise %2").arg(same).arg(noise[grid])));
                QVERIFY2(fine >= 0.9 * noise[64] && fine < 0.12, qPrintable(what + QString(": error vs 64 %1").arg(fine)));
                if (grid == 64) QCOMPARE(fine, same);   // the finest grid is its own reference
                // Steps: the longest edge of the run's grid from its dims ("25x32x25").
                int longest = 0;
                for (const QString& d : r.value("dims").toString().split('x')) longest = std::max(longest, d.toInt());
                QCOMPARE(longest, grid);
                const int taken = r.value("steps_taken").toInt();
                if (steps == "default") QCOMPARE(taken, 2 * longest);
                else if (steps == "half") QCOMPARE(taken, longest);
                else QVERIFY2(taken > 0 && taken <= 4 * longest, qPrintable(what + QString(": %1 steps").arg(taken)));
                if (r.value("default").toBool()) {
                    ++defaults;
                    QVERIFY2(defaultConfig == QString("grid %1, %2, %3").arg(grid).arg(steps, fp16 ? "fp16" : "fp32"), qPrintable(what));
                }
            }
            QCOMPARE(rows.size(), size_t(2 * 4 * 2));   // grids 32 and 64, four steps modes, two storages
            QCOMPARE(defaults, 1);
            for (int grid : {32, 64})
                for (const QString steps : {"default", "half", "tol 1e-3", "tol 1e-4"}) {
                    const QJsonObject a = rows[{grid, steps, false}], b = rows[{grid, steps, true}];
                    const double d = std::fabs(a.value("err_fine").toDouble() - b.value("err_fine").toDouble());
                    QVERIFY2(d < 1e-3, qPrintable(QString("%1 grid %2 %3: fp16 moves the error by %4").arg(name).arg(grid).arg(steps).arg(d)));
                    if (grid == 32 && name != "cloud") {
                        const double coarse = a.value("err_fine").toDouble(), finer = rows[{64, steps, false}].value("err_fine").toDouble();
                        QVERIFY2(finer < coarse, qPrintable(QString("%1 %2: 64 nodes %3, 32 nodes %4 against the 64 reference")
                                                                .arg(name, steps).arg(finer).arg(coarse)));
                    }
                }
            for (int grid : {32, 64})
                for (bool fp16 : {false, true}) {
                    const int tight = rows[{grid, "tol 1e-4", fp16}].value("steps_taken").toInt();
                    const int loose = rows[{grid, "tol 1e-3", fp16}].value("steps_taken").toInt();
                    QVERIFY2(tight >= loose, qPrintable(QString("%1 grid %2: tol 1e-4 %3 steps, tol 1e-3 %4").arg(name).arg(grid).arg(tight).arg(loose)));
                }
        }
        QVERIFY(casesRun >= 3);
    }

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
        const Run r = runStudy({"study", "lb", "--quick", "--out", dir.path()});
        QVERIFY2(r.code == 0, qPrintable(r.err + r.out));
        const QString md = readText(dir.filePath("ACCURACY.md"));
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
        checkLbNumbers(dir.filePath("accuracy/lb.json"));
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
        const Run again = runStudy({"study", "report", "--out", dir.path()}, env);
        QVERIFY2(again.code == 0, qPrintable(again.err + again.out));
        const QString md2 = readText(dir.filePath("ACCURACY.md"));
        QVERIFY(md2.contains("Kept text 4711."));
        QVERIFY(md2.contains("| 64 |"));
        QVERIFY(md2.contains("Plots: skipped"));
        QVERIFY(again.out.contains("plots skipped"));

        // Bad usage.
        QCOMPARE(runStudy({"study", "everything"}).code, 2);
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
        const Run r = runStudy({"study", "scene", "--quick", "--out", dir.path()});
        QVERIFY2(r.code == 0, qPrintable(r.err + r.out));
        const QString md = readText(dir.filePath("ACCURACY.md"));
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
        const Run r = runStudy({"study", "sky", "--quick", "--out", dir.path()});
        QVERIFY2(r.code == 0, qPrintable(r.err + r.out));
        const QString md = readText(dir.filePath("ACCURACY.md"));
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
