// The studio as an artist expects it, under Xvfb: the render window (F12) renders the scene at its render
// size and samples, its passes adding samples, and its picture equals sylva render's (renderScene,
// composeMode, writeRender as the command runs them); Save writes a file of that size.
#include <QAction>
#include <QLabel>
#include <QProgressBar>
#include <QPushButton>
#include <QSpinBox>

#include <algorithm>
#include <cstdlib>
#include <memory>

#include "pipeline/cache/grid_cache.h"
#include "pipeline/render/render_job.h"
#include "studio/render_window.h"
#include "studio_test_util.h"

using namespace sylva;
using namespace sylva::test;

class TstStudioArtist : public QObject {
    Q_OBJECT

    QTemporaryDir m_dir;
    std::unique_ptr<MainWindow> m_win;
    QStringList m_errors;

    const Scene& scene() const { return m_win->document()->scene(); }
    SceneDocument* doc() const { return m_win->document(); }
    QAction* action(const char* name) const { return m_win->findChild<QAction*>(QString::fromLatin1(name)); }

private Q_SLOTS:
    void initTestCase()
    {
        SYLVA_SKIP_WITHOUT_X();
        QVERIFY(m_dir.isValid());
        isolate(m_dir);
        m_win = std::make_unique<MainWindow>();
        quietWindow(*m_win, &m_errors);
        m_win->lighting()->setAutoLighting(false);
        m_win->resize(1200, 760);
        QVERIFY(showWithViewport(*m_win, 640, 360));
        Scene s = treeScene();
        s.render.width = 72;
        s.render.height = 40;
        s.render.spp = 4;
        doc()->reset(s, QString());
    }

    void cleanupTestCase()
    {
        if (m_win) doc()->undoStack()->setClean();
        m_win.reset();
    }

    void renderWindow()
    {
        QAction* a = action("actionRenderImage");
        QVERIFY(a);
        QCOMPARE(a->shortcut(), QKeySequence(Qt::Key_F12));
        a->trigger();
        RenderWindow* rw = m_win->renderWindow();
        QVERIFY(rw);
        QVERIFY(rw->isVisible());
        QVERIFY(rw->isRendering());
        QCOMPARE(rw->widthBox()->value(), 72);
        QCOMPARE(rw->heightBox()->value(), 40);
        QCOMPARE(rw->samplesBox()->value(), 4);
        QSignalSpy passes(rw, &RenderWindow::passShown);
        QSignalSpy ended(rw, &RenderWindow::renderEnded);
        QVERIFY(ended.wait(180000));
        QVERIFY2(ended.at(0).at(0).toBool(), qPrintable(m_errors.join('\n')));
        QTRY_COMPARE(rw->samples(), 4);
        // The passes add samples (1, 1, 2 of 4) and the counter says how many there are.
        QCOMPARE(ExportController::renderSamplePasses(4, 1), (std::vector<int>{1, 2, 4}));
        QCOMPARE(passes.size(), 3);
        QCOMPARE(passes.first().at(0).toInt(), 1);
        QCOMPARE(passes.last().at(0).toInt(), 4);
        QCOMPARE(rw->sampleCounter()->text(), QStringLiteral("Samples 4 / 4"));
        QCOMPARE(rw->progressBar()->value(), rw->progressBar()->maximum());
        const QImage shown = rw->image();
        QCOMPARE(shown.size(), QSize(72, 40));

        // The oracle: sylva render's path (renderScene, then composeMode and writeRender as the command writes).
        GridCache cache;
        const RenderOutput out = renderScene(scene(), &cache);
        const QString refPath = m_dir.filePath("cli.png");
        writeRender(refPath.toStdString(), composeMode(out.film, scene().render.mode, composeSky(scene())), out.film.width,
                    out.film.height, scene().render.exposureKey);
        const QImage ref = QImage(refPath).convertToFormat(QImage::Format_RGB32);
        QCOMPARE(ref.size(), QSize(72, 40));
        const QImage got = shown.convertToFormat(QImage::Format_RGB32);
        int worst = 0;
        double sum = 0.0;
        for (int y = 0; y < 40; ++y)
            for (int x = 0; x < 72; ++x) {
                const QRgb p = got.pixel(x, y), q = ref.pixel(x, y);
                for (int d : {qRed(p) - qRed(q), qGreen(p) - qGreen(q), qBlue(p) - qBlue(q)}) {
                    worst = std::max(worst, std::abs(d));
                    sum += std::abs(d);
                }
            }
        // The passes' sum equals the one-pass frame up to float rounding: at most one 8-bit step.
        QVERIFY2(worst <= 1, qPrintable(QStringLiteral("worst %1").arg(worst)));
        QVERIFY(sum / (72.0 * 40.0 * 3.0) < 0.05);
        double mean = 0.0, stddev = 0.0;
        lumaStats(got, &mean, &stddev);
        QVERIFY(stddev > 2.0);   // a picture, not a flat colour

        // Save: the export's writer, at the render size; the PNG holds the shown pixels.
        const QString png = m_dir.filePath("saved.png"), exr = m_dir.filePath("saved.exr");
        QVERIFY(rw->saveImage(png));
        const QImage saved = QImage(png).convertToFormat(QImage::Format_RGB32);
        QCOMPARE(saved.size(), QSize(72, 40));
        QCOMPARE(saved, got);
        QVERIFY(rw->saveImage(exr));
        QVERIFY(QFileInfo(exr).size() > 0);
        QVERIFY(!rw->saveImage(m_dir.filePath("saved.bmp")));   // not a format the writer knows

        // The size and samples are edited in the window: one undo step, and the next render has that size.
        const int steps = doc()->undoStack()->count();
        rw->widthBox()->setValue(40);
        rw->heightBox()->setValue(30);
        rw->samplesBox()->setValue(2);
        QVERIFY(rw->render());
        QCOMPARE(scene().render.width, 40);
        QCOMPARE(scene().render.height, 30);
        QCOMPARE(scene().render.spp, 2);
        QCOMPARE(doc()->undoStack()->count(), steps + 1);
        QSignalSpy ended2(rw, &RenderWindow::renderEnded);
        QVERIFY(ended2.wait(120000));
        QTRY_COMPARE(rw->image().size(), QSize(40, 30));
        doc()->undoStack()->undo();
        QCOMPARE(rw->widthBox()->value(), 72);
        rw->close();
    }
};

QTEST_MAIN(TstStudioArtist)
#include "tst_studio_artist.moc"
