// The studio's document and outliner without GL: undo/redo and merging, modified state, save and
// reopen, the outliner model under QAbstractItemModelTester, the property panel's edits, navigation math.
#include <QAbstractItemModelTester>
#include <QDial>
#include <QComboBox>
#include <QDoubleSpinBox>
#include <QLineEdit>
#include <QSignalSpy>
#include <QSpinBox>
#include <QStandardPaths>
#include <QTemporaryDir>
#include <QTest>

#include <algorithm>
#include <cmath>

#include "core/base/error.h"
#include "core/lb/lb_params.h"
#include "core/render/render_scene.h"
#include "core/render/shade.h"
#include "pipeline/scene/scene_file.h"
#include "studio/camera_nav.h"
#include "studio/outliner_model.h"
#include "studio/property_panel.h"
#include "studio/scene_document.h"

using namespace sylva;

namespace {

QString sharedTree() { return QStringLiteral(SYLVA_RESOURCES "/trees/quaternius/OBJ/Tree_1.obj"); }

Scene treeScene(int instances)
{
    Scene s;
    SpeciesDesc sp;
    sp.name = "Tree_1";
    sp.meshPath = sharedTree().toStdString();
    sp.lighting = lb::paramsFromPreset(*lb::findPreset("leaf"));
    s.species.push_back(sp);
    for (int i = 0; i < instances; ++i) {
        InstanceDesc in;
        in.position = {2.0 * i, 0.0, 0.0};
        s.instances.push_back(in);
    }
    return s;
}

} // namespace

class TstSceneDocument : public QObject {
    Q_OBJECT

private Q_SLOTS:
    void initTestCase() { QStandardPaths::setTestModeEnabled(true); }

    void editUndoRedo()
    {
        SceneDocument doc;
        QSignalSpy changed(&doc, &SceneDocument::changed);
        QVERIFY(!doc.isModified());
        Scene s = treeScene(1);
        doc.edit(s, "add");
        QVERIFY(doc.isModified());
        QCOMPARE(changed.count(), 1);
        QVERIFY(hasPart(changed.last().at(0).value<ScenePart>(), ScenePart::Species));
        s.instances[0].position.x = 3.0;
        doc.edit(s, "move");
        QCOMPARE(changed.last().at(0).value<ScenePart>(), ScenePart::Instances);
        QCOMPARE(doc.undoStack()->count(), 2);
        doc.undoStack()->undo();
        QCOMPARE(doc.scene().instances[0].position.x, 0.0);
        doc.undoStack()->redo();
        QCOMPARE(doc.scene().instances[0].position.x, 3.0);
        // An edit that changes nothing is not a step.
        doc.edit(doc.scene(), "nothing");
        QCOMPARE(doc.undoStack()->count(), 2);
        doc.undoStack()->undo();
        doc.undoStack()->undo();
        QVERIFY(!doc.isModified());
        QVERIFY(doc.scene().species.empty());
    }

    void mergeKeysCollapseGestures()
    {
        SceneDocument doc;
        doc.reset(treeScene(1), QString());
        const int drag = SceneDocument::newMergeKey();
        for (int i = 1; i <= 5; ++i) {
            Scene s = doc.scene();
            s.camera.position.x = i;
            doc.edit(s, "navigate", drag);
        }
        QCOMPARE(doc.undoStack()->count(), 1);
        const int other = SceneDocument::newMergeKey();
        Scene s = doc.scene();
        s.camera.position.y = 9.0;
        doc.edit(s, "navigate", other);
        QCOMPARE(doc.undoStack()->count(), 2);
        doc.undoStack()->undo();
        QCOMPARE(doc.scene().camera.position.x, 5.0);
        doc.undoStack()->undo();
        QCOMPARE(doc.scene().camera.position.x, 0.0);
        // After undo, an edit with an old key starts a new step instead of folding into history.
        doc.undoStack()->redo();
        s = doc.scene();
        s.camera.position.z = 1.0;
        doc.edit(s, "navigate", drag);
        QCOMPARE(doc.undoStack()->count(), 2);
        doc.undoStack()->undo();
        QCOMPARE(doc.scene().camera.position.x, 5.0);
        QCOMPARE(doc.scene().camera.position.z, -10.0);
    }

    void saveAndReopen()
    {
        QTemporaryDir dir;
        SceneDocument doc;
        doc.reset(treeScene(3), QString());
        Scene s = doc.scene();
        s.sun.direction = sunDirection(30.0, 120.0);
        s.sun.temperature = 4500.0;
        s.instances[1].rotationDeg = {0.0f, 45.0f, 0.0f};
        s.instances[2].scale = 1.5f;
        s.species[0].grid = 16;
        doc.edit(s, "tweak");
        QVERIFY(doc.isModified());
        const QString path = dir.filePath("sub/forest.sylva.json");
        doc.saveAs(path);
        QVERIFY(!doc.isModified());
        QCOMPARE(doc.filePath(), path);
        SceneDocument reopened;
        reopened.open(path);
        const std::string base = dir.path().toStdString();
        QCOMPARE(QString::fromStdString(sceneToJson(reopened.scene(), base)), QString::fromStdString(sceneToJson(doc.scene(), base)));
        QCOMPARE(changedParts(reopened.scene(), doc.scene()), ScenePart::None);
    }

    // A new document (no plants: ground and sky) saves and reads back; a file that cannot be written or read
    // is an error that leaves the document as it was.
    void saveAndOpenErrors()
    {
        QTemporaryDir dir;
        SceneDocument doc;
        doc.saveAs(dir.filePath("empty.sylva.json"));
        SceneDocument reopened;
        reopened.open(dir.filePath("empty.sylva.json"));
        QVERIFY(reopened.scene().species.empty() && reopened.scene().instances.empty());
        const std::string base = dir.path().toStdString();
        QCOMPARE(QString::fromStdString(sceneToJson(reopened.scene(), base)), QString::fromStdString(sceneToJson(doc.scene(), base)));
        SceneDocument other;
        QFile plain(dir.filePath("plain"));   // a file where the folder should be
        QVERIFY(plain.open(QIODevice::WriteOnly));
        plain.close();
        QVERIFY_THROWS_EXCEPTION(Error, other.saveAs(dir.filePath("plain/x.sylva.json")));
        QVERIFY(other.filePath().isEmpty());
        QVERIFY_THROWS_EXCEPTION(Error, other.open(dir.filePath("missing.sylva.json")));
        QVERIFY(other.filePath().isEmpty());
    }

    void outlinerModel()
    {
        SceneDocument doc;
        OutlinerModel model(&doc);
        QAbstractItemModelTester tester(&model, QAbstractItemModelTester::FailureReportingMode::QtTest);
        QCOMPARE(model.rowCount(), int(OutlinerModel::GroupCount));
        QCOMPARE(model.rowCount(model.index(OutlinerModel::SpeciesGroup, 0)), 0);
        doc.edit(treeScene(4), "add");
        QCOMPARE(model.rowCount(model.index(OutlinerModel::SpeciesGroup, 0)), 1);
        QCOMPARE(model.rowCount(model.index(OutlinerModel::InstancesGroup, 0)), 4);
        const QModelIndex inst = model.indexOf({OutlinerItem::Kind::Instance, 2});
        QCOMPARE(model.data(inst).toString(), QStringLiteral("Tree_1 #3"));
        QCOMPARE(model.itemAt(inst), (OutlinerItem{OutlinerItem::Kind::Instance, 2}));
        QCOMPARE(model.parent(inst), model.index(OutlinerModel::InstancesGroup, 0));
        QCOMPARE(model.itemAt(model.index(OutlinerModel::SunGroup, 0)).kind, OutlinerItem::Kind::Sun);
        QCOMPARE(model.data(model.indexOf({OutlinerItem::Kind::Species, 0})).toString(), QStringLiteral("Tree_1"));
        // Same shape: dataChanged; new shape: reset. The tester checks both.
        QSignalSpy dataChanged(&model, &QAbstractItemModel::dataChanged);
        Scene s = doc.scene();
        s.instances[2].position.x = 7.0;
        doc.edit(s, "move");
        QVERIFY(dataChanged.count() > 0);
        QVERIFY(model.data(model.indexOf({OutlinerItem::Kind::Instance, 2}, 1)).toString().contains("7"));
        s.instances.pop_back();
        doc.edit(s, "delete");
        QCOMPARE(model.rowCount(model.index(OutlinerModel::InstancesGroup, 0)), 3);
        doc.undoStack()->undo();
        QCOMPARE(model.rowCount(model.index(OutlinerModel::InstancesGroup, 0)), 4);
        doc.reset(Scene{}, QString());
        QCOMPARE(model.rowCount(model.index(OutlinerModel::InstancesGroup, 0)), 0);
    }

    void propertyPanelEdits()
    {
        SceneDocument doc;
        doc.reset(treeScene(2), QString());
        PropertyPanel panel(&doc);
        panel.showItem({OutlinerItem::Kind::Instance, 1});
        QCOMPARE(panel.instancePosition(0)->value(), 2.0);
        panel.instancePosition(0)->setValue(4.5);
        panel.instancePosition(0)->setValue(5.5);   // one editor in a row: one undo step
        panel.instanceScale()->setValue(2.0);
        QCOMPARE(doc.scene().instances[1].position.x, 5.5);
        QCOMPARE(doc.scene().instances[1].scale, 2.0f);
        QCOMPARE(doc.undoStack()->count(), 2);
        doc.undoStack()->undo();
        QCOMPARE(panel.instanceScale()->value(), 1.0);   // the panel follows undo
        doc.undoStack()->undo();
        QCOMPARE(panel.instancePosition(0)->value(), 2.0);

        panel.showItem({OutlinerItem::Kind::Sun, -1});
        panel.sunElevation()->setValue(20.0);
        panel.sunAzimuthDial()->setValue(90);
        double el = 0.0, az = 0.0;
        sunAngles(doc.scene().sun.direction, &el, &az);
        QVERIFY(std::abs(el - 20.0) < 1e-3);
        QVERIFY(std::abs(az - 90.0) < 1e-3);
        panel.sunTemperature()->setValue(3200.0);
        QCOMPARE(doc.scene().sun.temperature, 3200.0);

        panel.showItem({OutlinerItem::Kind::Species, 0});
        panel.speciesGrid()->setValue(16);
        QCOMPARE(doc.scene().species[0].grid, 16);
        panel.speciesPreset()->setCurrentText("cloud");
        QCOMPARE(QString::fromStdString(doc.scene().species[0].preset), QStringLiteral("cloud"));
        QCOMPARE(doc.scene().species[0].lighting.zeroF0, lb::findPreset("cloud")->zeroF0);
        QCOMPARE(doc.scene().species[0].grid, 16);   // the preset leaves the grid alone
        panel.speciesName()->setText("Oak");
        Q_EMIT panel.speciesName()->editingFinished();
        QCOMPARE(QString::fromStdString(doc.scene().species[0].name), QStringLiteral("Oak"));
        panel.speciesName()->setText("  ");   // names stay non-empty (and unique)
        Q_EMIT panel.speciesName()->editingFinished();
        QCOMPARE(QString::fromStdString(doc.scene().species[0].name), QStringLiteral("Oak"));
        QCOMPARE(panel.speciesName()->text(), QStringLiteral("Oak"));
    }

    void navigation()
    {
        CameraDesc c;
        c.position = {0.0, 2.0, -10.0};
        c.target = {0.0, 2.0, 0.0};
        const double d0 = glm::length(c.position - c.target);
        const CameraDesc o = orbitCamera(c, 90.0, 0.0);
        QVERIFY(std::abs(glm::length(o.position - o.target) - d0) < 1e-9);
        QVERIFY(std::abs(o.position.x - -10.0) < 1e-9 || std::abs(o.position.x - 10.0) < 1e-9);
        const CameraDesc up = orbitCamera(c, 0.0, 200.0);   // clamped short of the pole
        QVERIFY(up.position.y - up.target.y < d0);
        QVERIFY(up.position.y > up.target.y);
        const CameraDesc p = panCamera(c, 100.0, 0.0, 500.0);
        QCOMPARE(p.position - c.position, p.target - c.target);
        QVERIFY(p.target.x != 0.0);
        const CameraDesc z = zoomCamera(c, 1.0);
        QVERIFY(std::abs(glm::length(z.position - z.target) - 0.85 * d0) < 1e-9);
        QCOMPARE(z.target, c.target);
        double el = 0.0, az = 0.0;
        sunAngles(sunDirection(35.0, 250.0), &el, &az);
        QVERIFY(std::abs(el - 35.0) < 1e-4 && std::abs(az - 250.0) < 1e-4);
    }

    // No movement is no change (bit for bit: a click must not become a camera edit); zoom about a point keeps
    // it on its pixel; a pan at a depth carries a point at that depth with the cursor; framing puts the box's
    // farthest projected corner at `fill`; projectToView inverts the renderer's cameraRay; instance boxes.
    void navigationAboutPoints()
    {
        CameraDesc c;
        c.position = {3.0, 4.0, -12.0};
        c.target = {0.5, 2.0, 1.0};
        auto same = [](const CameraDesc& a, const CameraDesc& b) { return a.position == b.position && a.target == b.target; };
        QVERIFY(same(orbitCamera(c, 0.0, 0.0), c));
        QVERIFY(same(flyLook(c, 0.0, 0.0), c));
        QVERIFY(same(panCamera(c, 0.0, 0.0, 360.0, 7.0), c));
        QVERIFY(same(zoomCameraAbout(c, 0.0, {1.0, 1.0, 1.0}), c));

        const double w = 640.0, h = 360.0;
        // projectToView against the renderer's own camera ray through a pixel (core/render/shade.h).
        RenderView v{};
        v.camera = makeCamera(c, int(w), int(h));
        v.width = int(w);
        v.height = int(h);
        for (const glm::dvec2 px : {glm::dvec2(10.5, 20.5), glm::dvec2(320.0, 180.0), glm::dvec2(600.25, 300.75)}) {
            const Ray r = cameraRay(v, float(px.x), float(px.y));
            glm::dvec2 back;
            QVERIFY(projectToView(c, w, h, c.position + 25.0 * glm::dvec3(r.dir), &back));
            QVERIFY2(glm::length(back - px) < 1e-3, qPrintable(QString("%1 %2 vs %3 %4").arg(back.x).arg(back.y).arg(px.x).arg(px.y)));
        }
        glm::dvec2 behind;
        QVERIFY(!projectToView(c, w, h, c.position - (c.target - c.position), &behind));

        // viewRayDirection is the renderer's ray; viewRayOnPlane: it meets the plane y = 0.5 (and the vertical
        // plane x = 1) at a point on that ray, in the plane, projected back onto the pixel, and the plane y = 0.5
        // not at all for a pixel above the horizon (the ray rises away from a plane below the eye).
        for (const glm::dvec2 px : {glm::dvec2(10.5, 300.5), glm::dvec2(320.0, 340.0), glm::dvec2(600.25, 350.75)}) {
            const glm::dvec3 dir = glm::normalize(glm::dvec3(cameraRay(v, float(px.x), float(px.y)).dir));
            QVERIFY(glm::length(viewRayDirection(c, w, h, px) - dir) < 1e-6);
            for (const auto& [point, normal] : {std::pair{glm::dvec3(0.0, 0.5, 0.0), glm::dvec3(0.0, 1.0, 0.0)},
                                                std::pair{glm::dvec3(1.0, 0.0, 0.0), glm::dvec3(1.0, 0.0, 0.0)}}) {
                glm::dvec3 onPlane;
                if (normal.x > 0.0 && dir.x * (1.0 - c.position.x) <= 0.0) continue;   // that plane is behind this ray
                QVERIFY(viewRayOnPlane(c, w, h, px, point, normal, &onPlane));
                QVERIFY(std::abs(glm::dot(onPlane - point, normal)) < 1e-9);
                QVERIFY(glm::length(glm::normalize(onPlane - c.position) - dir) < 1e-6);
                glm::dvec2 back;
                QVERIFY(projectToView(c, w, h, onPlane, &back));
                QVERIFY(glm::length(back - px) < 1e-6);
            }
        }
        glm::dvec3 none;
        QVERIFY(!viewRayOnPlane(c, w, h, glm::dvec2(320.0, 2.0), glm::dvec3(0.0, 0.5, 0.0), glm::dvec3(0.0, 1.0, 0.0), &none));

        // Zoom about a point off the axis: it stays on its pixel, 0.85x as far; the view direction stays.
        const glm::dvec3 p(-2.0, 1.0, 3.0);
        glm::dvec2 before, after;
        QVERIFY(projectToView(c, w, h, p, &before));
        const CameraDesc z = zoomCameraAbout(c, 1.0, p);
        QVERIFY(projectToView(z, w, h, p, &after));
        QVERIFY(glm::length(after - before) < 1e-9);
        QVERIFY(std::abs(glm::length(z.position - p) - 0.85 * glm::length(c.position - p)) < 1e-9);
        QVERIFY(glm::length(glm::normalize(z.target - z.position) - glm::normalize(c.target - c.position)) < 1e-12);
        const CameraDesc zt = zoomCameraAbout(c, 2.0, c.target), zz = zoomCamera(c, 2.0);
        QVERIFY(glm::length(zt.position - zz.position) < 1e-12 && zt.target == zz.target);

        // Pan at p's depth: p moves with the cursor.
        const double depth = glm::dot(p - c.position, glm::normalize(c.target - c.position));
        const CameraDesc pan = panCamera(c, 40.0, -25.0, h, depth);
        QVERIFY(projectToView(pan, w, h, p, &after));
        QVERIFY2(glm::length(after - (before + glm::dvec2(40.0, -25.0))) < 1e-6, qPrintable(QString("%1 %2").arg(after.x).arg(after.y)));

        // Framing a box: every corner inside, the farthest at 90% of the half-size, the direction kept.
        Bounds3 box;
        box.extend({-4.0f, 0.0f, 2.0f});
        box.extend({6.0f, 3.0f, 5.0f});
        const CameraDesc f = frameBoxCamera(c, box, w / h);
        QVERIFY(glm::length(glm::normalize(f.target - f.position) - glm::normalize(c.target - c.position)) < 1e-12);
        double edge = 0.0;
        for (int k = 0; k < 8; ++k) {
            const glm::dvec3 q((k & 1) ? box.hi.x : box.lo.x, (k & 2) ? box.hi.y : box.lo.y, (k & 4) ? box.hi.z : box.lo.z);
            glm::dvec2 at;
            QVERIFY(projectToView(f, w, h, q, &at));
            edge = std::max({edge, std::abs(2.0 * at.x / w - 1.0), std::abs(2.0 * at.y / h - 1.0)});
        }
        QVERIFY2(std::abs(edge - 0.9) < 1e-6, qPrintable(QString::number(edge)));

        // An instance turned 90 degrees about y (x -> -z), scaled 2, at (10, 0, 0).
        Bounds3 mesh;
        mesh.extend({-1.0f, 0.0f, -0.5f});
        mesh.extend({1.0f, 4.0f, 0.5f});
        InstanceDesc in;
        in.position = {10.0, 0.0, 0.0};
        in.rotationDeg = {0.0f, 90.0f, 0.0f};
        in.scale = 2.0f;
        const Bounds3 b = instanceBounds(Scene{}, in, mesh);
        QVERIFY(glm::length(b.lo - glm::vec3(9.0f, 0.0f, -2.0f)) < 1e-5f && glm::length(b.hi - glm::vec3(11.0f, 8.0f, 2.0f)) < 1e-5f);
        Scene two;
        two.instances = {in, InstanceDesc{}};
        const Bounds3 all = sceneBounds(two, {mesh});
        QVERIFY(glm::length(all.lo - glm::vec3(-1.0f, 0.0f, -2.0f)) < 1e-5f && glm::length(all.hi - glm::vec3(11.0f, 8.0f, 2.0f)) < 1e-5f);
    }

    // A gesture of merged edits that ends where it began leaves no undo step, and a clean document clean.
    void gestureBackToStartLeavesNoStep()
    {
        SceneDocument doc;
        Scene s;
        s.camera.position = {0.0, 2.0, -10.0};
        doc.reset(s, QString());
        const int key = SceneDocument::newMergeKey();
        Scene moved = s;
        moved.camera.position.x = 3.0;
        doc.edit(moved, "Navigate", key);
        QCOMPARE(doc.undoStack()->count(), 1);
        QVERIFY(doc.isModified());
        doc.edit(s, "Navigate", key);
        QCOMPARE(doc.undoStack()->count(), 0);
        QVERIFY(!doc.isModified());
        QCOMPARE(doc.scene().camera.position, s.camera.position);
    }

    // Fly navigation: looking turns the view about a fixed eye, moving carries eye and target along
    // the camera's own axes. Expected values worked out by hand for a camera at (1, 2, -10) looking
    // down +Z (its right is -X: right = view x up).
    void flyNavigation()
    {
        CameraDesc c;
        c.position = {1.0, 2.0, -10.0};
        c.target = {1.0, 2.0, -6.0};   // 4 m ahead along +Z
        auto near = [](const glm::dvec3& a, const glm::dvec3& b) { return glm::length(a - b) < 1e-9; };

        // Turn right 90 degrees: now looking down -X, same eye, same distance.
        const CameraDesc r = flyLook(c, 90.0, 0.0);
        QVERIFY(near(r.position, c.position));
        QVERIFY2(near(r.target, {-3.0, 2.0, -10.0}), qPrintable(QString("%1 %2 %3").arg(r.target.x).arg(r.target.y).arg(r.target.z)));
        // Turn left 90: +X.
        QVERIFY(near(flyLook(c, -90.0, 0.0).target, {5.0, 2.0, -10.0}));
        // Look up 30 degrees: the target rises by 4 sin 30 and comes in to 4 cos 30.
        const CameraDesc u = flyLook(c, 0.0, 30.0);
        QVERIFY(near(u.target, {1.0, 2.0 + 2.0, -10.0 + 4.0 * std::cos(30.0 * 3.14159265358979323846 / 180.0)}));
        // Never over the pole.
        const CameraDesc top = flyLook(c, 0.0, 500.0);
        const glm::dvec3 v = glm::normalize(top.target - top.position);
        QVERIFY(std::abs(std::asin(v.y) * 180.0 / 3.14159265358979323846 - 89.0) < 1e-9);
        // Look is reversible.
        QVERIFY(near(flyLook(flyLook(c, 37.0, 0.0), -37.0, 0.0).target, c.target));

        // Forward 2 m, right 1 m, up 0.5 m: eye and target by the same vector.
        const CameraDesc m = flyMove(c, 1.0, 0.5, 2.0);
        QVERIFY(near(m.position, {0.0, 2.5, -8.0}));
        QVERIFY(near(m.target - m.position, c.target - c.position));
        // Looking up 30 degrees, forward goes up the view line; up stays world up.
        const CameraDesc mu = flyMove(u, 0.0, 1.0, 2.0);
        QVERIFY(near(mu.position - u.position, 2.0 * glm::normalize(u.target - u.position) + glm::dvec3(0.0, 1.0, 0.0)));
        // Straight down: the right axis comes from the camera's up vector, nothing degenerates.
        CameraDesc down = c;
        down.target = c.position + glm::dvec3(0.0, -3.0, 0.0);
        down.up = glm::vec3(0.0f, 0.0f, 1.0f);
        const CameraDesc md = flyMove(down, 1.0, 0.0, 0.0);
        QVERIFY(std::abs(glm::length(md.position - down.position) - 1.0) < 1e-9);
    }
};

QTEST_MAIN(TstSceneDocument)
#include "tst_scene_document.moc"
