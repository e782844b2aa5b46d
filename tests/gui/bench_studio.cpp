// The studio's responsiveness as figures (the tests check behaviour only): run under X, e.g.
//   xvfb-run -a -s "-screen 0 1600x1200x24" bench_studio [--gaps] [--forest] [--grid 96] [--moves 8]
// --gaps: Tree_1 lit at grid 96 (seconds of LB) while a 10 ms timer runs on the GUI thread; each gap
//   between two ticks timed on the wall clock and in the GUI thread's own CPU time (work this thread does
//   shows in both; a wait on the software GL threads composing a repaint, or the VM not run, only in the
//   first). Target: no 50 ms of GUI-thread work between two ticks.
// --forest: the default forest (32-node grids, from the grid cache after the first run) in a 640x360
//   viewport; after each small orbit the time from the request to the first (quarter-size) picture shown.
//   Target: 0.5 s.
// Without either flag both run. Ends with name=value lines.
#include <QApplication>
#include <QElapsedTimer>
#include <QSignalSpy>
#include <QTest>
#include <QTimer>

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <functional>
#include <vector>

#include <QUndoStack>

#include "studio/job_manager.h"
#include "studio/lighting_scheduler.h"
#include "studio/main_window.h"
#include "studio/scene_document.h"
#include "studio/species_importer.h"
#include "studio/viewport.h"

using namespace sylva;

namespace {

qint64 threadCpuNanoseconds()
{
    timespec t{};
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
    return qint64(t.tv_sec) * 1000000000 + t.tv_nsec;
}

bool waitFor(const std::function<bool()>& done, int ms) { return QTest::qWaitFor(done, ms); }

bool waitForFinalImage(Viewport* v, int ms)
{
    bool last = false;
    const QMetaObject::Connection c = QObject::connect(v, &Viewport::imageShown, v, [&](int, bool l, double) { last = l; });
    const bool ok = waitFor([&] { return last; }, ms);
    QObject::disconnect(c);
    return ok;
}

// Tree_1 at `grid`: returns false when something failed.
bool gaps(int grid)
{
    MainWindow win;
    win.setSavePrompt([](const QString&) { return QMessageBox::Discard; });
    win.lighting()->setAutoLighting(false);
    win.resize(1100, 700);
    win.show();
    if (!QTest::qWaitForWindowExposed(&win)) return false;
    bool imported = false, importOk = false;
    Job* job = win.importer()->importMesh(QStringLiteral(SYLVA_RESOURCES "/trees/quaternius/OBJ/Tree_1.obj"));
    if (!job) return false;
    QObject::connect(job, &Job::finished, &win, [&](Job* j) {
        imported = true;
        importOk = j->state() == Job::State::Succeeded;
    });
    if (!waitFor([&] { return imported; }, 60000) || !importOk) return false;
    Scene s = win.document()->scene();
    s.species[0].grid = grid;
    win.document()->edit(s, "grid");

    QElapsedTimer clock;
    qint64 last = -1, lastCpu = 0, maxGap = 0, secondGap = 0, maxCpu = 0;
    int ticks = 0, over50 = 0;
    QTimer probe;
    probe.setTimerType(Qt::PreciseTimer);
    probe.setInterval(10);
    QObject::connect(&probe, &QTimer::timeout, &win, [&] {
        const qint64 now = clock.nsecsElapsed(), cpu = threadCpuNanoseconds();
        if (last >= 0) {
            const qint64 gap = now - last;
            if (gap > maxGap) {
                secondGap = maxGap;
                maxGap = gap;
            } else {
                secondGap = std::max(secondGap, gap);
            }
            maxCpu = std::max(maxCpu, cpu - lastCpu);
            if (gap > 50000000) ++over50;
        }
        last = now;
        lastCpu = cpu;
        ++ticks;
    });
    QSignalSpy finished(win.lighting(), &LightingScheduler::lightingFinished);
    clock.start();
    probe.start();
    if (!win.lighting()->computeLighting()) return false;
    if (!finished.wait(600000) || !finished.at(0).at(0).toBool()) return false;
    const bool framed = waitForFinalImage(win.viewport(), 120000);   // the viewport's frame after the job is part of the run
    probe.stop();
    if (!framed) return false;
    const double seconds = double(clock.nsecsElapsed()) * 1e-9, gapMs = double(maxGap) * 1e-6, secondMs = double(secondGap) * 1e-6,
                 cpuMs = double(maxCpu) * 1e-6;
    std::printf("lighting job (Tree_1, grid %d) and viewport frame: %.2f s; GUI event loop: %d ticks of 10 ms, longest gap %.1f ms "
                "(next %.1f ms), %d gaps over 50 ms; most GUI-thread CPU time in one gap %.1f ms\n",
                grid, seconds, ticks, gapMs, secondMs, over50, cpuMs);
    std::printf("gui_lighting_s=%.3f\ngui_ticks=%d\ngui_gap_max_ms=%.1f\ngui_gap_second_ms=%.1f\ngui_gaps_over_50ms=%d\n"
                "gui_cpu_max_ms=%.1f\ngui_cpu_target_ms=50\ngui_cpu_within_target=%d\n",
                seconds, ticks, gapMs, secondMs, over50, cpuMs, cpuMs < 50.0 ? 1 : 0);
    win.document()->undoStack()->setClean();
    return true;
}

bool forest(int moves)
{
    MainWindow win;
    win.setSavePrompt([](const QString&) { return QMessageBox::Discard; });
    win.show();
    Viewport* v = win.viewport();
    v->setFixedSize(640, 360);
    if (!QTest::qWaitForWindowExposed(&win)) return false;
    QSignalSpy lit(win.lighting(), &LightingScheduler::lightingFinished);
    win.loadExampleForest();
    Scene s = win.document()->scene();
    for (SpeciesDesc& sp : s.species) sp.grid = 32;
    win.document()->edit(s, "grid 32");
    if (!waitFor([&] { return lit.count() >= 1; }, 1800000) || !lit.last().at(0).toBool()) return false;
    if (!waitForFinalImage(v, 120000)) return false;
    std::vector<double> firsts;
    for (int m = 0; m < moves; ++m) {
        QSignalSpy shown(v, &Viewport::imageShown);
        const QPoint c = v->rect().center();
        QTest::mousePress(v, Qt::LeftButton, {}, c);
        QTest::mouseRelease(v, Qt::LeftButton, {}, c + QPoint(15, 3));
        if (!shown.wait(60000)) return false;
        firsts.push_back(shown.at(0).at(2).toDouble());
        if (!waitForFinalImage(v, 120000)) return false;   // each move from a settled picture
    }
    std::vector<double> sorted = firsts;
    std::sort(sorted.begin(), sorted.end());
    double sum = 0.0;
    for (double f : firsts) sum += f;
    const double mean = sum / double(firsts.size()), median = sorted[sorted.size() / 2], worst = sorted.back();
    std::printf("default forest, 640x360 viewport: first picture after a camera move: median %.3f s, mean %.3f s, worst %.3f s "
                "(%d moves)\n",
                median, mean, worst, moves);
    std::printf("forest_first_image_median_s=%.3f\nforest_first_image_mean_s=%.3f\nforest_first_image_worst_s=%.3f\n"
                "forest_first_image_target_s=0.5\nforest_first_image_within_target=%d\n",
                median, mean, worst, worst < 0.5 ? 1 : 0);
    win.document()->undoStack()->setClean();
    return true;
}

} // namespace

int main(int argc, char** argv)
{
    QApplication app(argc, argv);
    QApplication::setOrganizationName("SylvaBench");
    QApplication::setApplicationName("bench-studio");
    bool runGaps = false, runForest = false;
    int grid = 96, moves = 8;
    for (int i = 1; i < argc; ++i) {
        if (!std::strcmp(argv[i], "--gaps")) runGaps = true;
        else if (!std::strcmp(argv[i], "--forest")) runForest = true;
        else if (!std::strcmp(argv[i], "--grid") && i + 1 < argc) grid = std::atoi(argv[++i]);
        else if (!std::strcmp(argv[i], "--moves") && i + 1 < argc) moves = std::max(1, std::atoi(argv[++i]));
        else {
            std::fprintf(stderr, "usage: bench_studio [--gaps] [--forest] [--grid N] [--moves N]\n");
            return 2;
        }
    }
    if (!runGaps && !runForest) runGaps = runForest = true;
    if (runGaps && !gaps(grid)) {
        std::fprintf(stderr, "bench_studio: the lighting run failed\n");
        return 1;
    }
    if (runForest && !forest(moves)) {
        std::fprintf(stderr, "bench_studio: the forest run failed\n");
        return 1;
    }
    return 0;
}
