// The studio's landscapes and volumes under Xvfb: a landscape scene
// opened, flown over (the picture changes, nothing is built again), its density and a tile edited (the
// picture changes without a new frame build; the density-updated picture equals a whole build's); a
// cloud added through its dialog (a volume in the scene and the outliner, the picture changes where the
// cloud is and nowhere else, undo restores the picture); a smoke job cancelled with nothing changed and
// one that completes adding a volume.
#include <QAction>
#include <QCheckBox>
#include <QDir>
#include <QDoubleSpinBox>
#include <QFile>
#include <QTimer>
#include <QTreeView>

#include <cmath>
#include <memory>

#include "studio/camera_nav.h"
#include "studio/outliner_model.h"
#include "studio/property_panel.h"
#include "studio/render_worker.h"
#include "studio/scene_document.h"
#include "studio/scene_item_pages.h"
#include "studio/volume_dialogs.h"
#include "studio/volume_inspector.h"
#include "studio_picture.h"
#include "studio_test_util.h"

using namespace sylva;
using namespace sylva::test;

namespace {

// Mean absolute luminance difference over the rectangle (fractions of the picture).
double meanDiff(const QImage& a, const QImage& b, double x0, double y0, double x1, double y1)
{
    const QImage x = a.convertToFormat(QImage::Format_RGB32), y = b.convertToFormat(QImage::Format_RGB32);
    double s = 0.0;
    int n = 0;
    for (int j = int(y0 * x.height()); j < int(y1 * x.height()); ++j)
        for (int i = int(x0 * x.width()); i < int(x1 * x.width()); ++i) {
            const QRgb p = x.pixel(i, j), q = y.pixel(i, j);
            s += std::abs(qGray(p) - qGray(q));
            ++n;
        }
    return n ? s / n : 0.0;
}

} // namespace

class TstStudioLandVol : public QObject {
    Q_OBJECT

    QTemporaryDir m_dir;

    std::unique_ptr<MainWindow> window()
    {
        auto w = std::make_unique<MainWindow>();
        w->setErrorReporter([](const QString&, const QString& m) { qWarning("error: %s", qPrintable(m)); });
        w->setSavePrompt([](const QString&) { return QMessageBox::Discard; });
        w->resize(900, 640);
        w->show();
        return w;
    }

    // The viewport's settled picture after whatever was just asked of it: a new final picture, shown for
    // the worker's newest request, with no lighting job running or about to start (a request that raced
    // the one just shown, e.g. from a lighting job ending, is waited for the same way).
    static QImage settled(MainWindow& w, int timeoutMs = 60000)
    {
        Viewport* v = w.viewport();
        quint64 finalFor = 0;   // the worker's newest request when the latest final picture was shown (0: none since)
        const QMetaObject::Connection c = QObject::connect(v, &Viewport::imageShown, v, [&](int, bool last, double) {
            finalFor = last ? v->worker()->latestRequest() : 0;
        });
        [&] {
            QVERIFY(waitForFinalImage(v, timeoutMs));
            QTRY_VERIFY_WITH_TIMEOUT(v->lastImageFinal() && !w.lighting()->isPending() && finalFor == v->worker()->latestRequest(),
                                     timeoutMs);
        }();
        QObject::disconnect(c);
        return v->lastImage();
    }

    void select(MainWindow& w, OutlinerItem item)
    {
        w.outliner()->setCurrentIndex(w.outlinerModel()->indexOf(item));
        QCoreApplication::processEvents();
    }

    // A 65 x 65 DEM (16-bit PNG, 1 m apart, hills up to 12 m), one small grown shrub on 4 x 4 cells of a
    // 16 m tile set, the density rule on; local mode (no LB solve).
    QString writeLandscape()
    {
        QImage dem(65, 65, QImage::Format_Grayscale16);
        for (int j = 0; j < 65; ++j) {
            auto* row = reinterpret_cast<quint16*>(dem.scanLine(j));
            for (int i = 0; i < 65; ++i) row[i] = quint16(std::lround(100.0 * (6.0 + 6.0 * std::sin(i * 0.09) * std::cos(j * 0.07) + 0.05 * i)));
        }
        const QString png = m_dir.filePath("hills.png");
        [&] { QVERIFY(dem.save(png)); }();
        const QString path = m_dir.filePath("land.sylva.json");
        QFile f(path);
        [&] { QVERIFY(f.open(QIODevice::WriteOnly)); }();
        f.write(R"({"version": 1,
 "species": [{"name": "shrub", "grow": {"species": "shrub", "seed": 3, "triangles": 2000, "height": 2.0}, "lighting": {"preset": "leaf", "grid": 16}}],
 "instances": [],
 "terrain": {"dem": "hills.png", "spacing": 1, "height_scale": 0.01, "cells": 4,
   "tiles": {"size": 16, "seed": 3, "plants": [{"species": "shrub", "spacing": 2.5}]},
   "density": {"enabled": true, "lower": 4, "upper": 14, "at_lower": 1.0, "at_upper": 0.0}},
 "sun": {"elevation": 40, "azimuth": 200},
 "camera": {"position": [8, 26, 6], "target": [36, 4, 36], "fov": 50},
 "render": {"width": 160, "height": 100, "mode": "local"}}
)");
        return path;
    }

private Q_SLOTS:
    void initTestCase()
    {
        SYLVA_SKIP_WITHOUT_X();
        QVERIFY(m_dir.isValid());
        isolate(m_dir);
    }

    void landscapeFlyAndEdits()
    {
        auto w = window();
        QVERIFY(w->openFile(writeLandscape()));
        const Scene& s = w->document()->scene();
        QVERIFY(s.terrain.enabled() && s.terrain.field);
        QVERIFY(s.instances.empty());

        // Outliner: Terrain with Tiles, Tiling, Density; the properties show each.
        OutlinerModel* m = w->outlinerModel();
        const QModelIndex terrain = m->indexOf({OutlinerItem::Kind::Terrain, -1});
        QCOMPARE(m->rowCount(terrain), 3);
        QVERIFY(m->data(m->indexOf({OutlinerItem::Kind::Terrain, -1}, 1)).toString().contains("65 x 65"));
        QVERIFY(m->data(m->indexOf({OutlinerItem::Kind::Tiles, -1}, 1)).toString().contains("16 m"));
        QVERIFY(m->data(m->indexOf({OutlinerItem::Kind::Tiling, -1}, 1)).toString().contains("16 tiles"));
        select(*w, {OutlinerItem::Kind::Density, -1});
        auto* lower = w->propertyPanel()->findChild<QDoubleSpinBox*>("density.lower");
        QVERIFY(lower && lower->isVisible());
        QCOMPARE(lower->value(), 4.0);

        // The first picture: the lighting job loads the species, the worker builds the frame once.
        const QImage first = settled(*w);
        QVERIFY(!first.isNull());
        RenderWorker* worker = w->viewport()->worker();
        const int builds = worker->frameBuilds();
        QVERIFY(builds >= 1);
        // ... and it is the renderer's picture of the opened scene at the viewport's camera and size (terrain,
        // tiles and the shrub; local mode: no lighting grids). One 8-bit step allowed, for the tone map's
        // log-average key summed in another order (tst_view_frame, tst_sky_studio allow the same).
        const Scene opened = w->document()->scene();
        const QImage want =
            settledPicture(opened, assetCopies(w->assetStore()->forScene(opened, modeNeedsLighting(opened.render.mode))), w->viewport()->renderSize());
        const int worst = maxStep(first, want);
        qInfo("landscape: first picture vs headless render: worst channel step %d of 255", worst);
        QVERIFY2(worst <= 1, qPrintable(QString("the first picture is %1 steps off the renderer's").arg(worst)));

        // Fly: F, then W with Shift (5 x 0.5% of the 64 m side per press) and a look to the right.
        Viewport* v = w->viewport();
        v->setFocus();
        QTest::keyClick(v, Qt::Key_F);
        QVERIFY(v->flyMode());
        QCOMPARE(v->flyStep(), 0.005 * 64.0);
        const glm::dvec3 eye0 = s.camera.position;
        for (int i = 0; i < 4; ++i) QTest::keyClick(v, Qt::Key_W, Qt::ShiftModifier);
        const double moved = glm::length(w->document()->scene().camera.position - eye0);
        QVERIFY2(std::abs(moved - 4 * 5 * 0.32) < 1e-6, qPrintable(QString::number(moved)));
        QTest::mousePress(v, Qt::LeftButton, {}, QPoint(200, 150));
        QTest::mouseMove(v, QPoint(230, 150));
        QTest::mouseRelease(v, Qt::LeftButton, {}, QPoint(230, 150));
        const QImage flown = settled(*w);
        QVERIFY2(pixelsOver(first, flown, 2) > flown.width() * flown.height() / 10, "flying did not change the picture");
        QCOMPARE(worker->frameBuilds(), builds);   // a camera move re-places, builds nothing

        // Density: the lower tree line up by 4 m (fewer plants low down); one undo step; no frame build.
        const int undoBefore = w->document()->undoStack()->count();
        const int updates = worker->frameUpdates();
        lower->setValue(8.0);
        QCOMPARE(w->document()->scene().terrain.density.lower, 8.0);
        QCOMPARE(w->document()->undoStack()->count(), undoBefore + 1);
        const QImage thinned = settled(*w);
        QCOMPARE(worker->frameBuilds(), builds);
        QCOMPARE(worker->frameUpdates(), updates + 1);
        const int changed = pixelsOver(flown, thinned, 2);
        QVERIFY2(changed > 20, qPrintable(QString("the density edit changed %1 pixels").arg(changed)));

        // The updated frame against a whole build of the same scene (a change of accel forces one; the
        // viewport traces BVHs either way): the same picture.
        Scene rebuilt = w->document()->scene();
        rebuilt.render.accel = AccelKind::KdTree;
        w->document()->edit(rebuilt, "force a build");
        const QImage whole = settled(*w);
        QCOMPARE(worker->frameBuilds(), builds + 1);
        QCOMPARE(pixelsOver(thinned, whole, 0), 0);
        w->document()->undoStack()->undo();   // accel back (a build again)
        settled(*w);
        const int builds2 = worker->frameBuilds();

        // Undo the density edit: the flown picture again, without a build.
        w->document()->undoStack()->undo();
        QCOMPARE(w->document()->scene().terrain.density.lower, 4.0);
        const QImage back = settled(*w);
        QCOMPARE(worker->frameBuilds(), builds2);
        QCOMPARE(pixelsOver(flown, back, 0), 0);

        // A tile edit (the plants' spacing): the landscape's arrays again, the species' BVH kept.
        select(*w, {OutlinerItem::Kind::Tiles, -1});
        auto* spacing = w->propertyPanel()->findChild<QDoubleSpinBox*>("tiles.spacing.0");
        QVERIFY(spacing && spacing->isVisible());
        const int updates2 = worker->frameUpdates();
        spacing->setValue(4.0);
        const QImage sparse = settled(*w);
        QCOMPARE(worker->frameBuilds(), builds2);
        QCOMPARE(worker->frameUpdates(), updates2 + 1);
        QVERIFY(pixelsOver(back, sparse, 2) > 20);
    }

    // A small scene with a ground and a few shrubs, local mode; a cloud added through Edit > Add Cloud.
    void cloudThroughDialog()
    {
        auto w = window();
        w->importer()->growSpecies(GrowSpec{"shrub", 3, 2000, 0.0f});
        Scene s = w->document()->scene();
        QVERIFY(!s.instances.empty());
        s.instances[0].position = {-3.0, 0.0, 4.0};
        s.camera.position = {0.0, 2.0, -10.0};
        s.camera.target = {0.0, 2.0, 0.0};
        s.render.mode = RenderMode::Full;
        s.species[0].grid = 16;   // a quick LB solve
        s.render.width = 160;
        s.render.height = 100;
        w->document()->edit(s, "set up");
        const QImage empty = settled(*w, 120000);

        // The dialog: a 3 m cloud (24^3 nodes) at the target, in the middle of the picture.
        bool seen = false;
        QTimer::singleShot(0, [&] {
            auto* d = qobject_cast<CloudDialog*>(QApplication::activeModalWidget());
            if (!d) return;
            seen = true;
            volume::PyroclasticParams p = d->params();
            p.radius = 1.5f;
            p.amplitude = 0.5f;
            p.frequency = 1.0f;
            p.resolution = 24;
            p.centre = {0.0f, 2.0f, 0.0f};
            d->setParams(p);
            d->accept();
        });
        w->findChild<QAction*>("actionAddCloud")->trigger();
        QVERIFY(seen);
        const Scene& c = w->document()->scene();
        QCOMPARE(int(c.volumes.size()), 1);
        QCOMPARE(QString::fromStdString(c.volumes[0].name), QString("cloud"));
        QVERIFY(c.volumes[0].data);
        QCOMPARE(c.volumes[0].data->density.geometry.dims, glm::ivec3(24));
        QVERIFY(QFileInfo::exists(QString::fromStdString(c.volumes[0].grid)));
        OutlinerModel* m = w->outlinerModel();
        QCOMPARE(m->rowCount(m->indexOf({OutlinerItem::Kind::VolumesGroup, -1})), 1);
        QCOMPARE(m->data(m->indexOf({OutlinerItem::Kind::Volume, 0})).toString(), QString("cloud"));
        // The new volume is selected: its properties page.
        auto* tracer = w->propertyPanel()->findChild<QWidget*>("volume.tracer");
        QVERIFY(tracer && tracer->isVisible());

        // The viewport draws it (its LB lighting solved by the lighting job): the middle of the picture
        // changes, the corners (far from the cloud) much less (they move only with the tone map's key,
        // the picture's log-average luminance, which the cloud shifts).
        const QImage cloudy = settled(*w, 120000);
        const double middle = meanDiff(empty, cloudy, 0.4, 0.35, 0.6, 0.65);
        const double corners = 0.5 * (meanDiff(empty, cloudy, 0.0, 0.0, 0.1, 0.1) + meanDiff(empty, cloudy, 0.9, 0.0, 1.0, 0.1));
        QVERIFY2(middle > 8.0 && middle > 4.0 * corners, qPrintable(QString("middle %1, corners %2").arg(middle).arg(corners)));

        // The inspector shows its grids: the density and the LB lighting it was solved with.
        QVERIFY(w->inspectorController()->inspectVolume(0));
        auto grids = w->inspector()->grids();
        QVERIFY(grids);
        QCOMPARE(grids->density.geometry.dims, glm::ivec3(24));
        QCOMPARE(grids->lighting.geometry.dims, glm::ivec3(24));

        // Undo: no volume, no row, the empty scene's picture again.
        w->document()->undoStack()->undo();
        QVERIFY(w->document()->scene().volumes.empty());
        QCOMPARE(m->rowCount(m->indexOf({OutlinerItem::Kind::VolumesGroup, -1})), 0);
        const QImage after = settled(*w, 120000);
        QCOMPARE(pixelsOver(empty, after, 0), 0);
    }

    void smokeJob()
    {
        auto w = window();
        w->lighting()->setAutoLighting(false);
        VolumeTools* t = w->volumeTools();
        // Cancelled mid-run: nothing written, nothing in the scene or the undo stack.
        const quint64 revision = w->document()->revision();
        const int undo = w->document()->undoStack()->count();
        SmokeSpec big;
        big.cells = {32, 48, 32};
        big.steps = 100000;
        big.name = "plume";
        const QString wouldBe = t->gridPathFor("plume");
        Job* job = t->simulateSmoke(big);
        QVERIFY(job);
        QSignalSpy progressed(job, &Job::progressChanged);
        QVERIFY(progressed.wait(30000));
        job->cancel();
        Job::State state = Job::State::Running;
        QVERIFY(!waitForJob(job, 30000, &state));
        QCOMPARE(state, Job::State::Cancelled);
        QCOMPARE(w->document()->revision(), revision);
        QCOMPARE(w->document()->undoStack()->count(), undo);
        QVERIFY(w->document()->scene().volumes.empty());
        QVERIFY(!QFileInfo::exists(wouldBe));

        // A short one: a smoke volume (preset smoke) with the simulated density, one undo step.
        SmokeSpec small;
        small.cells = {8, 12, 8};
        small.steps = 3;
        QVERIFY(waitForJob(t->simulateSmoke(small), 30000));
        QCOMPARE(int(w->document()->scene().volumes.size()), 1);
        const VolumeDesc& v = w->document()->scene().volumes[0];
        QCOMPARE(QString::fromStdString(v.preset), QString("smoke"));
        QCOMPARE(v.data->density.geometry.dims, glm::ivec3(8, 12, 8));
        float peak = 0.0f;
        for (float x : v.data->density.density) peak = std::max(peak, x);
        QVERIFY(peak > 0.1f && peak <= 1.0f);
        QVERIFY(v.temperature.empty() && v.data->temperature.empty());   // cold smoke: no emission
        const std::vector<float> coldDensity = v.data->density.density;
        w->document()->undoStack()->undo();
        QVERIFY(w->document()->scene().volumes.empty());

        // Hot smoke: the same plume (buoyancy per kelvin scaled) with a temperature grid in kelvin that the
        // volume references: the sources' cells at 1500 K, and no value above it.
        SmokeSpec hot = small;
        hot.name = "fire";
        hot.sourceKelvin = 1500.0f;
        QVERIFY(waitForJob(t->simulateSmoke(hot), 30000));
        QCOMPARE(int(w->document()->scene().volumes.size()), 1);
        const VolumeDesc& f = w->document()->scene().volumes[0];
        QVERIFY(!f.temperature.empty() && QFileInfo::exists(QString::fromStdString(f.temperature)));
        QCOMPARE(f.data->temperature.size(), f.data->density.density.size());
        const float hottest = *std::max_element(f.data->temperature.begin(), f.data->temperature.end());
        QVERIFY2(std::abs(hottest - 1500.0f) < 1e-3f, qPrintable(QString::number(double(hottest))));
        QCOMPARE(f.data->density.density.size(), coldDensity.size());
        float worst = 0.0f;
        for (size_t i = 0; i < coldDensity.size(); ++i) worst = std::max(worst, std::abs(f.data->density.density[i] - coldDensity[i]));
        QVERIFY2(worst < 1e-4f, qPrintable(QString::number(double(worst))));   // the same rise, up to float rounding
        w->document()->undoStack()->undo();
        QVERIFY(w->document()->scene().volumes.empty());
    }
};

QTEST_MAIN(TstStudioLandVol)
#include "tst_studio_landvol.moc"
