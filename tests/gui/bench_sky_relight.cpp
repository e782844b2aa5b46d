// The studio's sun drag on the default forest relit from cached bases: the window, its
// sky panel's azimuth dial and the CPU viewport at 640x360. Builds (or loads from the grid cache) each
// species' relighting basis first, then turns the dial: in `sequential` steps (each waits for the
// viewport's first image of the new sun: the latency-bound rate) and as a `drag` (the dial moved at 30
// Hz for a few seconds: the pictures of a new sun the viewport shows per second). Prints the time one
// relight of all species takes (composing the bases) and checks that no lighting job ran. Run under X:
//   xvfb-run -a -s "-screen 0 1600x1200x24" bench_sky_relight [--grid 64] [--moves 20] [--seconds 4]
#include <QApplication>
#include <QDial>
#include <QElapsedTimer>
#include <QSignalSpy>
#include <QTest>
#include <QTimer>

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <optional>

#include "studio/job_manager.h"
#include "studio/lighting_scheduler.h"
#include "studio/main_window.h"
#include "studio/relight.h"
#include "studio/sky_panel.h"
#include "studio/viewport.h"

using namespace sylva;

int main(int argc, char** argv)
{
    QApplication app(argc, argv);
    QApplication::setOrganizationName("SylvaBench");
    QApplication::setApplicationName("bench-sky-relight");
    int grid = 64, moves = 20;
    double seconds = 4.0;
    for (int i = 1; i < argc; ++i) {
        if (!std::strcmp(argv[i], "--grid") && i + 1 < argc) grid = std::atoi(argv[++i]);
        else if (!std::strcmp(argv[i], "--moves") && i + 1 < argc) moves = std::atoi(argv[++i]);
        else if (!std::strcmp(argv[i], "--seconds") && i + 1 < argc) seconds = std::atof(argv[++i]);
    }
    MainWindow win;
    win.setSavePrompt([](const QString&) { return QMessageBox::Discard; });
    win.show();
    Viewport* v = win.viewport();
    v->setFixedSize(640, 360);
    if (!QTest::qWaitForWindowExposed(&win)) return 1;
    LightingScheduler* lighting = win.lighting();
    QSignalSpy lit(lighting, &LightingScheduler::lightingFinished);
    QElapsedTimer t;
    t.start();
    win.loadExampleForest();
    Scene s = win.document()->scene();
    for (SpeciesDesc& sp : s.species) sp.grid = grid;
    win.document()->edit(s, "grid");
    if (!QTest::qWaitFor([&] { return lit.count() >= 1; }, 1800000) || !lit.last().at(0).toBool()) return 1;
    std::printf("lighting (%zu species, grid %d): %.1f s\n", s.species.size(), grid, t.elapsed() / 1000.0);
    t.restart();
    QSignalSpy basis(lighting, &LightingScheduler::basisFinished);
    lighting->buildRelightingBasis();
    if (!QTest::qWaitFor([&] { return basis.count() >= 1; }, 3600000) || !basis.last().at(0).toBool()) return 1;
    const double basisSeconds = t.elapsed() / 1000.0;
    std::printf("relighting basis (built or loaded): %.1f s\n", basisSeconds);
    const Scene scene = win.document()->scene();
    const std::optional<Relighting> r = lighting->relightingFor(scene);
    if (!r) return 1;

    // One relight of every species (what the worker does per sun change before tracing), median of 9.
    std::vector<double> compose;
    for (int k = 0; k < 9; ++k) {
        QElapsedTimer c;
        c.start();
        for (const BasisPtr& b : r->bases) (void)relitGrid(*b, sunDirection(30.0 + k, 40.0 * k));
        compose.push_back(c.nsecsElapsed() * 1e-6);
    }
    std::sort(compose.begin(), compose.end());
    double basisMb = 0.0;
    for (const BasisPtr& b : r->bases) basisMb += basisBytes(b->basis) / 1e6;

    QDial* dial = win.skyPanel()->sunAzimuthDial();
    const int jobs0 = lighting->lightingJobs();
    int az = dial->value();
    // Sequential: each step waits for the first image of its sun.
    QTest::qWait(2000);
    t.restart();
    for (int m = 0; m < moves; ++m) {
        QSignalSpy shown(v, &Viewport::imageShown);
        az = (az + 3) % 360;
        dial->setValue(az);
        while (!(shown.count() > 0 && shown.first().at(0).toInt() == 0))
            if (!shown.wait(60000)) return 1;
    }
    const double sequential = moves / (t.elapsed() / 1000.0);
    // Drag: the dial moves at 30 Hz; count the pictures of a new sun (first images of a request) shown.
    QSignalSpy shown(v, &Viewport::imageShown);
    QTimer drag;
    drag.setInterval(33);
    QObject::connect(&drag, &QTimer::timeout, [&] {
        az = (az + 1) % 360;
        dial->setValue(az);
    });
    t.restart();
    drag.start();
    QTest::qWait(int(seconds * 1000));
    drag.stop();
    const double dragSeconds = t.elapsed() / 1000.0;
    int firstImages = 0;
    for (const auto& a : shown) firstImages += a.at(0).toInt() == 0 ? 1 : 0;
    const double dragRate = firstImages / dragSeconds;
    const int jobs = lighting->lightingJobs() - jobs0;
    double load = 0.0;
    std::ifstream("/proc/loadavg") >> load;
    std::printf("relight of %zu species: median %.1f ms; bases %.0f MB in memory\n", r->bases.size(), compose[4], basisMb);
    std::printf("sun drag, 640x360: %.1f updates/s sequential (%d steps), %.1f updates/s while dragging at 30 Hz (%d in %.1f s); "
                "lighting jobs during the drag: %d\n",
                sequential, moves, dragRate, firstImages, dragSeconds, jobs);
    std::printf("grid=%d\nbasis_s=%.1f\nbasis_mb=%.0f\nrelight_ms=%.1f\nsequential_updates_per_s=%.2f\ndrag_updates_per_s=%.2f\n"
                "lighting_jobs=%d\nloadavg=%.2f\n",
                grid, basisSeconds, basisMb, compose[4], sequential, dragRate, jobs, load);
    win.document()->undoStack()->setClean();
    return jobs == 0 ? 0 : 2;
}
