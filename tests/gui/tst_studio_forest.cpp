// The studio on the bundled default forest (5 grown species, 962 instances) under Xvfb: automatic
// lighting grows and lights the species (32-node grids), the viewport settles on the picture the renderer
// gives for the same scene and camera, and a camera move restarts the progressive schedule on the kept
// frame: a quarter-size first picture, then the refined ones, with no frame build (the species' BVHs are
// kept). How soon that first picture comes is a speed figure: bench_studio --forest (docs/STUDIO.md).
#include <QAction>
#include <QSignalSpy>

#include <memory>

#include "studio_picture.h"
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
        quietWindow(win, &errors);
        QVERIFY(showWithViewport(win, 640, 360));
        Viewport* v = win.viewport();
        QSignalSpy lit(win.lighting(), &LightingScheduler::lightingFinished);
        win.loadExampleForest();
        QCOMPARE(win.document()->scene().instances.size(), size_t(962));
        // 32-node grids instead of 64 keep a first run (fresh cache) short; render time does not
        // depend on the grid size. The edit lands before automatic lighting starts.
        Scene s = win.document()->scene();
        for (SpeciesDesc& sp : s.species) sp.grid = 32;
        win.document()->edit(s, "grid 32");
        // Orbiting while the species are lit does not restart the job: one lighting job in all, none
        // cancelled, nothing pending once it has ended.
        QTRY_VERIFY_WITH_TIMEOUT(win.jobs()->isBusy(), 60000);
        QTest::mousePress(v, Qt::LeftButton, {}, v->rect().center());
        QTest::mouseRelease(v, Qt::LeftButton, {}, v->rect().center() + QPoint(20, 0));
        // The lighting may already be done (a warm cache loads quickly): wait for its one signal whether
        // or not it has come yet (QSignalSpy::wait waits for the next one only).
        QTRY_VERIFY_WITH_TIMEOUT(lit.count() >= 1, 300000);
        QTRY_VERIFY_WITH_TIMEOUT(!win.lighting()->isPending(), 60000);
        QCOMPARE(lit.count(), 1);
        QCOMPARE(win.lighting()->lightingJobs(), 1);
        QVERIFY(lit.last().at(0).toBool());
        QVERIFY2(!win.logText().contains("cancelled"), qPrintable(win.logText()));
        QVERIFY(waitForFinalImage(v, 120000));
        QVERIFY2(errors.isEmpty(), qPrintable(errors.join('\n')));
        QCOMPARE(v->lastImage().size(), QSize(640, 360));
        v->lastImage().save(QString(SYLVA_TEST_OUTPUT) + "/gui_default_forest.png");

        // The settled picture is the renderer's for the same scene, camera and size, with the grids the
        // window lit (the worker's last pass traces the frame buildRenderScene builds; tst_view_frame shows
        // the re-placed frame equal to a fresh build bit for bit). Allowed: one 8-bit step, for the
        // rounding of the tone map's log-average key over a different summation order; measured 0.
        const std::vector<SpeciesAssets> assets = assetCopies(win.assetStore()->forScene(win.document()->scene(), true));
        QCOMPARE(assets.size(), win.document()->scene().species.size());
        const QImage want = settledPicture(win.document()->scene(), assets, v->renderSize());
        const int worst = maxStep(v->lastImage(), want);
        qInfo("default forest, viewport vs headless render: worst channel step %d of 255", worst);
        QVERIFY2(worst <= 1, qPrintable(QString("the viewport is %1 steps off the renderer's picture").arg(worst)));

        // Orbit a little, several times: each move restarts the schedule on the kept frame. Its first
        // picture is the schedule's first pass (quarter size), shown before the last pass, and the move
        // builds no frame (only the top level is re-placed).
        const int builds = v->worker()->frameBuilds();
        const std::vector<RenderPass> passes = RenderWorker::defaultPasses();
        const QSize quarter(v->renderSize().width() / passes[0].divisor, v->renderSize().height() / passes[0].divisor);
        for (int m = 0; m < 4; ++m) {
            QList<std::pair<int, QSize>> shown;   // pass and size of every picture shown after the move
            bool settledNow = false;
            const QMetaObject::Connection c = connect(v, &Viewport::imageShown, this, [&](int pass, bool last, double) {
                shown.append({pass, v->lastImage().size()});
                settledNow = last;
            });
            const QPoint c0 = v->rect().center();
            QTest::mousePress(v, Qt::LeftButton, {}, c0);
            QTest::mouseRelease(v, Qt::LeftButton, {}, c0 + QPoint(15, 3));
            QTRY_VERIFY_WITH_TIMEOUT(settledNow, 120000);
            disconnect(c);
            QVERIFY2(shown.size() >= 2, qPrintable(QString("move %1: %2 picture(s)").arg(m).arg(shown.size())));
            QCOMPARE(shown.first().first, 0);
            QCOMPARE(shown.first().second, quarter);
            QCOMPARE(shown.last().second, v->renderSize());
            QVERIFY(shown.last().first > 0);
            QCOMPARE(v->worker()->frameBuilds(), builds);
        }
        // ... and the moved camera's settled picture is the renderer's for that camera.
        const QImage moved = settledPicture(win.document()->scene(), assets, v->renderSize());
        QVERIFY(maxStep(moved, want) > 8);   // the camera did move the picture
        const int worstMoved = maxStep(v->lastImage(), moved);
        QVERIFY2(worstMoved <= 1, qPrintable(QString("after the moves the viewport is %1 steps off the renderer's picture").arg(worstMoved)));
        win.document()->undoStack()->setClean();
    }
};

QTEST_MAIN(TstStudioForest)
#include "tst_studio_forest.moc"
