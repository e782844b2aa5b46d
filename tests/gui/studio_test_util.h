// Helpers for the studio tests that open the main window (under Xvfb): skip without X, isolation,
// picture checks, waiting for jobs and viewport passes.
#pragma once

#include <cmath>
#include <optional>

#include <QApplication>
#include <QDir>
#include <QFileInfo>
#include <QImage>
#include <QMessageBox>
#include <QSettings>
#include <QSignalSpy>
#include <QStandardPaths>
#include <QTemporaryDir>
#include <QTest>

#include "core/lb/lb_params.h"
#include "core/scene/scene.h"
#include "studio/autosave_controller.h"
#include "studio/camera_nav.h"
#include "studio/export_controller.h"
#include "studio/inspector_controller.h"
#include "studio/job_manager.h"
#include "studio/lighting_scheduler.h"
#include "studio/main_window.h"
#include "studio/materials_controller.h"
#include "studio/recent_files.h"
#include "studio/scatter_tool.h"
#include "studio/species_importer.h"
#include "studio/viewport.h"

namespace sylva::test {

inline QString sharedTree() { return QStringLiteral(SYLVA_RESOURCES "/trees/quaternius/OBJ/Tree_1.obj"); }

// Three Tree_1 instances of resources/trees in a row, turned 0, 40 and 80 degrees, seen from the front.
inline Scene treeScene()
{
    Scene s;
    SpeciesDesc sp;
    sp.name = "Tree_1";
    sp.meshPath = sharedTree().toStdString();
    sp.lighting = lb::paramsFromPreset(*lb::findPreset("leaf"));
    sp.grid = 16;
    s.species.push_back(sp);
    for (int i = 0; i < 3; ++i) {
        InstanceDesc in;
        in.position = {3.0 * i - 3.0, 0.0, 2.0 * i};
        in.rotationDeg = {0.0f, 40.0f * float(i), 0.0f};
        s.instances.push_back(in);
    }
    s.camera.position = {1.0, 3.0, -14.0};
    s.camera.target = {0.0, 2.5, 0.0};
    return s;
}

// Call first in initTestCase: QSKIP when CMake found no xvfb-run.
#define SYLVA_SKIP_WITHOUT_X()                                                                                \
    do {                                                                                                      \
        if (qEnvironmentVariableIsSet("SYLVA_GUI_NO_X"))                                                       \
            QSKIP("xvfb-run was not found when CMake ran: install xvfb (./build.sh does) to run the GL tests"); \
    } while (false)

// Settings in Qt's test location (emptied), grid cache in `dir` (a fresh cache: the first solve computes).
inline void isolate(const QTemporaryDir& dir)
{
    QStandardPaths::setTestModeEnabled(true);
    QApplication::setOrganizationName("SylvaTest");
    QApplication::setApplicationName("sylva-studio-test");
    QSettings().clear();   // test mode keeps its files between runs (~/.qttest)
    // The viewport at its own aspect (View > Camera Frame off): the tests compare its pictures with headless
    // renders of the scene's camera at the viewport's size; tst_studio_artist tests the camera frame.
    QSettings().setValue("view/cameraFrame", false);
    // The viewport refines to the scene's samples (its sample limit 0, not the final preset's 64): the tests
    // compare its settled pictures with renders at the scene's samples; tst_studio_progressive tests the limit.
    QSettings().setValue("viewport/sampleLimit", 0);
    // No sample counter over the picture: the tests compare the framebuffer with the picture (tst_studio_progressive
    // turns it on).
    QSettings().setValue("view/sampleCounter", false);
    // No crash recovery left over from an earlier run (its question would block the test).
    QDir(QFileInfo(AutosaveController::recoveryFilePath()).absolutePath()).removeRecursively();
    qputenv("XDG_CACHE_HOME", dir.filePath("cache").toLocal8Bit());
    QApplication::setStyle("Fusion");
}

// A test's main window: error reports collected in *errors instead of a dialog, unsaved changes discarded on close.
inline void quietWindow(MainWindow& win, QStringList* errors)
{
    win.setErrorReporter([errors](const QString&, const QString& m) { *errors << m; });
    win.setSavePrompt([](const QString&) { return QMessageBox::Discard; });
}

// Shows the window with its viewport fixed at w x h; false when the window is not exposed.
inline bool showWithViewport(MainWindow& win, int w, int h)
{
    win.show();
    win.viewport()->setFixedSize(w, h);
    return QTest::qWaitForWindowExposed(&win);
}

// Mean and standard deviation of the luminance (0..255) of a picture.
inline void lumaStats(const QImage& image, double* mean, double* stddev)
{
    const QImage img = image.convertToFormat(QImage::Format_RGB32);
    double s = 0.0, s2 = 0.0;
    const double n = double(img.width()) * double(img.height());
    for (int y = 0; y < img.height(); ++y)
        for (int x = 0; x < img.width(); ++x) {
            const QRgb p = img.pixel(x, y);
            const double l = 0.2126 * qRed(p) + 0.7152 * qGreen(p) + 0.0722 * qBlue(p);
            s += l;
            s2 += l * l;
        }
    *mean = n > 0 ? s / n : 0.0;
    *stddev = n > 0 ? std::sqrt(std::max(0.0, s2 / n - *mean * *mean)) : 0.0;
}

// Waits for a job's end; true when it succeeded.
// (The job deletes itself after finishing: read its state in the signal, not afterwards.)
inline bool waitForJob(Job* job, int timeoutMs, Job::State* stateOut = nullptr)
{
    if (!job) return false;
    bool done = false;
    Job::State state = Job::State::Running;
    const QMetaObject::Connection c = QObject::connect(job, &Job::finished, job, [&](Job* j) {
        done = true;
        state = j->state();
    });
    done = QTest::qWaitFor([&] { return done; }, timeoutMs);
    if (!done) QObject::disconnect(c);
    if (stateOut) *stateOut = state;
    return done && state == Job::State::Succeeded;
}

// An orbit drag that began at widget pixel `from`, where the viewport picked `pressPick`, turned the camera
// from `before` to `after` about that point (orbitCameraAbout: the point back on `from` within 0.75 px) or, when
// the press was over the sky, about the target (kept exactly). Empty when it did; else what is wrong.
inline QString orbitPivotProblem(const Viewport* v, const std::optional<ViewPick>& pressPick, const CameraDesc& before,
                                 const CameraDesc& after, QPoint from)
{
    if (!pressPick || pressPick->kind == SurfaceKind::None)
        return after.target == before.target ? QString() : QStringLiteral("an orbit over the sky moved the target");
    glm::dvec2 px;
    if (!projectToView(after, v->width(), v->height(), pressPick->point, &px)) return QStringLiteral("the pivot went behind the eye");
    if (std::abs(px.x - from.x()) < 0.75 && std::abs(px.y - from.y()) < 0.75) return QString();
    return QStringLiteral("the pivot picked at %1, %2 is at %3, %4 after the orbit").arg(from.x()).arg(from.y()).arg(px.x).arg(px.y);
}

// Waits until the viewport shows the last pass of its schedule.
inline bool waitForFinalImage(Viewport* v, int timeoutMs)
{
    QSignalSpy shown(v, &Viewport::imageShown);
    QElapsedTimer t;
    t.start();
    while (t.elapsed() < timeoutMs) {
        if (!shown.isEmpty() && shown.last().at(1).toBool()) return true;
        shown.wait(std::max<int>(1, timeoutMs - int(t.elapsed())));
    }
    return !shown.isEmpty() && shown.last().at(1).toBool();
}

} // namespace sylva::test
