// The studio's sky panel and relighting from cached bases under Xvfb:
// panel edits are undoable scene edits whose built sky equals the one the scene reader builds; the time
// slider moves the sun as NOAA's algorithm (core/sky/sun_position) and the solar-noon closed form place it;
// with every species' basis in memory a sun change starts no lighting job and writes nothing to the grid
// cache (no LB solve), and the viewport's picture equals a render of freshly solved grids.
#include <QCheckBox>
#include <QComboBox>
#include <QDateEdit>
#include <QDial>
#include <QDirIterator>
#include <QDoubleSpinBox>
#include <QLineEdit>
#include <QSlider>
#include <QSpinBox>

#include <cmath>

#include "core/lb/lb_params.h"
#include "core/render/render_cpu.h"
#include "core/sky/sky_light.h"
#include "core/sky/sun_position.h"
#include "pipeline/cache/grid_cache.h"
#include "pipeline/io/env_map_io.h"
#include "pipeline/render/frame_build.h"
#include "pipeline/render/render_job.h"
#include "pipeline/scene/scene_file.h"
#include "studio/camera_nav.h"
#include "studio/relight.h"
#include "studio/sky_panel.h"
#include "studio_picture.h"
#include "studio_test_util.h"

using namespace sylva;
using namespace sylva::test;

namespace {

// The sky sampled over the sphere (a 32 x 16 map of skyToMap): equal skies, equal pixels.
std::vector<float> skyPixels(const sky::Sky& s) { return sky::skyToMap(s, 32).rgb; }

// The sky the scene reader would build for these settings (loadSceneSky from scratch).
std::vector<float> freshSky(Scene s)
{
    s.skyModel.built.reset();
    loadSceneSky(s);
    return skyPixels(*s.skyModel.built);
}

int cacheFiles(const QString& dir)
{
    int n = 0;
    QDirIterator it(dir, QDir::Files, QDirIterator::Subdirectories);
    while (it.hasNext()) {
        it.next();
        ++n;
    }
    return n;
}

} // namespace

class TstSkyStudio : public QObject {
    Q_OBJECT

    QTemporaryDir m_dir;

private Q_SLOTS:
    void initTestCase()
    {
        SYLVA_SKIP_WITHOUT_X();
        isolate(m_dir);
    }

    // Model, turbidity, map, rotation, lights: each an undo step whose built sky is the reader's.
    void panelEditsTheSkyAndUndoes()
    {
        SceneDocument doc;
        doc.reset(treeScene(), QString());
        SkyPanel panel(&doc);
        QUndoStack* undo = doc.undoStack();

        panel.kind()->setCurrentIndex(panel.kind()->findData(int(sky::SkyKind::Preetham)));
        QCOMPARE(doc.scene().skyModel.kind, sky::SkyKind::Preetham);
        QVERIFY(doc.scene().skyModel.built);
        QVERIFY(skyPixels(*doc.scene().skyModel.built) == freshSky(doc.scene()));
        const auto preetham3 = doc.scene().skyModel.built;
        panel.turbidity()->setValue(6.0);
        QCOMPARE(doc.scene().skyModel.turbidity, 6.0);
        QVERIFY(doc.scene().skyModel.built != preetham3);
        QVERIFY(skyPixels(*doc.scene().skyModel.built) == freshSky(doc.scene()));
        QVERIFY(skyPixels(*doc.scene().skyModel.built) != skyPixels(*preetham3));
        QCOMPARE(undo->count(), 2);
        // The Preetham sky follows the sun (a dial turn rebuilds it for the new direction).
        panel.sunAzimuthDial()->setValue(90);
        QVERIFY(skyPixels(*doc.scene().skyModel.built) == freshSky(doc.scene()));
        QVERIFY(std::abs(glm::dot(glm::normalize(doc.scene().skyModel.built->sun.direction), glm::normalize(doc.scene().sun.direction)) - 1.0f) < 1e-5f);
        undo->undo();
        undo->undo();
        QCOMPARE(doc.scene().skyModel.turbidity, 3.0);
        QVERIFY(doc.scene().skyModel.built == preetham3);   // the step's own sky back, not a rebuild
        QCOMPARE(panel.turbidity()->value(), 3.0);
        undo->undo();
        QCOMPARE(doc.scene().skyModel.kind, sky::SkyKind::Constant);
        QVERIFY(!doc.scene().skyModel.built);
        QCOMPARE(panel.kind()->currentData().toInt(), int(sky::SkyKind::Constant));

        // A map: the file, then its rotation and intensity; the lights and their interleave.
        const QString map = QStringLiteral(SYLVA_RESOURCES "/hdri/forest.exr");
        panel.setMapChooser([map] { return map; });
        panel.kind()->setCurrentIndex(panel.kind()->findData(int(sky::SkyKind::Map)));   // asks for the file
        QCOMPARE(doc.scene().skyModel.kind, sky::SkyKind::Map);
        QCOMPARE(QString::fromStdString(doc.scene().skyModel.path), map);
        QCOMPARE(panel.mapPath()->text(), map);
        QVERIFY(skyPixels(*doc.scene().skyModel.built) == freshSky(doc.scene()));
        panel.rotation()->setValue(90.0);
        panel.mapIntensity()->setValue(2.0);
        QCOMPARE(doc.scene().skyModel.rotationDeg, 90.0f);
        QCOMPARE(doc.scene().skyModel.built->rotationDeg, 90.0f);
        QVERIFY(skyPixels(*doc.scene().skyModel.built) == freshSky(doc.scene()));
        panel.lights()->setValue(128);
        panel.interleave()->setValue(4);
        QCOMPARE(doc.scene().skyModel.lights, 128);
        QCOMPARE(doc.scene().skyModel.interleave, 4);
        const int steps = undo->count();
        // A map that cannot be read changes nothing and says why.
        panel.setMapPath(m_dir.filePath("missing.exr"));
        QCOMPARE(undo->count(), steps);
        QCOMPARE(QString::fromStdString(doc.scene().skyModel.path), map);
        QVERIFY2(panel.status().contains("missing.exr"), qPrintable(panel.status()));
        for (int i = 0; i < 4; ++i) undo->undo();
        QCOMPARE(doc.scene().skyModel.rotationDeg, 0.0f);
        QCOMPARE(doc.scene().skyModel.lights, SkyDesc{}.lights);
        QVERIFY(skyPixels(*doc.scene().skyModel.built) == freshSky(doc.scene()));
        // Haze in the distance (aerial perspective) under the map: one step, its turbidity shown and edited.
        QVERIFY(!panel.aerialPerspective()->isChecked());
        QVERIFY(!panel.turbidity()->isVisibleTo(&panel));
        const int hazeSteps = undo->index();
        panel.aerialPerspective()->setChecked(true);
        QVERIFY(doc.scene().skyModel.aerialPerspective);
        QCOMPARE(undo->index(), hazeSteps + 1);
        QCOMPARE(undo->undoText(), QStringLiteral("Turn on distance haze"));
        QVERIFY(panel.turbidity()->isVisibleTo(&panel));
        panel.turbidity()->setValue(5.0);
        QCOMPARE(doc.scene().skyModel.turbidity, 5.0);
        // The scene file keeps the settings: save, read back, the same sky and haze.
        const QString file = m_dir.filePath("sky.sylva.json");
        doc.saveAs(file);
        Scene back = readSceneFile(file.toStdString());
        QCOMPARE(int(back.skyModel.kind), int(sky::SkyKind::Map));
        QVERIFY(skyPixels(*back.skyModel.built) == skyPixels(*doc.scene().skyModel.built));
        QVERIFY(back.skyModel.aerialPerspective);
        QCOMPARE(back.skyModel.turbidity, 5.0);
        undo->undo();
        undo->undo();
        QVERIFY(!doc.scene().skyModel.aerialPerspective);
        QVERIFY(!panel.aerialPerspective()->isChecked());
        QVERIFY(!panel.turbidity()->isVisibleTo(&panel));
    }

    // The time slider: the sun where NOAA's algorithm puts it; at solar noon of the June solstice at
    // latitude 48 N the elevation is 90 - 48 + 23.44 (declination, closed form) to NOAA's refraction.
    void timeSliderMovesTheSun()
    {
        SceneDocument doc;
        doc.reset(treeScene(), QString());
        SkyPanel panel(&doc);
        panel.sunMode()->setCurrentIndex(1);
        QVERIFY(doc.scene().sun.place.has_value());
        panel.sunDate()->setDate(QDate(2024, 6, 21));
        panel.timeZone()->setValue(0.0);
        panel.latitude()->setValue(48.0);
        panel.longitude()->setValue(0.0);
        for (int minutes : {6 * 60 + 30, 9 * 60 + 45, 12 * 60 + 2, 17 * 60 + 10}) {
            panel.timeSlider()->setValue(minutes);
            const Scene& s = doc.scene();
            QVERIFY(s.sun.place);
            QCOMPARE(s.sun.place->hour, minutes / 60.0);
            const sky::SunPosition want = sky::noaaSunPosition(*s.sun.place);
            QVERIFY(glm::length(s.sun.direction - want.direction) < 1e-6f);
            double el = 0.0, az = 0.0;
            sunAngles(s.sun.direction, &el, &az);
            QVERIFY(std::abs(el - want.elevationDeg) < 1e-3);
            QCOMPARE(panel.sunTime()->time(), QTime(minutes / 60, minutes % 60));
        }
        // 12:02 UTC at longitude 0 is within a minute of solar noon (equation of time -1.8 min).
        panel.timeSlider()->setValue(12 * 60 + 2);
        double el = 0.0, az = 0.0;
        sunAngles(doc.scene().sun.direction, &el, &az);
        QVERIFY2(std::abs(el - (90.0 - 48.0 + 23.44)) < 0.05, qPrintable(QString::number(el)));
        QVERIFY(std::abs(az) < 0.5 || std::abs(az - 360.0) < 0.5);   // due south (+Z)
        // The slider's edits of one drag merge; undo brings the morning back; the dial goes back to a direction.
        const glm::vec3 noon = doc.scene().sun.direction;
        panel.sunMode()->setCurrentIndex(0);
        QVERIFY(!doc.scene().sun.place);
        QVERIFY(doc.scene().sun.direction == noon);
        doc.undoStack()->undo();
        QVERIFY(doc.scene().sun.place);
        QCOMPARE(panel.sunMode()->currentIndex(), 1);
        // A Preetham sky follows the slider.
        panel.kind()->setCurrentIndex(panel.kind()->findData(int(sky::SkyKind::Preetham)));
        panel.timeSlider()->setValue(8 * 60);
        QVERIFY(glm::length(glm::normalize(doc.scene().skyModel.built->sun.direction) - glm::normalize(doc.scene().sun.direction)) < 1e-5f);
        QVERIFY(skyPixels(*doc.scene().skyModel.built) == freshSky(doc.scene()));
    }

    // With the species' basis in memory a sun change relights the viewport: no lighting job, no new
    // grid-cache entry (a solve would store its grid), the frame relit in place; the picture equals a
    // render of grids solved afresh for that sun (in a separate cache) within one 8-bit step.
    void sunChangeRelightsFromTheBasis()
    {
        MainWindow win;
        QStringList errors;
        quietWindow(win, &errors);
        QVERIFY(showWithViewport(win, 160, 96));
        Viewport* v = win.viewport();
        QCOMPARE(v->backend(), QStringLiteral("cpu"));
        LightingScheduler* lighting = win.lighting();
        QSignalSpy lit(lighting, &LightingScheduler::lightingFinished);
        // The worker's images from before the reset on: the lit scene's final image may come while the wait for the
        // lighting runs the event loop (imageReady: image, pass, last, seconds, serial, ...).
        QSignalSpy ready(v->worker(), &RenderWorker::imageReady);
        win.document()->reset(treeScene(), QString());
        QTRY_VERIFY_WITH_TIMEOUT(lit.count() >= 1, 120000);
        QVERIFY(lit.last().at(0).toBool());
        const quint64 litRequest = v->worker()->latestRequest();   // the lit scene's (requested before lightingFinished)
        auto litSettled = [&] {
            for (const QList<QVariant>& args : ready)
                if (args.at(2).toBool() && args.at(4).toULongLong() >= litRequest) return true;
            return false;
        };
        QTRY_VERIFY_WITH_TIMEOUT(litSettled(), 60000);

        QSignalSpy basis(lighting, &LightingScheduler::basisFinished);
        Job* job = lighting->buildRelightingBasis();
        QVERIFY(job);
        QTRY_VERIFY_WITH_TIMEOUT(basis.count() == 1, 180000);
        QVERIFY(basis.at(0).at(0).toBool());
        QVERIFY(lighting->hasBases(win.document()->scene()));
        QVERIFY2(win.logText().contains("relighting basis, 18 grids"), qPrintable(win.logText()));
        QTRY_VERIFY_WITH_TIMEOUT(v->lastImageFinal(), 60000);   // (its image may have come already)

        const QString cacheDir = m_dir.filePath("cache");
        const int filesBefore = cacheFiles(cacheDir);
        const int jobsBefore = lighting->lightingJobs(), relightsBefore = lighting->relights();
        const int relitBefore = v->worker()->relitFrames();
        SkyPanel* panel = win.skyPanel();
        QVERIFY(panel);
        panel->sunElevation()->setValue(35.0);
        panel->sunAzimuthDial()->setValue(200);
        QVERIFY(waitForFinalImage(v, 60000));
        QVERIFY(!win.jobs()->isBusy());
        QCOMPARE(lighting->lightingJobs(), jobsBefore);
        QVERIFY(lighting->relights() >= relightsBefore + 2);
        QVERIFY(v->worker()->relitFrames() > relitBefore);
        QCOMPARE(cacheFiles(cacheDir), filesBefore);
        QVERIFY(!lighting->isPending());
        QVERIFY2(errors.isEmpty(), qPrintable(errors.join('\n')));

        // The reference: the same scene's grids solved for this sun in a fresh cache, rendered headless
        // at the viewport's size and final samples.
        Scene ref = win.document()->scene();
        const glm::vec3 sunNow = ref.sun.direction;
        QVERIFY(glm::length(sunNow - sunDirection(35.0, 200.0)) < 1e-6f);
        GridCache fresh(m_dir.filePath("fresh").toStdString());
        JobLog log;
        const std::vector<SpeciesAssets> solved = loadSpeciesAssets(ref, &fresh, true, nullptr, &log);
        QVERIFY(std::find(log.stages.begin(), log.stages.end(), "light") != log.stages.end());
        // The basis error: the relit grid against the solve, node by node.
        const RelitGrid relit = relitGrid(*lighting->relightingFor(ref)->bases[0], sunNow);
        double num = 0.0, den = 0.0;
        for (size_t i = 0; i < relit.grid.rgb.size(); ++i) {
            const double d = double(relit.grid.rgb[i]) - double(solved[0].lighting.rgb[i]);
            num += d * d;
            den += double(solved[0].lighting.rgb[i]) * double(solved[0].lighting.rgb[i]);
        }
        const double relL2 = std::sqrt(num / den);
        qInfo("relit vs solved grid: relative L2 %.3g; norms %g %g", relL2, double(relit.norm.x), double(solved[0].lightingNorm.x));
        QVERIFY2(relL2 < 1e-3, "the basis reproduces the solve (fp16 storage: ~1e-4 measured)");
        QVERIFY(glm::length(relit.norm - solved[0].lightingNorm) < 1e-5f * glm::length(solved[0].lightingNorm));

        const QSize size = v->renderSize();
        const QImage want = settledPicture(ref, solved, size);   // at the viewport's final samples and its exposure
        ref.render.width = size.width();
        ref.render.height = size.height();
        ref.render.spp = RenderWorker::defaultPasses().back().spp;
        const int worst = maxStep(v->lastImage(), want);
        qInfo("relit viewport vs freshly solved render: worst channel step %d of 255", worst);
        QVERIFY2(worst <= 1, qPrintable(QString("the relit viewport is %1 steps off the solved render").arg(worst)));
        // And the picture did change with the sun (the relit frame is not the old one).
        Scene old = ref;
        old.sun.direction = treeScene().sun.direction;
        const std::vector<SpeciesAssets> oldAssets = loadSpeciesAssets(old, &fresh, true);
        const RenderScene rsOld = buildRenderScene(old, oldAssets, sunRadiance(old.sun));
        QVERIFY(maxStep(filmImage(renderFilm(rsOld.view()), old.render.mode, composeSky(old), old.render.exposureKey), want) > 8);

        // Undo back to the first sun: its own solved grids again, still no job.
        win.document()->undoStack()->undo();
        win.document()->undoStack()->undo();
        QVERIFY(waitForFinalImage(v, 60000));
        QCOMPARE(lighting->lightingJobs(), jobsBefore);

        // The sky is the viewport's background: a Preetham sky from the panel changes the picture's sky
        // (the frame's sky part built again), to the render of the same scene headless.
        const QImage constantSky = v->lastImage();
        panel->kind()->setCurrentIndex(panel->kind()->findData(int(sky::SkyKind::Preetham)));
        QVERIFY(waitForFinalImage(v, 120000));
        Scene pre = win.document()->scene();
        QVERIFY(pre.skyModel.built);
        pre.render.width = size.width();
        pre.render.height = size.height();
        QVERIFY(maxStep(v->lastImage().copy(0, 0, size.width(), 8), constantSky.copy(0, 0, size.width(), 8)) > 8);

        // The sky in the LB boundary from the panel: the species are lit again by a lighting job (the bases do
        // not compose it), with the grid `sylva render` solves for the same scene, and the picture changes.
        const QImage sunBoundary = v->lastImage();
        const int jobsSky = lighting->lightingJobs();
        panel->lbSky()->setChecked(true);
        QCOMPARE(win.document()->scene().lighting.boundary, LbBoundary::SunSky);
        QVERIFY(!lighting->relightingFor(win.document()->scene()));
        QVERIFY(waitForFinalImage(v, 180000));
        QVERIFY(lighting->lightingJobs() > jobsSky);
        const Scene withSky = win.document()->scene();
        const AssetsPtr held = win.assetStore()->find(assetKey(withSky.species[0], withSky, true));
        QVERIFY(held);
        const std::vector<SpeciesAssets> skyAssets = loadSpeciesAssets(withSky, &fresh, true);
        QCOMPARE(held->lighting.rgb.size(), skyAssets[0].lighting.rgb.size());
        QVERIFY(held->lighting.rgb == skyAssets[0].lighting.rgb);
        QVERIFY(held->lightingNorm == skyAssets[0].lightingNorm);
        QVERIFY(maxStep(v->lastImage(), sunBoundary) > 0);
        win.document()->undoStack()->undo();
        QCOMPARE(win.document()->scene().lighting.boundary, LbBoundary::Sun);
        QVERIFY(!panel->lbSky()->isChecked());
        win.document()->undoStack()->setClean();
    }
};

QTEST_MAIN(TstSkyStudio)
#include "tst_sky_studio.moc"
