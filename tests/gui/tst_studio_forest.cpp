// The studio on the bundled default forest (5 grown species, 962 instances) under Xvfb: automatic
// lighting grows and lights the species (32-node grids), the viewport draws the forest, and after a camera move the
// first image of a 640x360 viewport arrives quickly (the frame's species BVHs are kept).
#include <QAction>
#include <QSignalSpy>

#include <memory>

#include "studio_test_util.h"

using namespace sylva;
using namespace sylva::test;

class TstStudioForest : public QObject {
    Q_OBJECT

    QTemporaryDir m_dir;

private Q_SLOTS:
    void initTestCase()
    {
        SYLVA_SKIP_WITHOUT_X();
        isolate(m_dir);
        // The forest's grids are the main job's: share the build's cache instead of a fresh one.
        qputenv("XDG_CACHE_HOME", qgetenv("SYLVA_FOREST_CACHE"));
    }

    void defaultForest()
    {
        MainWindow win;
        QStringList errors;
        win.setErrorReporter([&](const QString&, const QString& m) { errors << m; });
        win.setSavePrompt([](const QString&) { return QMessageBox::Discard; });
        win.show();
        Viewport* v = win.viewport();
        v->setFixedSize(640, 360);
        QVERIFY(QTest::qWaitForWindowExposed(&win));
        QSignalSpy lit(win.lighting(), &LightingScheduler::lightingFinished);
        win.loadExampleForest();
        QCOMPARE(win.document()->scene().instances.size(), size_t(962));
        // 32-node grids instead of 64 keep a first run (fresh cache) short; render time does not
        // depend on the grid size. The edit lands before automatic lighting starts.
        Scene s = win.document()->scene();
        for (SpeciesDesc& sp : s.species) sp.grid = 32;
        win.document()->edit(s, "grid 32");
        // Orbiting while the species are lit does not restart the job.
        QVERIFY(QTest::qWaitFor([&] { return win.jobs()->isBusy(); }, 5000));
        QTest::mousePress(v, Qt::LeftButton, {}, v->rect().center());
        QTest::mouseRelease(v, Qt::LeftButton, {}, v->rect().center() + QPoint(20, 0));
        QTest::qWait(400);   // past the automatic-lighting delay
        // The lighting may already be done (a warm cache loads in well under the wait above): wait for its
        // one signal whether or not it has come yet (QSignalSpy::wait waits for the next one only).
        QTRY_VERIFY_WITH_TIMEOUT(lit.count() >= 1, 300000);
        QCOMPARE(lit.count(), 1);
        QVERIFY(lit.last().at(0).toBool());
        QVERIFY2(!win.logText().contains("cancelled"), qPrintable(win.logText()));
        QVERIFY(waitForFinalImage(v, 120000));
        QVERIFY2(errors.isEmpty(), qPrintable(errors.join('\n')));
        QCOMPARE(v->lastImage().size(), QSize(640, 360));
        double mean = 0.0, sd = 0.0;
        lumaStats(v->lastImage(), &mean, &sd);
        QVERIFY(sd > 8.0);
        v->lastImage().save(QString(SYLVA_TEST_OUTPUT) + "/gui_default_forest.png");

        // Orbit a little, several times: the first image after each move (each move restarts the frame).
        double worst = 0.0, sum = 0.0;
        const int moves = 4;
        for (int m = 0; m < moves; ++m) {
            QSignalSpy shown(v, &Viewport::imageShown);
            const QPoint c = v->rect().center();
            QTest::mousePress(v, Qt::LeftButton, {}, c);
            QTest::mouseRelease(v, Qt::LeftButton, {}, c + QPoint(15, 3));
            QVERIFY(shown.wait(30000));
            QCOMPARE(shown.at(0).at(0).toInt(), 0);
            const double first = shown.at(0).at(2).toDouble();
            worst = std::max(worst, first);
            sum += first;
        }
        qInfo("default forest, 640x360 viewport: first image after a camera move %.3f s mean, %.3f s worst (%d moves)",
              sum / moves, worst, moves);
        QVERIFY2(worst < 0.5, "the issue asks for < 0.5 s");
        win.document()->undoStack()->setClean();
    }
};

QTEST_MAIN(TstStudioForest)
#include "tst_studio_forest.moc"
