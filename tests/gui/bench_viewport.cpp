// Viewport timings on the CPU: the default forest at 640x360 through the studio's RenderWorker.
// Prints the time to the first (quarter-size) image and to each pass, for the first request (frame
// build included) and for camera moves (top level re-placed only). Lighting comes from the grid cache
// ($XDG_CACHE_HOME/sylva), computed on the first run.
//   bench_viewport [--width 640] [--height 360] [--moves 5] [--local]
#include <QCoreApplication>
#include <QElapsedTimer>
#include <QGuiApplication>
#include <QSignalSpy>

#include <cstdio>
#include <cstring>

#include "pipeline/cache/grid_cache.h"
#include "pipeline/render/render_job.h"
#include "studio/asset_store.h"
#include "studio/camera_nav.h"
#include "studio/render_worker.h"

using namespace sylva;

int main(int argc, char** argv)
{
    qputenv("QT_QPA_PLATFORM", "offscreen");
    QGuiApplication app(argc, argv);
    int width = 640, height = 360, moves = 5;
    bool local = false;
    for (int i = 1; i < argc; ++i) {
        if (!std::strcmp(argv[i], "--width") && i + 1 < argc) width = std::atoi(argv[++i]);
        else if (!std::strcmp(argv[i], "--height") && i + 1 < argc) height = std::atoi(argv[++i]);
        else if (!std::strcmp(argv[i], "--moves") && i + 1 < argc) moves = std::atoi(argv[++i]);
        else if (!std::strcmp(argv[i], "--local")) local = true;
    }
    Scene scene = defaultScene();
    if (local) scene.render.mode = RenderMode::Local;
    const bool lit = modeNeedsLighting(scene.render.mode);
    AssetStore store;
    GridCache cache;
    QElapsedTimer t;
    t.start();
    const std::vector<AssetsPtr> assets = ensureAssets(scene, lit, store, &cache, nullptr, [](const std::string& line) {
        std::printf("  %s\n", line.c_str());
    });
    std::printf("assets (%zu species, %s): %.2f s\n", assets.size(), lit ? "lit" : "unlit", t.elapsed() / 1000.0);

    RenderWorker worker;
    QSignalSpy images(&worker, &RenderWorker::imageReady);
    auto run = [&](const char* what) {
        images.clear();
        worker.request(scene, assets, QSize(width, height));
        while (images.isEmpty() || !images.last().at(2).toBool()) images.wait(60000);
        std::printf("%-28s", what);
        for (const auto& args : images)
            std::printf("  pass %d (%dx%d): %.3f s", args.at(1).toInt() + 1, args.at(0).value<QImage>().width(),
                        args.at(0).value<QImage>().height(), args.at(3).toDouble());
        std::printf("\n");
        return images.at(0).at(3).toDouble();
    };
    run("first request (build)");
    double sum = 0.0, worst = 0.0;
    for (int m = 0; m < moves; ++m) {
        scene.camera = orbitCamera(scene.camera, 7.0, 1.0);
        const double first = run("camera move");
        sum += first;
        worst = std::max(worst, first);
    }
    std::printf("first image after a camera move at %dx%d: mean %.3f s, worst %.3f s over %d moves\n", width, height,
                sum / std::max(1, moves), worst, moves);
    return 0;
}
