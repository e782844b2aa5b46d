// The studio as an artist expects it, under Xvfb: the render window (F12) renders the scene at its render
// size and samples, its passes adding samples, and its picture equals sylva render's (renderScene,
// composeMode, writeRender as the command runs them); Save writes a file of that size. The camera frame
// in the viewport has the render's proportions, lies inside the viewport, centred, and shows each point
// where the render shows it (a pinhole projection written here from the camera's parameters). Scatter keeps
// its clearance around the camera's eye and frames its result. Every control of the toolbar and the panels
// has a tooltip in words (no scene-file keys); the sun dial's compass points lie where they set the sun.
// Help > Manual shows the user documents (headings read from the files themselves); Help > Keyboard
// Shortcuts lists every action of the window that has a shortcut.
#include <QAction>
#include <QFile>
#include <QListWidget>
#include <QTableWidget>
#include <QTextBlock>
#include <QTextBrowser>
#include <QTextDocument>
#include <QAbstractSlider>
#include <QComboBox>
#include <QLineEdit>
#include <QRegularExpression>
#include <QScrollBar>
#include <QToolBar>
#include <QCheckBox>
#include <QDoubleSpinBox>
#include <QLabel>
#include <QProgressBar>
#include <QPushButton>
#include <QSpinBox>

#include <algorithm>
#include <cstdlib>
#include <memory>

#include "tests/common/pinhole.h"
#include "pipeline/cache/grid_cache.h"
#include "pipeline/render/render_job.h"
#include "studio/camera_nav.h"
#include "studio/dialogs.h"
#include "studio/help_dialogs.h"
#include "studio/property_panel.h"
#include "studio/sky_panel.h"
#include "studio/words.h"
#include "studio/render_window.h"
#include "studio_test_util.h"

using namespace sylva;
using namespace sylva::test;

namespace {

// Where world point p lands in a w x h picture of camera c (pixels, y down), from the camera's parameters alone.
QPointF project(const CameraDesc& c, double w, double h, const glm::dvec3& p)
{
    const glm::dvec2 q = test::pinholeProject(c, w, h, p);
    return {q.x, q.y};
}

} // namespace

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

        // A value typed in a box stays through other edits (a camera move) until it is rendered.
        rw->widthBox()->setValue(64);
        Scene moved = scene();
        moved.camera.position.x += 0.5;
        doc()->edit(moved, QStringLiteral("camera"));
        QCOMPARE(rw->widthBox()->value(), 64);
        doc()->undoStack()->undo();
        rw->widthBox()->setValue(72);

        // Cancel after the first pass: the picture keeps its samples, and Save writes it.
        rw->samplesBox()->setValue(4096);
        QSignalSpy firstPass(rw, &RenderWindow::passShown);
        QSignalSpy ended3(rw, &RenderWindow::renderEnded);
        QVERIFY(rw->render());
        QVERIFY(firstPass.wait(60000));
        rw->cancel();
        QVERIFY(ended3.wait(60000));
        QVERIFY(!ended3.at(0).at(0).toBool());
        QVERIFY(!rw->isRendering());
        QVERIFY(rw->samples() >= 1 && rw->samples() < 4096);
        QCOMPARE(rw->sampleCounter()->text(), QStringLiteral("Samples %1 / 4096").arg(rw->samples()));
        const QString partial = m_dir.filePath("partial.png");
        QVERIFY(rw->saveImage(partial));
        QCOMPARE(QImage(partial).convertToFormat(QImage::Format_RGB32), rw->image().convertToFormat(QImage::Format_RGB32));
        doc()->undoStack()->undo();
        rw->close();
    }

    void cameraFrame()
    {
        Viewport* v = m_win->viewport();
        QAction* a = action("actionCameraFrame");
        QVERIFY(a && a->isCheckable());
        QVERIFY(!a->isChecked());   // the tests' settings turn it off (the studio's default is on)
        QVERIFY(v->cameraFrameRect().isEmpty());
        a->setChecked(true);
        QVERIFY(v->cameraFrame());
        const double W = v->width(), H = v->height();
        // Wider than the viewport (letterbox), taller (pillarbox), the viewport's own proportions.
        for (const QSize render : {QSize(896, 448), QSize(300, 400), QSize(640, 360), QSize(1000, 100)}) {
            Scene s = scene();
            s.render.width = render.width();
            s.render.height = render.height();
            doc()->edit(s, QStringLiteral("render size"));
            const QRectF r = v->cameraFrameRect();
            const QString what = QStringLiteral("%1 x %2: frame %3, %4 %5 x %6")
                                     .arg(render.width()).arg(render.height())
                                     .arg(r.x()).arg(r.y()).arg(r.width()).arg(r.height());
            QVERIFY2(!r.isEmpty(), qPrintable(what));
            // The render's proportions within a pixel, inside the viewport, centred, as large as fits.
            QVERIFY2(std::abs(r.width() - r.height() * render.width() / render.height()) <= 1.0, qPrintable(what));
            QVERIFY2(r.left() >= -1e-9 && r.top() >= -1e-9 && r.right() <= W + 1e-9 && r.bottom() <= H + 1e-9, qPrintable(what));
            QVERIFY2(std::abs(r.center().x() - 0.5 * W) < 0.5 && std::abs(r.center().y() - 0.5 * H) < 0.5, qPrintable(what));
            QVERIFY2(std::abs(r.width() - W) < 0.5 || std::abs(r.height() - H) < 0.5, qPrintable(what));
            // Each point lies in the frame where the render puts it: the viewport's camera (what it traces and
            // picks with) against the scene's camera at the render's size.
            for (const InstanceDesc& in : scene().instances)
                for (const glm::dvec3 off : {glm::dvec3(0.0), glm::dvec3(1.0, 4.0, 0.5), glm::dvec3(-2.0, 1.0, 1.0)}) {
                    const glm::dvec3 p = in.position + off;
                    const QPointF inRender = project(scene().camera, render.width(), render.height(), p);
                    const QPointF expected = r.topLeft() + inRender * (r.width() / render.width());
                    const QPointF shown = project(v->viewCamera(), W, H, p);
                    QVERIFY2(std::abs(shown.x() - expected.x()) < 0.5 && std::abs(shown.y() - expected.y()) < 0.5,
                             qPrintable(what + QStringLiteral(": a point at (%1, %2), expected (%3, %4)")
                                                   .arg(shown.x()).arg(shown.y()).arg(expected.x()).arg(expected.y())));
                }
            QCOMPARE(v->viewCamera().position, scene().camera.position);
        }

        // The viewport draws the wider view: its settled picture is the scene at viewCamera, outside the frame darker.
        QSignalSpy finished(m_win->lighting(), &LightingScheduler::lightingFinished);
        if (m_win->lighting()->computeLighting()) QVERIFY(finished.wait(120000));   // null: the render's assets are in memory
        Scene s = scene();
        s.render.width = 896;
        s.render.height = 300;
        doc()->edit(s, QStringLiteral("render size"));
        QVERIFY(waitForFinalImage(v, 60000));
        const QRectF r = v->cameraFrameRect();
        QVERIFY(r.top() > 20.0);
        const QImage fb = v->grabFramebuffer().convertToFormat(QImage::Format_RGB32);
        const QImage pic = v->lastImage().convertToFormat(QImage::Format_RGB32);
        const double sx = double(fb.width()) / W, sy = double(fb.height()) / H;
        int darker = 0, samples = 0;
        for (int x = 10; x < int(W) - 10; x += 37) {
            const int y = int(r.top() * 0.5);
            const QRgb drawn = fb.pixel(int(x * sx), int(y * sy));
            const QRgb traced = pic.pixel(int(x * pic.width() / W), int(y * pic.height() / H));
            ++samples;
            if (qGray(drawn) < qGray(traced) || qGray(traced) == 0) ++darker;
        }
        QCOMPARE(darker, samples);

        // Frame All frames into the render's picture: every corner of every instance's box inside it.
        QVERIFY(v->frameAll());
        for (const InstanceDesc& in : scene().instances) {
            const Bounds3 b = instanceBounds(scene(), in, v->speciesBoxes()[in.species]);
            QVERIFY(b.valid());
            for (int k = 0; k < 8; ++k) {
                const glm::dvec3 c((k & 1) ? b.hi.x : b.lo.x, (k & 2) ? b.hi.y : b.lo.y, (k & 4) ? b.hi.z : b.lo.z);
                const QPointF p = project(scene().camera, 896, 300, c);
                QVERIFY2(p.x() >= 0 && p.x() <= 896 && p.y() >= 0 && p.y() <= 300,
                         qPrintable(QStringLiteral("corner at (%1, %2)").arg(p.x()).arg(p.y())));
            }
        }
        a->setChecked(false);
        QVERIFY(v->cameraFrameRect().isEmpty());
        QCOMPARE(v->viewCamera().fovY, scene().camera.fovY);
    }

    void words()
    {
        // The toolbar's light modes in artists' words, the scene's values underneath.
        QComboBox* mode = m_win->modeSelector();
        QStringList labels;
        for (int i = 0; i < mode->count(); ++i) labels << mode->itemText(i);
        QCOMPARE(labels, (QStringList{"All", "Direct only", "Flat ambient", "Bounce only"}));
        QCOMPARE(mode->itemData(0).toInt(), int(RenderMode::Full));
        QCOMPARE(mode->itemData(1).toInt(), int(RenderMode::Local));
        QCOMPARE(mode->itemData(2).toInt(), int(RenderMode::Ambient));
        QCOMPARE(mode->itemData(3).toInt(), int(RenderMode::Lb));
        for (int i = 0; i < mode->count(); ++i) QVERIFY(!mode->itemData(i, Qt::ToolTipRole).toString().isEmpty());

        // Every control of the toolbar, the properties (all pages) and the sky panel: a tooltip, without the
        // scene file's keys (sun_sky, lighting.boundary) or code quotes.
        const QRegularExpression key(QStringLiteral("`|\\b[a-z]+_[a-z_]+\\b|\\b[a-z]+\\.[a-z][a-z_.]*\\b"));
        QStringList missing, keyed;
        int controls = 0;
        for (QWidget* root : {static_cast<QWidget*>(mode->parentWidget()), static_cast<QWidget*>(m_win->propertyPanel()),
                              static_cast<QWidget*>(m_win->skyPanel())}) {
            for (QWidget* w : root->findChildren<QWidget*>()) {
                const bool control = qobject_cast<QComboBox*>(w) || qobject_cast<QAbstractSpinBox*>(w) ||
                                     qobject_cast<QAbstractButton*>(w) || qobject_cast<QLineEdit*>(w) ||
                                     (qobject_cast<QAbstractSlider*>(w) && !qobject_cast<QScrollBar*>(w));
                if (!control || w->objectName().startsWith(QLatin1String("qt_"))) continue;
                if (qobject_cast<QLineEdit*>(w) && qobject_cast<QAbstractSpinBox*>(w->parentWidget())) continue;   // a spin box's own
                if (qobject_cast<QLineEdit*>(w) && qobject_cast<QComboBox*>(w->parentWidget())) continue;
                ++controls;
                const QString tip = w->toolTip();
                if (tip.trimmed().isEmpty()) missing << w->objectName() + QStringLiteral(" (") + w->metaObject()->className() + ')';
                else if (key.match(tip).hasMatch()) keyed << w->objectName() + QStringLiteral(": ") + tip;
            }
        }
        QVERIFY(controls > 40);
        QVERIFY2(missing.isEmpty(), qPrintable(missing.join(", ")));
        QVERIFY2(keyed.isEmpty(), qPrintable(keyed.join("\n")));

        // The two one-colour skies read differently and say which lights the plants.
        auto* kind = m_win->skyPanel()->findChild<QComboBox*>(QStringLiteral("sky.kind"));
        QVERIFY(kind);
        const int constant = kind->findData(int(sky::SkyKind::Constant)), uniform = kind->findData(int(sky::SkyKind::Uniform));
        QVERIFY(constant >= 0 && uniform >= 0);
        QCOMPARE(kind->itemText(constant), QStringLiteral("Colour backdrop (lights nothing)"));
        QCOMPARE(kind->itemText(uniform), QStringLiteral("Even sky light (lights the plants)"));
        QVERIFY(kind->itemData(constant, Qt::ToolTipRole).toString().contains(QStringLiteral("lights nothing")));
        QVERIFY(kind->itemData(uniform, Qt::ToolTipRole).toString().contains(QStringLiteral("lights the plants")));
        QVERIFY(kind->itemData(constant, Qt::ToolTipRole) != kind->itemData(uniform, Qt::ToolTipRole));

        // The compass dial: a click on a point's letter turns the sun there (east +X, north -Z, the scene's axes).
        SceneDocument doc;
        Scene s = scene();
        s.sun.direction = glm::normalize(glm::vec3(0.0f, 1.0f, 1.0f));
        doc.reset(s, QString());
        SkyPanel panel(&doc);
        panel.show();
        QVERIFY(QTest::qWaitForWindowExposed(&panel));
        auto* dial = dynamic_cast<CompassDial*>(panel.sunAzimuthDial());
        QVERIFY(dial);
        const struct {
            double azimuth;
            glm::vec3 toward;
        } points[] = {{90.0, {1.0f, 0.0f, 0.0f}}, {180.0, {0.0f, 0.0f, -1.0f}}, {270.0, {-1.0f, 0.0f, 0.0f}}, {0.0, {0.0f, 0.0f, 1.0f}}};
        for (const auto& pt : points) {
            QTest::mouseClick(dial, Qt::LeftButton, Qt::NoModifier, dial->labelCentre(pt.azimuth).toPoint());
            const glm::vec3 d = doc.scene().sun.direction;
            const glm::vec3 flat = glm::normalize(glm::vec3(d.x, 0.0f, d.z));
            QVERIFY2(glm::dot(flat, pt.toward) > 0.95,
                     qPrintable(QStringLiteral("azimuth %1: dial %2, sun (%3, %4, %5)").arg(pt.azimuth).arg(dial->value()).arg(d.x).arg(d.y).arg(d.z)));
        }
    }

    void manual()
    {
        // The documents' headings, read from the files here: level 1 (the title) and the level-2 headings.
        auto headings = [](const QString& file, int level) {
            QFile f(file);
            if (!f.open(QIODevice::ReadOnly | QIODevice::Text)) return QStringList{};
            const QString prefix = QString(level, QLatin1Char('#')) + QLatin1Char(' ');
            QStringList out;
            bool fenced = false;
            for (const QString& line : QString::fromUtf8(f.readAll()).split(QLatin1Char('\n'))) {
                if (line.startsWith(QLatin1String("```"))) fenced = !fenced;
                if (!fenced && line.startsWith(prefix)) out << line.mid(prefix.size()).remove(QLatin1Char('`')).trimmed();
            }
            return out;
        };
        // The browser's headings of a level, as shown.
        auto shown = [](QTextBrowser* b, int level) {
            QStringList out;
            for (QTextBlock block = b->document()->begin(); block.isValid(); block = block.next())
                if (block.blockFormat().headingLevel() == level) out << block.text().trimmed();
            return out;
        };
        const QString docs = QStringLiteral(SYLVA_RESOURCES "/../docs");
        const QStringList studioTitle = headings(docs + QStringLiteral("/STUDIO.md"), 1);
        const QStringList studioSections = headings(docs + QStringLiteral("/STUDIO.md"), 2);
        QCOMPARE(studioTitle.size(), 1);
        QVERIFY(studioSections.contains(QStringLiteral("Menus and shortcuts")));

        QAction* a = action("actionManual");
        QVERIFY(a);
        QCOMPARE(a->shortcut(), QKeySequence(Qt::Key_F1));
        a->trigger();
        auto* manual = m_win->findChild<ManualDialog*>();
        QVERIFY(manual);
        QVERIFY(manual->isVisible());
        QVERIFY(!ManualDialog::docsRoot().isEmpty());
        QCOMPARE(manual->list()->count(), 3);
        // The studio's document first, rendered from Markdown: its title and every section heading as headings.
        QCOMPARE(shown(manual->browser(), 1), studioTitle);
        QCOMPARE(shown(manual->browser(), 2), studioSections);
        QVERIFY(manual->browser()->toPlainText().contains(QStringLiteral("Render window")));
        // The scene file's document from the list.
        manual->list()->setCurrentRow(1);
        QCOMPARE(shown(manual->browser(), 1), headings(docs + QStringLiteral("/SCENE.md"), 1));
        QVERIFY(!manual->showDocument(QStringLiteral("docs/NO_SUCH.md")));
        manual->close();
    }

    void shortcutSheet()
    {
        QAction* a = action("actionShortcuts");
        QVERIFY(a);
        a->trigger();
        auto* sheet = m_win->findChild<ShortcutSheet*>();
        QVERIFY(sheet && sheet->isVisible());
        QTableWidget* t = sheet->table();
        // Every action of the window with a shortcut has its row: its name (the end of the menu path) and its keys.
        QSet<QAction*> withKeys;
        for (QAction* act : m_win->findChildren<QAction*>())
            if (!act->shortcuts().isEmpty()) withKeys.insert(act);
        QVERIFY(withKeys.size() >= 15);
        QCOMPARE(t->rowCount(), int(withKeys.size()));
        for (QAction* act : withKeys) {
            QString name = act->text();
            name.remove(QLatin1Char('&'));
            const QString keys = act->shortcut().toString(QKeySequence::NativeText);
            bool found = false;
            for (int r = 0; r < t->rowCount() && !found; ++r)
                found = t->item(r, 0)->text().endsWith(name) && t->item(r, 1)->text().split(QStringLiteral(", ")).contains(keys);
            QVERIFY2(found, qPrintable(name + QStringLiteral(" ") + keys));
        }
        // Rows named by their menus.
        QStringList names;
        for (int r = 0; r < t->rowCount(); ++r) names << t->item(r, 0)->text() + QStringLiteral(" = ") + t->item(r, 1)->text();
        QVERIFY2(names.contains(QStringLiteral("Render > Render Image = F12")), qPrintable(names.join('\n')));
        QVERIFY2(names.contains(QStringLiteral("Help > Manual = F1")), qPrintable(names.join('\n')));
        QVERIFY2(names.contains(QStringLiteral("View > Frame All = Home")), qPrintable(names.join('\n')));
        QVERIFY2(names.contains(QStringLiteral("File > Open... = ") + QKeySequence(QKeySequence::Open).toString(QKeySequence::NativeText)),
                 qPrintable(names.join('\n')));
        // A shortcut added to an action shows in the next sheet: the sheet is made from the actions.
        QAction* materials = action("actionMaterials");
        QVERIFY(materials && materials->shortcut().isEmpty());
        materials->setShortcut(QKeySequence(Qt::CTRL | Qt::ALT | Qt::Key_M));
        ShortcutSheet* again = m_win->showShortcuts();
        QCOMPARE(again->table()->rowCount(), int(withKeys.size()) + 1);
        materials->setShortcut(QKeySequence());
        again->close();
    }

    void scatterClearance()
    {
        // The camera stands inside the area: 3000 instances over 60 x 60 m around it.
        Scene s = scene();
        s.camera.position = {2.0, 1.7, -3.0};
        s.camera.target = {2.0, 1.7, 10.0};
        doc()->edit(s, QStringLiteral("camera inside"));
        const size_t before = scene().instances.size();
        ScatterSpec spec = m_win->scatterTool()->defaultScatter();
        // The default clearance: 3 m, or Tree_1's crown reach at the largest scale when that is more (its
        // mesh's box from the loaded assets, the farthest corner from the trunk along the ground).
        const std::vector<AssetsPtr> assets = m_win->assetStore()->forScene(scene(), true);
        QCOMPARE(assets.size(), size_t(1));
        double reach = 0.0;
        for (const glm::vec3& p : assets[0]->mesh.positions) reach = std::max(reach, std::hypot(double(p.x), double(p.z)));
        double boxReach = 0.0;   // the box's corner: at least as far as any vertex
        {
            glm::dvec2 lo(1e30), hi(-1e30);
            for (const glm::vec3& p : assets[0]->mesh.positions) {
                lo = glm::min(lo, glm::dvec2(p.x, p.z));
                hi = glm::max(hi, glm::dvec2(p.x, p.z));
            }
            boxReach = std::hypot(std::max(std::abs(lo.x), std::abs(hi.x)), std::max(std::abs(lo.y), std::abs(hi.y)));
        }
        QVERIFY(boxReach >= reach);
        QVERIFY2(std::abs(spec.clearRadius - std::max(ScatterTool::kDefaultClearance, boxReach * double(spec.scaleMax))) < 1e-4,
                 qPrintable(QStringLiteral("%1 against %2").arg(spec.clearRadius).arg(boxReach)));
        QCOMPARE(spec.clearCentre, glm::dvec2(2.0, -3.0));   // the eye, on the ground plane
        spec.count = 3000;
        spec.min = {-28.0, -33.0};
        spec.max = {32.0, 27.0};
        spec.clearRadius = 4.5;
        const int steps = doc()->undoStack()->index();
        const CameraDesc camera = scene().camera;
        QVERIFY(m_win->scatterTool()->scatter(spec));
        QCOMPARE(doc()->undoStack()->index(), steps + 1);
        QCOMPARE(scene().camera.position, camera.position);   // not framed unless asked
        QCOMPARE(scene().instances.size(), before + 3000);   // the count kept: those drawn near the eye drawn again
        double nearest = 1e300;
        for (size_t i = before; i < scene().instances.size(); ++i) {
            const glm::dvec3 p = scene().instances[i].position;
            nearest = std::min(nearest, std::hypot(p.x - camera.position.x, p.z - camera.position.z));
            QVERIFY(p.x >= spec.min.x && p.x <= spec.max.x && p.z >= spec.min.y && p.z <= spec.max.y);
        }
        QVERIFY2(nearest >= 4.5, qPrintable(QString::number(nearest)));
        QVERIFY(nearest < 5.5);   // ... and the trees come close to it: only the disc is kept clear
        // Without a clearance the same spec puts some inside it (the disc holds about 1.8% of the area).
        spec.clearRadius = 0.0;
        int inside = 0;
        for (const InstanceDesc& in : scatterInstances(spec))
            inside += std::hypot(in.position.x - camera.position.x, in.position.z - camera.position.z) < 4.5;
        QVERIFY(inside > 20);
        doc()->undoStack()->undo();
        QCOMPARE(scene().instances.size(), before);

        // An area all within the clearance: an error, nothing changed.
        m_errors.clear();
        spec.clearRadius = 50.0;
        spec.min = {-5.0, -8.0};
        spec.max = {9.0, 2.0};
        QVERIFY(!m_win->scatterTool()->scatter(spec));
        QCOMPARE(m_errors.size(), 1);
        QCOMPARE(doc()->undoStack()->index(), steps);
        // A thin ring left outside the clearance: some instances find no room, the log says how many.
        m_win->clearLog();
        spec.clearRadius = 8.3;
        spec.min = {-4.0, -9.0};
        spec.max = {8.0, 3.0};   // a 12 m square about the eye: only its corners' tips lie beyond 8.3 m (0.1% of it)
        spec.count = 200;
        QVERIFY(m_win->scatterTool()->scatter(spec));
        const size_t placed = scene().instances.size() - before;
        QVERIFY2(placed > 0 && placed < 200, qPrintable(QString::number(placed)));
        QVERIFY2(m_win->logText().contains(QStringLiteral("%1 of the 200 instances").arg(200 - placed)), qPrintable(m_win->logText()));
        for (size_t i = before; i < scene().instances.size(); ++i) {
            const glm::dvec3 p = scene().instances[i].position;
            QVERIFY(std::hypot(p.x - camera.position.x, p.z - camera.position.z) >= 8.3);
        }
        doc()->undoStack()->undo();

        // The dialog: the clearance and "frame the result", and a framed scatter moves the camera out (navigation:
        // the scatter's one step, undone without moving the camera back).
        ScatterDialog d({QStringLiteral("Tree_1")}, m_win->scatterTool()->defaultScatter());
        QCOMPARE(d.clearanceBox()->value(), std::round(m_win->scatterTool()->defaultScatter().clearRadius * 10.0) / 10.0);
        QVERIFY(d.frameBox()->isChecked());
        d.clearanceBox()->setValue(6.0);
        ScatterSpec fromForm = d.spec();
        QCOMPARE(fromForm.clearRadius, 6.0);
        QCOMPARE(fromForm.clearCentre, glm::dvec2(2.0, -3.0));
        fromForm.min = {-28.0, -33.0};
        fromForm.max = {32.0, 27.0};
        const int steps2 = doc()->undoStack()->index();
        QVERIFY(m_win->scatterTool()->scatter(fromForm, d.frameResult()));
        QCOMPARE(doc()->undoStack()->index(), steps2 + 1);
        const CameraDesc framed = scene().camera;
        QVERIFY(framed.position != camera.position);
        doc()->undoStack()->undo();
        QCOMPARE(scene().instances.size(), before);
        QCOMPARE(scene().camera.position, framed.position);
        doc()->navigate(camera);
        QCOMPARE(scene().camera.position, camera.position);
    }
};

QTEST_MAIN(TstStudioArtist)
#include "tst_studio_artist.moc"
