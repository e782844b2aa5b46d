// The viewport as an artist used to Blender works in it, under Xvfb: navigation (a click, a drag, the wheel,
// fly keys, framing) leaves no undo step and the scene unmodified, other edits' undo keeps the navigated
// camera and saving writes it; a click on a tree selects its instance (outliner row,
// properties, an outline over the picture) without tracing again, a click on the sky or the ground clears
// the selection; Ctrl + drag slides a tree over the ground and Ctrl + wheel turns or scales it, a step each;
// Frame All and Frame Selected; the wheel zooms toward what is under the cursor and a pan
// drags what it grabbed; the outliner's numbers; File > Open's question before its file chooser and the
// dialogs' remembered folder. The oracles are the test's own: a pinhole projection from the camera's
// parameters and the boxes of the species' mesh as the lighting job loaded it.
#include <QAction>
#include <QDoubleSpinBox>
#include <QHeaderView>
#include <QItemSelectionModel>
#include <QRegularExpression>
#include <QTreeView>
#include <QWheelEvent>

#include <algorithm>
#include <cmath>
#include <memory>

#include "tests/common/pinhole.h"
#include "pipeline/scene/scene_file.h"
#include "studio/camera_nav.h"
#include "studio/outliner_model.h"
#include "studio/property_panel.h"
#include "studio/render_worker.h"
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

// The eight corners of box [lo, hi].
std::vector<glm::dvec3> corners(const glm::dvec3& lo, const glm::dvec3& hi)
{
    std::vector<glm::dvec3> out;
    for (int k = 0; k < 8; ++k) out.emplace_back((k & 1) ? hi.x : lo.x, (k & 2) ? hi.y : lo.y, (k & 4) ? hi.z : lo.z);
    return out;
}

// Two Tree_1 instances (grid 16) ten metres apart, unturned and unscaled, seen from the front.
Scene twoTrees()
{
    Scene s = treeScene();
    s.instances.resize(2);
    s.instances[0].position = {-5.0, 0.0, 0.0};
    s.instances[1].position = {5.0, 0.0, 0.0};
    for (InstanceDesc& in : s.instances) in.rotationDeg = glm::vec3(0.0f);
    s.camera.position = {0.0, 4.0, -20.0};
    s.camera.target = {0.0, 3.0, 0.0};
    return s;
}

} // namespace

class TstStudioViewport : public QObject {
    Q_OBJECT

    QTemporaryDir m_dir;
    std::unique_ptr<MainWindow> m_win;
    QStringList m_errors;
    int m_prompts = 0;
    QMessageBox::StandardButton m_answer = QMessageBox::Discard;
    glm::dvec3 m_lo{0.0}, m_hi{0.0};   // Tree_1's mesh box (species frame), from the loaded assets

    const Scene& scene() const { return m_win->document()->scene(); }
    SceneDocument* doc() const { return m_win->document(); }
    Viewport* viewport() const { return m_win->viewport(); }
    QAction* action(const char* name) const { return m_win->findChild<QAction*>(QString::fromLatin1(name)); }
    QSize size() const { return viewport()->size(); }
    QPoint at(const glm::dvec3& p) const { return project(scene().camera, size().width(), size().height(), p).toPoint(); }
    // A point well inside instance i's crown: three quarters up its box, above the box's centre.
    glm::dvec3 crown(int i) const
    {
        const glm::dvec3 c = 0.5 * (m_lo + m_hi);
        return scene().instances[size_t(i)].position + glm::dvec3(c.x, m_lo.y + 0.75 * (m_hi.y - m_lo.y), c.z);
    }
    OutlinerItem current() const { return m_win->outlinerModel()->itemAt(m_win->outliner()->currentIndex()); }
    void settle() { QVERIFY(waitForFinalImage(viewport(), 60000)); }
    void wheel(const QPoint& pos, int delta, Qt::KeyboardModifiers mods = Qt::NoModifier)
    {
        QWheelEvent e(QPointF(pos), viewport()->mapToGlobal(QPointF(pos)), QPoint(), QPoint(0, delta), Qt::NoButton, mods,
                      Qt::NoScrollPhase, false);
        QApplication::sendEvent(viewport(), &e);
    }

private Q_SLOTS:
    void initTestCase()
    {
        SYLVA_SKIP_WITHOUT_X();
        QVERIFY(m_dir.isValid());
        isolate(m_dir);
        m_win = std::make_unique<MainWindow>();
        m_win->setErrorReporter([this](const QString&, const QString& message) { m_errors << message; });
        m_win->setSavePrompt([this](const QString&) {
            ++m_prompts;
            return m_answer;
        });
        m_win->lighting()->setAutoLighting(false);
        m_win->resize(1200, 760);
        QVERIFY(showWithViewport(*m_win, 640, 360));
        doc()->reset(twoTrees(), QString());
        QSignalSpy finished(m_win->lighting(), &LightingScheduler::lightingFinished);
        QVERIFY(m_win->lighting()->computeLighting());
        QVERIFY(finished.wait(120000));
        QVERIFY(finished.at(0).at(0).toBool());
        settle();
        const std::vector<AssetsPtr> assets = m_win->assetStore()->forScene(scene(), true);
        QCOMPARE(assets.size(), size_t(1));
        m_lo = glm::dvec3(1e30);
        m_hi = glm::dvec3(-1e30);
        const TriangleMesh& mesh = assets[0]->mesh;
        for (const glm::uvec3& t : mesh.triangles)
            for (int k = 0; k < 3; ++k) {
                m_lo = glm::min(m_lo, glm::dvec3(mesh.positions[t[k]]));
                m_hi = glm::max(m_hi, glm::dvec3(mesh.positions[t[k]]));
            }
        QVERIFY(m_hi.y - m_lo.y > 1.0);
    }

    void cleanupTestCase()
    {
        if (m_win) doc()->undoStack()->setClean();
        m_win.reset();
    }

    // A click (and a press that moves less than the drag distance) changes no camera: no undo step, the
    // scene stays unmodified, the title has no '*', and New asks nothing. Navigation (drags, the wheel, fly
    // keys, Frame All) moves the camera with no step and leaves the scene unmodified; undo and redo of
    // other edits keep the navigated camera, an edit of the camera itself puts its own back; Save writes it.
    void navigationIsNoEdit()
    {
        QUndoStack* undo = doc()->undoStack();
        QCOMPARE(undo->count(), 0);
        QVERIFY(!doc()->isModified());
        const CameraDesc before = scene().camera;
        const QPoint c = viewport()->rect().center();
        QTest::mouseClick(viewport(), Qt::LeftButton, {}, c);
        QTest::mousePress(viewport(), Qt::LeftButton, {}, c);
        QTest::mouseMove(viewport(), c + QPoint(2, 1));
        QTest::mouseRelease(viewport(), Qt::LeftButton, {}, c + QPoint(2, 1));
        QTest::mouseClick(viewport(), Qt::MiddleButton, {}, c);
        QTest::mouseClick(viewport(), Qt::LeftButton, Qt::ShiftModifier, c);
        QCOMPARE(undo->count(), 0);
        QVERIFY(!doc()->isModified());
        QVERIFY(!m_win->isWindowModified());
        QVERIFY(scene().camera.position == before.position && scene().camera.target == before.target);

        // A drag there and back in one gesture: no step, still clean.
        QTest::mousePress(viewport(), Qt::LeftButton, {}, c);
        QTest::mouseMove(viewport(), c + QPoint(60, 20));
        QVERIFY(scene().camera.position != before.position);
        QTest::mouseMove(viewport(), c);
        QTest::mouseRelease(viewport(), Qt::LeftButton, {}, c);
        QCOMPARE(undo->count(), 0);
        QVERIFY(!doc()->isModified());
        QVERIFY(!m_win->isWindowModified());

        // A drag moves the camera but is navigation: no step, still clean, as are a wheel turn, a fly key and
        // Frame All.
        QTest::mousePress(viewport(), Qt::LeftButton, {}, c);
        for (int i = 1; i <= 5; ++i) QTest::mouseMove(viewport(), c + QPoint(12 * i, 3 * i));
        QTest::mouseRelease(viewport(), Qt::LeftButton, {}, c + QPoint(60, 15));
        QVERIFY(scene().camera.position != before.position);
        wheel(c, 120);
        QVERIFY(viewport()->frameAll());
        viewport()->setFocus();
        viewport()->setFlyMode(true);
        QTest::keyClick(viewport(), Qt::Key_W);
        viewport()->setFlyMode(false);
        QCOMPARE(undo->count(), 0);
        QVERIFY(!doc()->isModified());
        QVERIFY(!m_win->isWindowModified());
        const CameraDesc navigated = scene().camera;
        QVERIFY(navigated.position != before.position);

        // An edit after navigating, undone and redone, keeps the navigated camera; an edit of the camera
        // itself puts its own camera back.
        Scene lit = scene();
        lit.sun.intensity *= 2.0f;
        doc()->edit(lit, "sun");
        QCOMPARE(undo->count(), 1);
        undo->undo();
        QVERIFY(scene().camera.position == navigated.position && scene().camera.target == navigated.target);
        undo->redo();
        QVERIFY(scene().camera.position == navigated.position);
        undo->undo();
        Scene aimed = scene();
        aimed.camera.target.y += 1.0;
        doc()->edit(aimed, "aim");
        QTest::mousePress(viewport(), Qt::LeftButton, {}, c);
        QTest::mouseMove(viewport(), c + QPoint(40, 0));
        QTest::mouseRelease(viewport(), Qt::LeftButton, {}, c + QPoint(40, 0));
        undo->undo();
        QVERIFY(scene().camera.position == navigated.position && scene().camera.target == navigated.target);

        // Saving writes the navigated camera.
        QTest::mousePress(viewport(), Qt::LeftButton, {}, c);
        QTest::mouseMove(viewport(), c + QPoint(-30, 10));
        QTest::mouseRelease(viewport(), Qt::LeftButton, {}, c + QPoint(-30, 10));
        const CameraDesc last = scene().camera;
        const QString saved = m_dir.filePath("navigated.sylva.json");
        QVERIFY(m_win->saveFile(saved));
        const Scene reread = readSceneFile(saved.toStdString());
        QVERIFY(glm::length(reread.camera.position - last.position) < 1e-6 && glm::length(reread.camera.target - last.target) < 1e-6);
        Scene back = scene();
        back.camera = before;
        doc()->reset(back, QString());
        undo->clear();
        m_prompts = 0;
        QTest::mouseClick(viewport(), Qt::LeftButton, {}, c);
        // New after a click: nothing to save, no question (the scene is put back afterwards).
        const Scene kept = scene();
        QVERIFY(m_win->newScene());
        QCOMPARE(m_prompts, 0);
        doc()->reset(kept, QString());
        settle();
    }

    // An orbit a quarter turn about the target puts the eye at x = 1e-15 or so: the outliner shows 0, and
    // no number in scientific notation; the details column is as wide as its text.
    void outlinerNumbers()
    {
        Scene s = scene();
        s.camera.position = {-1.225e-15, 3.0, 12690.4};
        s.camera.target = {0.0, 2.5, 0.0};
        doc()->edit(s, "camera");
        OutlinerModel* m = m_win->outlinerModel();
        const QString text = m->data(m->indexOf({OutlinerItem::Kind::Camera, -1}, 1)).toString();
        QCOMPARE(text, QStringLiteral("at (0, 3, 12690)"));
        // The camera's page: 0.000, not -0.000.
        m_win->outliner()->setCurrentIndex(m->indexOf({OutlinerItem::Kind::Camera, -1}));
        auto* x = m_win->propertyPanel()->findChild<QDoubleSpinBox*>(QStringLiteral("camera.position.x"));
        QVERIFY(x);
        QCOMPARE(x->value(), 0.0);
        QVERIFY2(!x->text().startsWith(QLatin1Char('-')), qPrintable(x->text()));
        QCOMPARE(decimalText(-0.0004), QStringLiteral("0"));
        QCOMPARE(decimalText(2.5), QStringLiteral("2.5"));
        QCOMPARE(decimalText(-123.456), QStringLiteral("-123.5"));
        QCOMPARE(decimalText(0.0132), QStringLiteral("0.013"));
        QCOMPARE(decimalText(1.269e4), QStringLiteral("12690"));
        for (int g = 0; g < m->rowCount(); ++g) {
            const QModelIndex group = m->index(g, 0);
            for (int r = -1; r < m->rowCount(group); ++r) {
                const QString t = (r < 0 ? m->index(g, 1) : m->index(r, 1, group)).data().toString();
                QVERIFY2(!t.contains(QRegularExpression("[0-9]e[-+][0-9]")), qPrintable(t));
            }
        }
        QTreeView* tree = m_win->outliner();
        QTRY_VERIFY(tree->header()->sectionSize(1) >= tree->fontMetrics().horizontalAdvance(text));
        QVERIFY(tree->header()->sectionSize(0) >= tree->fontMetrics().horizontalAdvance(QStringLiteral("Tree_1 #2")));
        doc()->undoStack()->undo();
        doc()->undoStack()->clear();
        settle();
    }

    // A click on a crown selects that instance: the outliner's row (current and selected), the property
    // panel's page, the viewport's outline; the picture is not traced again and nothing is edited. A click
    // on the sky or the ground clears the selection and the properties.
    void clickPicksTheInstance()
    {
        Viewport* v = viewport();
        for (int i = 0; i < 2; ++i) {
            const QPoint p = at(crown(i));
            QVERIFY2(v->rect().contains(p), qPrintable(QStringLiteral("crown %1 at %2, %3").arg(i).arg(p.x()).arg(p.y())));
        }
        const quint64 requests = v->worker()->latestRequest();
        const quint64 revision = doc()->revision();
        for (int i : {1, 0, 1}) {
            QTest::mouseClick(v, Qt::LeftButton, {}, at(crown(i)));
            const OutlinerItem want{OutlinerItem::Kind::Instance, i};
            QCOMPARE(current(), want);
            QVERIFY(m_win->outliner()->selectionModel()->isSelected(m_win->outlinerModel()->indexOf(want)));
            QCOMPARE(m_win->propertyPanel()->item(), want);
            QCOMPARE(v->selectedInstance(), i);
        }
        // The pick's distance: the crown is hit before the point inside it, less than the box's diagonal before.
        const std::optional<ViewPick> hit = v->pickAt(QPointF(at(crown(1))));
        QVERIFY(hit);
        QCOMPARE(hit->instance, 1);
        const double toCrown = glm::length(crown(1) - scene().camera.position);
        QVERIFY2(hit->distance > toCrown - glm::length(m_hi - m_lo) && hit->distance < toCrown + 0.05,
                 qPrintable(QStringLiteral("%1 vs %2").arg(hit->distance).arg(toCrown)));
        QCOMPARE(v->worker()->latestRequest(), requests);   // no new trace
        QCOMPARE(doc()->revision(), revision);              // no edit
        QCOMPARE(doc()->undoStack()->count(), 0);

        // The sky (the top row) and the ground (the bottom row, between the trees): cleared.
        for (const QPoint p : {QPoint(v->width() / 2, 2), QPoint(v->width() / 2, v->height() - 3)}) {
            QTest::mouseClick(v, Qt::LeftButton, {}, at(crown(1)));
            QCOMPARE(v->selectedInstance(), 1);
            QTest::mouseClick(v, Qt::LeftButton, {}, p);
            QVERIFY(!m_win->outliner()->currentIndex().isValid());
            QVERIFY(m_win->outliner()->selectionModel()->selectedIndexes().isEmpty());
            QCOMPARE(m_win->propertyPanel()->item().kind, OutlinerItem::Kind::None);
            QCOMPARE(v->selectedInstance(), -1);
        }
        QCOMPARE(v->worker()->latestRequest(), requests);
        QCOMPARE(doc()->revision(), revision);
    }

    // Ctrl + drag on a tree slides it over the ground: the tree is selected, one "Move instance" step, its
    // height kept, and, seen from above, the point grabbed follows the cursor: some point of the tree's box on
    // the press pixel's ray lands, moved as the tree moved, on the release pixel's ray (the test's own pinhole
    // rays, solved by least squares); grabbed at eye level, a sideways drag moves it sideways. Ctrl + wheel
    // turns the selected tree 15 degrees a notch and Ctrl + Shift + wheel scales it by 1.1 a notch, a step a
    // burst. Undo puts it back; none of it touches the camera.
    void dragAndWheelEditTheInstance()
    {
        Viewport* v = viewport();
        const CameraDesc level = scene().camera;   // the eye at 4 m, the crowns about level with it
        CameraDesc above = level;
        above.position = {0.0, 14.0, -20.0};
        doc()->navigate(above);
        settle();
        QUndoStack* undo = doc()->undoStack();
        const int steps = undo->count();
        const InstanceDesc before = scene().instances[0];
        const CameraDesc camera = scene().camera;
        Scene view;   // the viewport's pinhole at its own size
        view.camera = v->viewCamera();
        view.render.width = v->width();
        view.render.height = v->height();
        const QPoint from = at(crown(0)), to = from + QPoint(90, 14);
        QTest::mousePress(v, Qt::LeftButton, Qt::ControlModifier, from);
        for (int i = 1; i <= 4; ++i) QTest::mouseMove(v, from + (to - from) * i / 4);
        QTest::mouseRelease(v, Qt::LeftButton, Qt::ControlModifier, to);
        QCOMPARE(v->selectedInstance(), 0);
        QCOMPARE(current(), (OutlinerItem{OutlinerItem::Kind::Instance, 0}));
        QCOMPARE(undo->count(), steps + 1);
        QCOMPARE(undo->undoText(), QStringLiteral("Move instance"));
        const InstanceDesc after = scene().instances[0];
        QCOMPARE(after.position.y, before.position.y);
        QCOMPARE(after.rotationDeg, before.rotationDeg);
        QCOMPARE(after.scale, before.scale);
        const glm::dvec3 delta = after.position - before.position;
        QVERIFY2(glm::length(delta) > 0.5, qPrintable(QString::number(glm::length(delta))));
        // e + t d1 + delta = e + u d2: least squares in (t, u), then the residual.
        const glm::dvec3 d1 = pinholeDirection(view, from.x(), from.y()), d2 = pinholeDirection(view, to.x(), to.y());
        const double a11 = glm::dot(d1, d1), a12 = -glm::dot(d1, d2), a22 = glm::dot(d2, d2);
        const double b1 = -glm::dot(d1, delta), b2 = glm::dot(d2, delta);
        const double det = a11 * a22 - a12 * a12;
        const double t = (b1 * a22 - a12 * b2) / det, u = (a11 * b2 - a12 * b1) / det;
        const glm::dvec3 grabbed = camera.position + t * d1;
        const double residual = glm::length(grabbed + delta - (camera.position + u * d2));
        QVERIFY2(residual < 1e-6 && t > 0.0, qPrintable(QStringLiteral("residual %1 m, t %2").arg(residual).arg(t)));
        const glm::dvec3 lo = before.position + m_lo - 0.01, hi = before.position + m_hi + 0.01;
        QVERIFY2(glm::all(glm::greaterThanEqual(grabbed, lo)) && glm::all(glm::lessThanEqual(grabbed, hi)),
                 qPrintable(QStringLiteral("grabbed %1 %2 %3").arg(grabbed.x).arg(grabbed.y).arg(grabbed.z)));

        // At eye level: a drag to the right moves the tree to the camera's right (-x here), along the ground.
        undo->undo();
        doc()->navigate(level);
        settle();
        const QPoint side = at(crown(0));
        const std::optional<ViewPick> sideHit = v->pickAt(QPointF(side), 2000);
        QVERIFY(sideHit && sideHit->instance == 0);
        QTest::mousePress(v, Qt::LeftButton, Qt::ControlModifier, side);
        for (int i = 1; i <= 4; ++i) QTest::mouseMove(v, side + QPoint(15 * i, 0));
        QTest::mouseRelease(v, Qt::LeftButton, Qt::ControlModifier, side + QPoint(60, 0));
        QCOMPARE(undo->index(), steps + 1);
        const glm::dvec3 sideways = scene().instances[0].position - before.position;
        QVERIFY2(sideways.x < -0.5 && std::abs(sideways.y) == 0.0, qPrintable(QStringLiteral("%1 %2 %3").arg(sideways.x).arg(sideways.y).arg(sideways.z)));
        const QPointF landed = project(scene().camera, v->width(), v->height(), sideHit->point + sideways);
        QVERIFY2(std::abs(landed.x() - (side.x() + 60)) < 0.75, qPrintable(QStringLiteral("%1 vs %2").arg(landed.x()).arg(side.x() + 60)));

        // Turn two notches, then scale one: two steps.
        const QPoint c = v->rect().center();
        wheel(c, 120, Qt::ControlModifier);
        wheel(c, 120, Qt::ControlModifier);
        QCOMPARE(undo->index(), steps + 2);
        QCOMPARE(undo->undoText(), QStringLiteral("Rotate instance"));
        QCOMPARE(double(scene().instances[0].rotationDeg.y), std::fmod(double(before.rotationDeg.y) + 30.0 + 360.0, 360.0));
        wheel(c, 120, Qt::ControlModifier | Qt::ShiftModifier);
        QCOMPARE(undo->index(), steps + 3);
        QCOMPARE(undo->undoText(), QStringLiteral("Scale instance"));
        QVERIFY(std::abs(scene().instances[0].scale - before.scale * 1.1f) < 1e-5f);
        QVERIFY(scene().camera.position == level.position && scene().camera.target == level.target);
        for (int i = 0; i < 3; ++i) undo->undo();
        QCOMPARE(scene().instances[0].position, before.position);
        QCOMPARE(scene().instances[0].rotationDeg, before.rotationDeg);
        QCOMPARE(scene().instances[0].scale, before.scale);
        QCOMPARE(undo->index(), steps);
        settle();
    }

    // The selected instance's box is outlined over the picture: its projected corners (the test's box,
    // projected by the test) bound the viewport's selection rectangle, and the framebuffer shows the
    // outline's orange at each of them.
    void selectionOutline()
    {
        Viewport* v = viewport();
        QTest::mouseClick(v, Qt::LeftButton, {}, at(crown(0)));
        QCOMPARE(v->selectedInstance(), 0);
        const glm::dvec3 pos = scene().instances[0].position;
        double x0 = 1e30, y0 = 1e30, x1 = -1e30, y1 = -1e30;
        const std::vector<glm::dvec3> box = corners(m_lo + pos, m_hi + pos);
        for (const glm::dvec3& c : box) {
            const QPointF p = project(scene().camera, v->width(), v->height(), c);
            x0 = std::min(x0, p.x());
            y0 = std::min(y0, p.y());
            x1 = std::max(x1, p.x());
            y1 = std::max(y1, p.y());
        }
        const QRectF r = v->selectionRect();
        QVERIFY2(std::abs(r.left() - x0) < 0.5 && std::abs(r.right() - x1) < 0.5 && std::abs(r.top() - y0) < 0.5 &&
                     std::abs(r.bottom() - y1) < 0.5,
                 qPrintable(QStringLiteral("rect %1 %2 %3 %4 vs %5 %6 %7 %8")
                                .arg(r.left()).arg(r.top()).arg(r.right()).arg(r.bottom()).arg(x0).arg(y0).arg(x1).arg(y1)));
        const QImage fb = v->grabFramebuffer().convertToFormat(QImage::Format_RGB32);
        fb.save(QString(SYLVA_TEST_OUTPUT) + "/gui_viewport_selection.png");
        const double sx = double(fb.width()) / v->width(), sy = double(fb.height()) / v->height();
        auto orange = [](QRgb c) { return qRed(c) > 200 && qGreen(c) > 110 && qGreen(c) < 210 && qBlue(c) < 90; };
        for (const glm::dvec3& c : box) {
            const QPointF p = project(scene().camera, v->width(), v->height(), c);
            bool found = false;
            for (int dy = -2; dy <= 2 && !found; ++dy)
                for (int dx = -2; dx <= 2 && !found; ++dx) {
                    const int x = int(p.x() * sx) + dx, y = int(p.y() * sy) + dy;
                    found = fb.rect().contains(x, y) && orange(fb.pixel(x, y));
                }
            QVERIFY2(found, qPrintable(QStringLiteral("no outline at %1, %2").arg(p.x()).arg(p.y())));
        }
        // The picture itself (the last image the renderer delivered) has no outline.
        QVERIFY(!v->lastImage().isNull());
        // Cleared: no outline.
        QTest::mouseClick(v, Qt::LeftButton, {}, QPoint(v->width() / 2, 2));
        QVERIFY(v->selectionRect().isEmpty());
    }

    // View > Frame All (Home) and Frame Selected (numpad period): the boxes' projected corners all inside
    // the picture, the farthest near its edge; the view direction kept; one undo step each.
    void frameAllAndSelected()
    {
        QCOMPARE(action("actionFrameAll")->shortcut(), QKeySequence(Qt::Key_Home));
        QCOMPARE(action("actionFrameSelected")->shortcut(), QKeySequence(Qt::KeypadModifier | Qt::Key_Period));
        const double w = viewport()->width(), h = viewport()->height();
        auto check = [&](const std::vector<glm::dvec3>& box, const char* what) {
            double edge = 0.0;
            for (const glm::dvec3& c : box) {
                const QPointF p = project(scene().camera, w, h, c);
                QVERIFY2(p.x() >= 0.0 && p.x() <= w && p.y() >= 0.0 && p.y() <= h,
                         qPrintable(QStringLiteral("%1: corner at %2, %3").arg(what).arg(p.x()).arg(p.y())));
                edge = std::max({edge, std::abs(2.0 * p.x() / w - 1.0), std::abs(2.0 * p.y() / h - 1.0)});
            }
            QVERIFY2(edge > 0.85 && edge <= 1.0, qPrintable(QStringLiteral("%1: farthest corner at %2 of the half-size").arg(what).arg(edge)));
        };
        // Move away first, so framing has something to do.
        Scene s = scene();
        s.camera.position = {30.0, 20.0, -60.0};
        s.camera.target = {10.0, 0.0, 0.0};
        doc()->edit(s, "away");
        const int steps = doc()->undoStack()->count();
        const glm::dvec3 dir = glm::normalize(s.camera.target - s.camera.position);
        action("actionFrameAll")->trigger();
        QVERIFY(scene().camera.position != s.camera.position);
        QCOMPARE(doc()->undoStack()->count(), steps);   // navigation: no step
        QVERIFY(glm::length(glm::normalize(scene().camera.target - scene().camera.position) - dir) < 1e-9);
        std::vector<glm::dvec3> all = corners(glm::min(m_lo + scene().instances[0].position, m_lo + scene().instances[1].position),
                                              glm::max(m_hi + scene().instances[0].position, m_hi + scene().instances[1].position));
        check(all, "frame all");
        settle();

        // Frame Selected on instance 1, selected in the outliner.
        m_win->outliner()->setCurrentIndex(m_win->outlinerModel()->indexOf({OutlinerItem::Kind::Instance, 1}));
        QCOMPARE(viewport()->selectedInstance(), 1);
        action("actionFrameSelected")->trigger();
        QCOMPARE(doc()->undoStack()->count(), steps);
        const glm::dvec3 p1 = scene().instances[1].position;
        check(corners(m_lo + p1, m_hi + p1), "frame selected");
        QVERIFY(glm::length(scene().camera.target - (0.5 * (m_lo + m_hi) + p1)) < 1e-4);
        // Nothing selected: Frame Selected does nothing.
        m_win->outliner()->selectionModel()->clear();
        const quint64 unselected = doc()->revision();
        action("actionFrameSelected")->trigger();
        QCOMPARE(doc()->revision(), unselected);
        // The keys themselves, pressed in the viewport: Home frames all, numpad period the selection (window
        // shortcuts: the window must be the active one).
        m_win->activateWindow();
        QVERIFY(QTest::qWaitForWindowActive(m_win.get()));
        viewport()->setFocus();
        QTest::mouseClick(viewport(), Qt::LeftButton, {}, at(crown(0)));
        QCOMPARE(viewport()->selectedInstance(), 0);
        const quint64 keyed = doc()->revision();
        QTest::keyClick(viewport(), Qt::Key_Period, Qt::KeypadModifier);
        QTRY_VERIFY(doc()->revision() > keyed);
        const glm::dvec3 p0 = scene().instances[0].position;
        check(corners(m_lo + p0, m_hi + p0), "numpad period");
        const quint64 homed = doc()->revision();
        QTest::keyClick(viewport(), Qt::Key_Home);
        QTRY_VERIFY(doc()->revision() > homed);
        check(all, "home");
        QCOMPARE(doc()->undoStack()->count(), steps);
        settle();
    }

    // Deleting the selected instance (and undoing it) leaves nothing selected: no properties, no outline.
    void deleteClearsTheSelection()
    {
        QTest::mouseClick(viewport(), Qt::LeftButton, {}, at(crown(1)));
        QCOMPARE(m_win->propertyPanel()->item(), (OutlinerItem{OutlinerItem::Kind::Instance, 1}));
        action("actionDelete")->trigger();
        QCOMPARE(scene().instances.size(), size_t(1));
        QCOMPARE(m_win->propertyPanel()->item().kind, OutlinerItem::Kind::None);
        QCOMPARE(viewport()->selectedInstance(), -1);
        QVERIFY(!m_win->outliner()->currentIndex().isValid());
        action("actionUndo")->trigger();
        QCOMPARE(scene().instances.size(), size_t(2));
        QCOMPARE(m_win->propertyPanel()->item().kind, OutlinerItem::Kind::None);
        QCOMPARE(viewport()->selectedInstance(), -1);
        settle();
        // The delete's request was cut short by the undo's, whose picture is the one before the delete: the
        // frame that picks is placed for the scene shown (both instances) again.
        const std::optional<ViewPick> hit = viewport()->pickAt(QPointF(at(crown(1))));
        QVERIFY(hit);
        QCOMPARE(hit->instance, 1);
    }

    // The wheel zooms toward what is under the cursor: that point stays under the cursor and comes
    // 0.85x nearer per notch. A pan drags the point it grabbed: it follows the cursor.
    void zoomAndPanFollowTheCursor()
    {
        const QPoint p = at(crown(1));
        const std::optional<ViewPick> hit = viewport()->pickAt(QPointF(p));
        QVERIFY(hit);
        QVERIFY2(hit->instance == 1, qPrintable(QStringLiteral("kind %1 instance %2 at %3, %4; eye %5 %6 %7")
                                                    .arg(int(hit->kind)).arg(hit->instance).arg(p.x()).arg(p.y())
                                                    .arg(scene().camera.position.x).arg(scene().camera.position.y).arg(scene().camera.position.z)));
        const glm::dvec3 point = hit->point;
        const double before = glm::length(point - scene().camera.position);
        const int steps = doc()->undoStack()->index();
        wheel(p, 120);
        QCOMPARE(doc()->undoStack()->index(), steps);   // navigation: no step
        const QPointF now = project(scene().camera, viewport()->width(), viewport()->height(), point);
        QVERIFY2(std::abs(now.x() - p.x()) < 0.75 && std::abs(now.y() - p.y()) < 0.75,
                 qPrintable(QStringLiteral("%1, %2 vs %3, %4").arg(now.x()).arg(now.y()).arg(p.x()).arg(p.y())));
        QVERIFY(std::abs(glm::length(point - scene().camera.position) - 0.85 * before) < 1e-6 * before);
        settle();

        // Shift + drag from the crown: the grabbed point ends under the cursor.
        const QPoint from = at(crown(1));
        const std::optional<ViewPick> grab = viewport()->pickAt(QPointF(from));
        QVERIFY(grab && grab->kind != SurfaceKind::None);
        const QPoint to = from + QPoint(-50, 20);
        QTest::mousePress(viewport(), Qt::LeftButton, Qt::ShiftModifier, from);
        QTest::mouseMove(viewport(), from + QPoint(-25, 10));
        QTest::mouseMove(viewport(), to);
        QTest::mouseRelease(viewport(), Qt::LeftButton, Qt::ShiftModifier, to);
        const QPointF moved = project(scene().camera, viewport()->width(), viewport()->height(), grab->point);
        QVERIFY2(std::abs(moved.x() - to.x()) < 0.75 && std::abs(moved.y() - to.y()) < 0.75,
                 qPrintable(QStringLiteral("%1, %2 vs %3, %4").arg(moved.x()).arg(moved.y()).arg(to.x()).arg(to.y())));
        settle();
    }

    // File > Open: the unsaved-changes question comes first; Cancel asks for no file; the chooser starts in
    // the folder of the last scene opened or saved, also in the next window (QSettings).
    void openAsksFirstAndRemembersTheFolder()
    {
        const QString folder = m_dir.filePath("scenes");
        QVERIFY(QDir().mkpath(folder));
        const QString path = QDir(folder).filePath("two.sylva.json");
        QVERIFY(m_win->saveFile(path));
        QCOMPARE(lastFolder("scenes"), QFileInfo(path).absolutePath());

        Scene s = scene();
        s.ground.height = 0.25;
        doc()->edit(s, "ground");
        QVERIFY(doc()->isModified());
        int chooserPrompts = -1;
        QString chooserFolder;
        m_win->setOpenChooser([&](const QString& f) {
            chooserPrompts = m_prompts;
            chooserFolder = f;
            return path;
        });
        m_prompts = 0;
        m_answer = QMessageBox::Cancel;
        action("actionOpen")->trigger();
        QCOMPARE(m_prompts, 1);
        QCOMPARE(chooserPrompts, -1);   // cancelled: no file asked for
        QVERIFY(doc()->isModified());

        m_answer = QMessageBox::Discard;
        action("actionOpen")->trigger();
        QCOMPARE(m_prompts, 2);
        QCOMPARE(chooserPrompts, 2);   // asked after the question, and only once
        QCOMPARE(chooserFolder, QFileInfo(path).absolutePath());
        QVERIFY(!doc()->isModified());
        QCOMPARE(scene().ground.height, 0.0);
        QCOMPARE(doc()->filePath(), QFileInfo(path).absoluteFilePath());

        // The next window's chooser starts there too.
        MainWindow other;
        other.lighting()->setAutoLighting(false);
        other.autosave()->setRecoveryPrompt([](const QString&, const QDateTime&) { return false; });
        QString otherFolder;
        other.setOpenChooser([&](const QString& f) {
            otherFolder = f;
            return QString();
        });
        other.openDialog();
        QCOMPARE(otherFolder, QFileInfo(path).absolutePath());
    }
};

QTEST_MAIN(TstStudioViewport)
#include "tst_studio_viewport.moc"
