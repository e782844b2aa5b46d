// The studio viewport's GPU path (CUDA-GL interop) in a real QOpenGLWidget: on a machine whose OpenGL
// runs on the CUDA device it must show the CPU's picture, follow camera moves and the side-by-side
// compare. Elsewhere (CI: Xvfb with Mesa, no device) the viewport is on the CPU and the test skips,
// saying why.
#include <QSignalSpy>
#include <QTemporaryDir>
#include <QTest>

#include <cmath>

#include "core/lb/lb_params.h"
#include "core/render/render_cpu.h"
#include "pipeline/cache/grid_cache.h"
#include "pipeline/render/render_job.h"
#include "pipeline/render/view_frame.h"
#include "studio/render_worker.h"
#include "studio/viewport.h"
#include "tests/common/scenes.h"
#include "tests/gui/studio_test_util.h"

using namespace sylva;

namespace {

// What the CPU shows for the same frame (filmImage / compareImage of a film traced at that size and
// the last pass's samples).
QImage cpuPicture(const Scene& s, const std::vector<SpeciesAssets>& assets, QSize size, int spp, std::optional<RenderMode> compare)
{
    const glm::vec3 sun = sunRadiance(s.sun);
    ViewFrame f = buildViewFrame(s, assets, sun);
    placeViewFrame(f, s, sun, size.width(), size.height(), spp);
    const Film film = renderFilm(f.rs.view());
    return compare ? compareImage(film, s.render.mode, *compare, s.sky, s.render.exposureKey)
                   : filmImage(film, s.render.mode, s.sky, s.render.exposureKey);
}

// Channels differing by more than 0.1 of full scale.
int differing(const QImage& a, const QImage& b)
{
    const QImage x = a.convertToFormat(QImage::Format_RGBX8888), y = b.convertToFormat(QImage::Format_RGBX8888);
    if (x.size() != y.size()) return x.width() * x.height() * 3 + 1;
    int bad = 0;
    for (int r = 0; r < x.height(); ++r)
        for (int c = 0; c < x.width() * 4; ++c)
            if (c % 4 != 3) bad += std::abs(int(x.constScanLine(r)[c]) - int(y.constScanLine(r)[c])) > 25;
    return bad;
}

} // namespace

class TstViewportGpu : public QObject {
    Q_OBJECT

    QTemporaryDir m_dir;

private Q_SLOTS:
    void initTestCase()
    {
        SYLVA_SKIP_WITHOUT_X();
        test::isolate(m_dir);
    }

    void gpuViewportShowsTheCpuPicture()
    {
        Viewport v;
        v.resize(240, 160);
        v.show();
        QVERIFY(QTest::qWaitForWindowExposed(&v));
        QTRY_VERIFY_WITH_TIMEOUT(!v.backendNote().isEmpty(), 10000);   // set in initializeGL
        qInfo("%s", qPrintable(v.backendNote()));
        if (v.backend() != QLatin1String("cuda-gl")) QSKIP(qPrintable("skipped: " + v.backendNote()));

        Scene s = test::twoShrubs();
        GridCache cache(m_dir.filePath("grids").toStdString());
        const std::vector<SpeciesAssets> loaded = loadSpeciesAssets(s, &cache, true);
        std::vector<AssetsPtr> assets;
        for (const SpeciesAssets& a : loaded) assets.push_back(std::make_shared<const SpeciesAssets>(a));
        const int spp = RenderWorker::defaultPasses().back().spp;
        const int tolerance = v.renderSize().width() * v.renderSize().height() * 3 / 200;

        v.setScene(s, assets);
        QVERIFY(test::waitForFinalImage(&v, 60000));
        QCOMPARE(v.lastImage().size(), v.renderSize());
        int bad = differing(v.lastImage(), cpuPicture(s, loaded, v.renderSize(), spp, std::nullopt));
        qInfo("first view: %d channels differ from the CPU picture", bad);
        QVERIFY(bad <= tolerance);

        // A camera move re-places the frame on the device.
        s.camera.position = {-2.0, 2.0, -4.0};
        v.setScene(s, assets);
        QVERIFY(test::waitForFinalImage(&v, 60000));
        bad = differing(v.lastImage(), cpuPicture(s, loaded, v.renderSize(), spp, std::nullopt));
        qInfo("after a camera move: %d channels differ", bad);
        QVERIFY(bad <= tolerance);

        // Side-by-side compare, each half its own mode's picture.
        v.setCompare(RenderMode::Lb);
        QVERIFY(test::waitForFinalImage(&v, 60000));
        bad = differing(v.lastImage(), cpuPicture(s, loaded, v.renderSize(), spp, RenderMode::Lb));
        qInfo("compare full | lb: %d channels differ", bad);
        QVERIFY(bad <= tolerance);
        v.setCompare(std::nullopt);

        // Frames through the widget while the camera moves (1 spp, 1280x720), for the record: each frame
        // is a camera edit and the wait for the picture it produces (paintGL through the event loop).
        v.worker()->setPasses({{1, 1}});
        v.resize(1280, 720);   // the five frames before the timed ones wait out the resize's own pictures
        QSignalSpy shown(&v, &Viewport::imageShown);
        const int frames = 60;
        QElapsedTimer t;
        for (int i = -5; i < frames; ++i) {
            if (i == 0) t.start();
            s.camera.position.x = -2.0 + 0.02 * i;
            const qsizetype before = shown.size();
            v.setScene(s, assets);
            QVERIFY(QTest::qWaitFor([&] { return shown.size() > before; }, 10000));
        }
        qInfo("%d frames with the camera moving, %dx%d, 1 spp: %.2f ms per frame through the widget", frames,
              v.renderSize().width(), v.renderSize().height(), double(t.nsecsElapsed()) * 1e-6 / frames);
        QCOMPARE(v.backend(), QStringLiteral("cuda-gl"));
    }
};

QTEST_MAIN(TstViewportGpu)
#include "tst_viewport_gpu.moc"
