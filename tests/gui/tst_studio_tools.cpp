// The studio's editing tools under Xvfb: autosave and crash recovery, fly navigation, scatter, side-by-side compare, leaf/wood materials, the inspector's 3D view.
#include <QAction>
#include <QCheckBox>
#include <QComboBox>
#include <QDir>
#include <QFile>
#include <QPushButton>
#include <QTabWidget>
#include <QTreeWidget>

#include <algorithm>
#include <memory>
#include <set>

#include "core/lb/lb_params.h"
#include "pipeline/cache/grid_cache.h"
#include "pipeline/scene/scene_file.h"
#include "studio/camera_nav.h"
#include "studio/render_worker.h"
#include "studio/scene_document.h"
#include "studio/volume_inspector.h"
#include "studio/volume_view.h"
#include "studio_test_util.h"
#include "tests/common/scenes.h"

using namespace sylva;
using namespace sylva::test;

namespace {

std::string json(const Scene& s) { return sceneToJson(s, "/"); }

} // namespace

class TstStudioTools : public QObject {
    Q_OBJECT

    QTemporaryDir m_dir;

    // A window as the tests want it: no automatic lighting, no blocking questions.
    std::unique_ptr<MainWindow> window(std::function<bool(const QString&, const QDateTime&)> recover = {})
    {
        auto w = std::make_unique<MainWindow>();
        w->lighting()->setAutoLighting(false);
        w->setErrorReporter([](const QString&, const QString& m) { qWarning("error: %s", qPrintable(m)); });
        w->setSavePrompt([](const QString&) { return QMessageBox::Discard; });
        w->autosave()->setRecoveryPrompt(recover ? recover : [](const QString&, const QDateTime&) { return false; });
        return w;
    }

    // A small scene: one grown shrub, two instances.
    static void compose(MainWindow& w)
    {
        w.importer()->growSpecies(GrowSpec{"shrub", 3, 2000, 0.0f});
        Scene s = w.document()->scene();
        InstanceDesc in = s.instances[0];
        in.position = {2.5, 0.0, -1.0};
        in.rotationDeg.y = 30.0f;
        s.instances.push_back(in);
        w.document()->edit(s, "add");
    }

private Q_SLOTS:
    void initTestCase()
    {
        SYLVA_SKIP_WITHOUT_X();
        QVERIFY(m_dir.isValid());
        isolate(m_dir);
    }

    // Modified untitled scene -> autosave -> the window goes without closing (a crash) -> a new window
    // offers the recovery and gets the modified scene back, modified, one undo step above an empty
    // scene; a clean save deletes the recovery file.
    void autosaveAndRecoverUntitled()
    {
        const QString rec = AutosaveController::recoveryFilePath();
        std::string want;
        {
            auto a = window();
            // The start-up recovery check is a zero-time single shot (a queued call): one pass of the event
            // loop runs it (nothing to offer).
            QCoreApplication::processEvents();
            compose(*a);
            QVERIFY(a->document()->isModified());
            QVERIFY(!QFile::exists(rec));
            QSignalSpy saved(a->autosave(), &AutosaveController::autosaved);
            a->autosave()->setInterval(50);
            QVERIFY(saved.wait(5000));
            QCOMPARE(saved.at(0).at(0).toString(), rec);
            QVERIFY(QFile::exists(rec));
            // Unchanged since: no second write.
            QVERIFY(!a->autosave()->autosaveNow());
            want = json(a->document()->scene());
            a->autosave()->setInterval(0);
        }   // destroyed without a close: what a crash leaves behind
        QVERIFY(QFile::exists(rec));

        int offered = 0;
        QString origin = "unset";
        auto b = window([&](const QString& o, const QDateTime& when) {
            ++offered;
            origin = o;
            return when.isValid();
        });
        QTRY_COMPARE(offered, 1);
        QVERIFY(origin.isEmpty());
        QCOMPARE(json(b->document()->scene()), want);
        QVERIFY(b->document()->isModified());
        QVERIFY(b->document()->filePath().isEmpty());
        QCOMPARE(b->document()->undoStack()->count(), 1);
        QVERIFY(!QFile::exists(rec));   // offered once

        // It autosaves again; a clean save removes the file.
        QVERIFY(b->autosave()->autosaveNow());
        QVERIFY(QFile::exists(rec));
        QVERIFY(b->saveFile(m_dir.filePath("recovered.sylva.json")));
        QVERIFY(!QFile::exists(rec));
        b->document()->undoStack()->setClean();
    }

    // A saved file, then edits: recovery reopens the file and puts the edits on top (undo shows the
    // saved scene); declining deletes the recovery and leaves the window empty.
    void recoverOnTopOfTheSavedFile()
    {
        const QString rec = AutosaveController::recoveryFilePath();
        const QString file = m_dir.filePath("forest.sylva.json");
        std::string saved, modified;
        {
            auto a = window();
            QCoreApplication::processEvents();   // the start-up recovery check (nothing to offer)
            compose(*a);
            QVERIFY(a->saveFile(file));
            saved = json(a->document()->scene());
            Scene s = a->document()->scene();
            s.instances[1].scale = 1.7f;
            s.sun.direction = sunDirection(25.0, 140.0);
            a->document()->edit(s, "edit");
            QVERIFY(a->autosave()->autosaveNow());
            modified = json(a->document()->scene());
        }
        QVERIFY(QFile::exists(rec));
        QString origin;
        auto b = window([&](const QString& o, const QDateTime&) {
            origin = o;
            return true;
        });
        QTRY_COMPARE(origin, QFileInfo(file).absoluteFilePath());
        QCOMPARE(json(b->document()->scene()), modified);
        QCOMPARE(b->document()->filePath(), QFileInfo(file).absoluteFilePath());
        QVERIFY(b->document()->isModified());
        b->document()->undoStack()->undo();
        QCOMPARE(json(b->document()->scene()), saved);
        QVERIFY(!b->document()->isModified());

        // Declined: gone, nothing loaded.
        b->document()->undoStack()->redo();
        QVERIFY(b->autosave()->autosaveNow());
        b.reset();
        QVERIFY(QFile::exists(rec));
        bool asked = false;
        auto c = window([&](const QString&, const QDateTime&) { return !(asked = true); });
        QTRY_VERIFY(asked);
        QVERIFY(!QFile::exists(rec));
        QVERIFY(c->document()->scene().species.empty());
        QVERIFY(!c->document()->isModified());
        // A clean close deletes a recovery file too.
        compose(*c);
        QVERIFY(c->autosave()->autosaveNow());
        QVERIFY(QFile::exists(rec));
        c->show();
        QVERIFY(c->close());
        QVERIFY(!QFile::exists(rec));
    }

    // F toggles fly mode in the viewport; W/A/S/D/Q/E move by flyStep along the camera's axes (navigation:
    // no undo step); a left drag looks around the fixed eye; F again: orbit.
    void flyNavigationInTheViewport()
    {
        auto w = window();
        w->resize(900, 600);
        w->show();
        QVERIFY(QTest::qWaitForWindowExposed(w.get()));
        compose(*w);
        Viewport* v = w->viewport();
        v->setFocus();
        const auto cam = [&] { return w->document()->scene().camera; };
        auto near = [](const glm::dvec3& a, const glm::dvec3& b) { return glm::length(a - b) < 1e-9; };
        QAction* flyAction = w->findChild<QAction*>("actionFly");
        QVERIFY(flyAction && !flyAction->isChecked());
        QTest::keyClick(v, Qt::Key_F);
        QVERIFY(v->flyMode());
        QVERIFY(flyAction->isChecked());

        const CameraDesc c0 = cam();
        const int index0 = w->document()->undoStack()->index();
        const double step = v->flyStep();
        QCOMPARE(step, std::max(0.05, 0.05 * glm::length(c0.target - c0.position)));
        QTest::keyClick(v, Qt::Key_W);
        QTest::keyClick(v, Qt::Key_W);
        QTest::keyClick(v, Qt::Key_D);
        QTest::keyClick(v, Qt::Key_E, Qt::ShiftModifier);
        const CameraDesc want = flyMove(flyMove(flyMove(flyMove(c0, 0, 0, step), 0, 0, step), step, 0, 0), 0, 5 * step, 0);
        QVERIFY(near(cam().position, want.position));
        QVERIFY(near(cam().target, want.target));
        QCOMPARE(w->document()->undoStack()->index(), index0);   // navigation: no step
        w->document()->navigate(c0);

        // Mouse look: 60 px right turns 18 degrees right about the eye.
        const QPoint at = v->rect().center();
        QTest::mousePress(v, Qt::LeftButton, {}, at);
        QTest::mouseMove(v, at + QPoint(30, 0));
        QTest::mouseRelease(v, Qt::LeftButton, {}, at + QPoint(60, 0));
        QCOMPARE(cam().position, c0.position);
        QVERIFY(near(cam().target, flyLook(c0, 18.0, 0.0).target));
        QCOMPARE(w->document()->undoStack()->index(), index0);

        // Back to orbit (through the menu action): keys move nothing, a drag moves the eye.
        flyAction->trigger();
        QVERIFY(!v->flyMode());
        const CameraDesc c1 = cam();
        QTest::keyClick(v, Qt::Key_W);
        QCOMPARE(cam().position, c1.position);
        const std::optional<ViewPick> pivot = v->pickAt(QPointF(at), 2000);
        QTest::mousePress(v, Qt::LeftButton, {}, at);
        QTest::mouseRelease(v, Qt::LeftButton, {}, at + QPoint(40, 0));
        QVERIFY(cam().position != c1.position);
        // About the point under the cursor at the press (the target over the sky).
        const QString problem = orbitPivotProblem(v, pivot, c1, cam(), at);
        QVERIFY2(problem.isEmpty(), qPrintable(problem));
        w->document()->undoStack()->setClean();
    }

    // Edit > Scatter: count instances inside the rectangle, on the ground, rotations and scales in
    // range, as ONE undo step; the same seed gives the same instances, another seed others; a bad
    // spec changes nothing; the dialog's form gives back what it was given.
    void scatterIsOneUndoStep()
    {
        auto w = window();
        QStringList errors;
        w->setErrorReporter([&](const QString&, const QString& m) { errors << m; });
        compose(*w);
        Scene base = w->document()->scene();
        base.ground.height = -0.5;
        w->document()->edit(base, "ground");
        const std::string before = json(base);
        const int index0 = w->document()->undoStack()->index();

        ScatterSpec spec;
        spec.species = 0;
        spec.count = 250;
        spec.min = {-20.0, 5.0};
        spec.max = {30.0, 9.0};
        spec.height = base.ground.height;
        spec.scaleMin = 0.7f;
        spec.scaleMax = 1.3f;
        spec.seed = 11;
        QVERIFY(w->scatterTool()->scatter(spec));
        const Scene after = w->document()->scene();
        QCOMPARE(after.instances.size(), base.instances.size() + 250);
        QCOMPARE(w->document()->undoStack()->index(), index0 + 1);
        for (size_t i = 0; i < base.instances.size(); ++i) QCOMPARE(after.instances[i].position, base.instances[i].position);
        double minX = 1e9, maxX = -1e9;
        std::set<float> rotations;
        for (size_t i = base.instances.size(); i < after.instances.size(); ++i) {
            const InstanceDesc& in = after.instances[i];
            QCOMPARE(in.species, 0u);
            QVERIFY(in.position.x >= -20.0 && in.position.x <= 30.0);
            QVERIFY(in.position.z >= 5.0 && in.position.z <= 9.0);
            QCOMPARE(in.position.y, -0.5);
            QVERIFY(in.scale >= 0.7f && in.scale <= 1.3f);
            QVERIFY(in.rotationDeg.y >= 0.0f && in.rotationDeg.y < 360.0f);
            minX = std::min(minX, in.position.x);
            maxX = std::max(maxX, in.position.x);
            rotations.insert(in.rotationDeg.y);
        }
        QVERIFY(maxX - minX > 40.0);   // spread over the area, not piled up
        QVERIFY(rotations.size() > 200);

        // One undo removes all 250; the same seed again gives the same scene.
        w->document()->undoStack()->undo();
        QCOMPARE(json(w->document()->scene()), before);
        QVERIFY(w->scatterTool()->scatter(spec));
        QCOMPARE(json(w->document()->scene()), json(after));
        w->document()->undoStack()->undo();
        spec.seed = 12;
        QVERIFY(w->scatterTool()->scatter(spec));
        QVERIFY(json(w->document()->scene()) != json(after));
        QCOMPARE(w->document()->scene().instances.size(), after.instances.size());
        w->document()->undoStack()->undo();

        // Bad specs: an error, no change.
        ScatterSpec bad = spec;
        bad.scaleMin = 0.0f;
        QVERIFY(!w->scatterTool()->scatter(bad));
        bad = spec;
        bad.species = 3;
        QVERIFY(!w->scatterTool()->scatter(bad));
        QCOMPARE(errors.size(), 2);
        QCOMPARE(json(w->document()->scene()), before);
        QCOMPARE(w->document()->undoStack()->index(), index0);

        // The form: what it is given comes back; corners typed in either order.
        ScatterSpec init = w->scatterTool()->defaultScatter();
        QCOMPARE(init.height, -0.5);
        QVERIFY(init.min.x < -1.0 && init.max.x > 1.0);   // around the instances
        init.count = 33;
        init.seed = 99;
        init.min = {8.0, -3.0};
        init.max = {2.0, 4.0};
        ScatterDialog d({"shrub 3", "other"}, init);
        const ScatterSpec got = d.spec();
        QCOMPARE(got.count, 33);
        QCOMPARE(got.seed, uint64_t(99));
        QCOMPARE(got.species, 0u);
        QCOMPARE(got.min, glm::dvec2(2.0, -3.0));
        QCOMPARE(got.max, glm::dvec2(8.0, 4.0));
        QCOMPARE(got.height, -0.5);
        w->document()->undoStack()->setClean();
    }

    // The compare toggle and second mode in the viewport's bar: with the scene in full and compare on
    // lb, the viewport's picture is full's picture on the left and lb's on the right (the same film
    // recomposed, so exactly); off again: full's picture.
    void compareToggleInTheViewport()
    {
        auto w = window();
        w->resize(900, 600);
        w->show();
        QVERIFY(QTest::qWaitForWindowExposed(w.get()));
        compose(*w);
        Scene s = w->document()->scene();
        s.species[0].grid = 12;
        w->document()->edit(s, "grid");
        Viewport* v = w->viewport();
        v->worker()->setPasses({{2, 1}});
        QSignalSpy lit(w->lighting(), &LightingScheduler::lightingFinished);
        QVERIFY(w->lighting()->computeLighting());
        QVERIFY(lit.wait(60000));
        QVERIFY(lit.at(0).at(0).toBool());
        QVERIFY(waitForFinalImage(v, 60000));
        const QImage full = v->lastImage();
        s = w->document()->scene();
        s.render.mode = RenderMode::Lb;
        w->document()->edit(s, "lb");
        QVERIFY(waitForFinalImage(v, 60000));
        const QImage lb = v->lastImage();
        QVERIFY(lb != full);
        w->document()->undoStack()->undo();
        QVERIFY(waitForFinalImage(v, 60000));
        QCOMPARE(v->lastImage(), full);

        const int steps = w->document()->undoStack()->index();
        QVERIFY(!w->compareSelector()->isEnabled());
        QCOMPARE(w->compareSelector()->currentText(), QStringLiteral("Bounce only"));
        QCOMPARE(w->compareSelector()->currentData().toInt(), int(RenderMode::Lb));
        w->compareToggle()->setChecked(true);
        QVERIFY(w->compareSelector()->isEnabled());
        QCOMPARE(v->compare(), std::optional<RenderMode>(RenderMode::Lb));
        QVERIFY(waitForFinalImage(v, 60000));
        const QImage cmp = v->lastImage();
        QCOMPARE(cmp.size(), full.size());
        const int split = cmp.width() / 2;
        QCOMPARE(cmp.copy(0, 0, split, cmp.height()), full.copy(0, 0, split, full.height()));
        QCOMPARE(cmp.copy(split, 0, cmp.width() - split, cmp.height()), lb.copy(split, 0, lb.width() - split, lb.height()));
        QCOMPARE(w->document()->undoStack()->index(), steps);   // a view setting, not a scene edit

        w->compareToggle()->setChecked(false);
        QVERIFY(!v->compare());
        QVERIFY(waitForFinalImage(v, 60000));
        QCOMPARE(v->lastImage(), full);
        w->document()->undoStack()->setClean();
    }

    // Edit > Species Materials on the imported Tree_1 (Tree_1.mtl: "Bark" and "Tree_Leaves"; by the
    // importer's rules the leaf-named one is leaf, bark is wood): the dialog starts from the rules,
    // Leaf and Wood exclude each other, the answer becomes the species' leaf_materials in one undo
    // step, the next opening starts from that list, "Importer's Rules" writes an empty list again.
    void materialAssignment()
    {
        auto w = window();
        QStringList errors;
        w->setErrorReporter([&](const QString&, const QString& m) { errors << m; });
        QVERIFY(waitForJob(w->importer()->importMesh(sharedTree()), 30000));
        QVERIFY(w->document()->scene().species[0].leafMaterials.empty());
        std::vector<MaterialChoice> seen;
        w->materials()->setMaterialEditor([&](const QString& species, const std::vector<MaterialChoice>& m) {
            seen = m;
            MaterialDialog d(species, m);
            const int bark = m[0].name == "Bark" ? 0 : 1;
            // The user ticks Leaf on the bark: its Wood box clears.
            d.table()->topLevelItem(bark)->setCheckState(MaterialDialog::LeafColumn, Qt::Checked);
            if (d.table()->topLevelItem(bark)->checkState(MaterialDialog::WoodColumn) != Qt::Unchecked) return std::optional<std::vector<std::string>>();
            return std::optional(d.leafMaterials());
        });
        const int index0 = w->document()->undoStack()->index();
        QVERIFY(waitForJob(w->materials()->editMaterials(0), 30000));
        QCOMPARE(seen.size(), size_t(2));
        QStringList names{seen[0].name, seen[1].name};
        names.sort();
        QCOMPARE(names, (QStringList{"Bark", "Tree_Leaves"}));
        for (const MaterialChoice& c : seen) {
            QCOMPARE(c.leafByRules, c.name == "Tree_Leaves");
            QCOMPARE(c.leaf, c.leafByRules);
        }
        std::vector<std::string> got = w->document()->scene().species[0].leafMaterials;
        std::sort(got.begin(), got.end());
        QCOMPARE(got, (std::vector<std::string>{"Bark", "Tree_Leaves"}));
        QCOMPARE(w->document()->undoStack()->index(), index0 + 1);
        QVERIFY(QString::fromStdString(sceneToJson(w->document()->scene(), "/")).contains("leaf_materials"));

        // Again: the dialog starts from the list; back to the importer's rules = an empty list.
        w->materials()->setMaterialEditor([&](const QString& species, const std::vector<MaterialChoice>& m) {
            seen = m;
            MaterialDialog d(species, m);
            d.resetToRules();
            return std::optional(d.leafMaterials());
        });
        QVERIFY(waitForJob(w->materials()->editMaterials(0), 30000));
        for (const MaterialChoice& c : seen) QVERIFY(c.leaf);
        QVERIFY(w->document()->scene().species[0].leafMaterials.empty());
        QCOMPARE(w->document()->undoStack()->index(), index0 + 2);
        w->document()->undoStack()->undo();
        QCOMPARE(w->document()->scene().species[0].leafMaterials.size(), size_t(2));
        w->document()->undoStack()->undo();
        QVERIFY(w->document()->scene().species[0].leafMaterials.empty());

        // Cancelled: nothing changes.
        w->materials()->setMaterialEditor([](const QString&, const std::vector<MaterialChoice>&) { return std::optional<std::vector<std::string>>(); });
        QVERIFY(waitForJob(w->materials()->editMaterials(0), 30000));
        QCOMPARE(w->document()->undoStack()->index(), index0);

        // No leaf at all cannot be said (an empty list means the rules): OK is disabled.
        MaterialDialog d("Tree_1", {{"Bark", false, false}, {"Tree_Leaves", true, true}});
        QVERIFY(d.okButton()->isEnabled());
        d.table()->topLevelItem(1)->setCheckState(MaterialDialog::WoodColumn, Qt::Checked);
        QVERIFY(!d.isLeaf(1));
        QCOMPARE(d.table()->topLevelItem(1)->checkState(MaterialDialog::LeafColumn), Qt::Unchecked);
        QVERIFY(!d.okButton()->isEnabled());

        // A grown species has no materials to assign.
        w->importer()->growSpecies(GrowSpec{"shrub", 1, 2000, 0.0f});
        QVERIFY(!w->materials()->editMaterials(1));
        QCOMPARE(errors.size(), 1);
        QVERIFY(errors[0].contains("grown"));
        w->document()->undoStack()->setClean();
    }

    // The inspector's 3D view under Xvfb (Mesa): a grown shrub's density ray marched with single
    // scattering draws the plant over the background; an empty grid draws only the background; the
    // picture follows the light (sun above vs below) and the LB lighting mode draws too.
    void volumeViewRendersTheGrid()
    {
        Scene one;
        one.species.push_back(test::shrubSpecies(16));
        GridCache cache(m_dir.filePath("cache-3d").toStdString());
        auto grids = std::make_shared<const SpeciesGrids>(loadSpeciesGrids(one, 0, &cache));

        VolumeInspector insp;
        insp.resize(420, 560);
        insp.setGrids("shrub", grids);
        insp.show();
        QVERIFY(QTest::qWaitForWindowExposed(&insp));
        QVERIFY(!insp.volumeView());   // made on first use only
        insp.tabs()->setCurrentIndex(1);
        VolumeView* v = insp.volumeView();
        QVERIFY(v);
        QTRY_VERIFY(v->isValid());
        const QColor bg = VolumeView::background();
        auto stats = [&](const QImage& img, int* differing) {
            *differing = 0;
            for (int y = 0; y < img.height(); ++y)
                for (int x = 0; x < img.width(); ++x) {
                    const QRgb p = img.pixel(x, y);
                    if (std::abs(qRed(p) - bg.red()) + std::abs(qGreen(p) - bg.green()) + std::abs(qBlue(p) - bg.blue()) > 6) ++*differing;
                }
        };
        v->setView(30.0f, 15.0f, 2.4f);
        v->setSunDirection({0.3f, 1.0f, 0.2f});
        const QImage above = v->grabFramebuffer();
        QVERIFY2(v->problem().isEmpty(), qPrintable(v->problem()));
        QVERIFY(above.width() > 100);
        int differing = 0;
        stats(above, &differing);
        const double share = double(differing) / double(above.width() * above.height());
        QVERIFY2(share > 0.02 && share < 0.9, qPrintable(QString("%1 of the pixels show the plant").arg(share)));
        double mean = 0.0, sd = 0.0;
        lumaStats(above, &mean, &sd);
        QVERIFY2(sd > 3.0, qPrintable(QString::number(sd)));
        const QRgb corner = above.pixel(2, 2);
        QVERIFY(std::abs(qRed(corner) - bg.red()) <= 2 && std::abs(qBlue(corner) - bg.blue()) <= 2);
        QImage shot = above;
        shot.save(QString(SYLVA_TEST_OUTPUT) + "/gui_volume_view.png");

        // The light matters: from below, the plant is lit differently.
        v->setSunDirection({0.3f, -1.0f, 0.2f});
        const QImage below = v->grabFramebuffer();
        QVERIFY(below != above);
        // LB lighting draws too, and differently.
        insp.volumeLightingBox()->setCurrentIndex(1);
        QCOMPARE(v->lighting(), VolumeView::Lighting::Lb);
        const QImage lbPicture = v->grabFramebuffer();
        stats(lbPicture, &differing);
        QVERIFY(differing > above.width() * above.height() / 50);
        QVERIFY(lbPicture != above);

        // No medium: the background only.
        auto empty = std::make_shared<SpeciesGrids>(*grids);
        std::fill(empty->density.density.begin(), empty->density.density.end(), 0.0f);
        insp.setGrids("empty", empty);
        stats(v->grabFramebuffer(), &differing);
        QCOMPARE(differing, 0);
    }
};

QTEST_MAIN(TstStudioTools)
#include "tst_studio_tools.moc"
