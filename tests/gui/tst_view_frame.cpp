// The viewport's fast path: a frame built once and re-placed for a new camera, instances and
// environment renders what a fresh buildRenderScene renders; the render worker's passes and restarts.
#include <QSignalSpy>
#include <QTemporaryDir>
#include <QTest>

#include <cmath>
#include <cstring>

#include "core/lb/lb_params.h"
#include "core/render/render_cpu.h"
#include "pipeline/cache/grid_cache.h"
#include "pipeline/grow/tree_grower.h"
#include "pipeline/io/env_map_io.h"
#include "pipeline/render/frame_build.h"
#include "pipeline/render/render_job.h"
#include "studio/asset_store.h"
#include "studio/render_worker.h"
#include "pipeline/render/view_frame.h"
#include "studio_picture.h"
#include "studio_test_util.h"

using namespace sylva;
using namespace sylva::test;

namespace {

// Pixels whose parts differ by more than a rounding error.
int differingPixels(const Film& a, const Film& b)
{
    int n = 0;
    for (size_t i = 0; i < a.pixels.size(); ++i) {
        const SampleParts &p = a.pixels[i], &q = b.pixels[i];
        const float d = glm::length(p.local - q.local) + glm::length(p.indirect - q.indirect) + std::abs(p.skyCover - q.skyCover);
        if (d > 1e-4f) ++n;
    }
    return n;
}

} // namespace

class TstViewFrame : public QObject {
    Q_OBJECT

    QTemporaryDir m_dir;
    std::vector<SpeciesAssets> m_assets;

private Q_SLOTS:
    void initTestCase()
    {
        GridCache cache(m_dir.filePath("cache").toStdString());
        m_assets = loadSpeciesAssets(treeScene(), &cache, true);
        QCOMPARE(m_assets.size(), size_t(1));
        QVERIFY(!m_assets[0].lighting.rgb.empty());
    }

    void replacedFrameMatchesFreshBuild()
    {
        const Scene a = treeScene();
        ViewFrame frame = buildViewFrame(a, m_assets, sunRadiance(a.sun));
        Scene b = a;
        b.camera.position = {-6.0, 5.0, -9.0};
        b.camera.target = {0.5, 2.0, 1.0};
        b.camera.fovY = 50.0f;
        b.instances[1].position = {1.0, 0.5, 3.0};
        b.instances[2].rotationDeg = {5.0f, 200.0f, -3.0f};
        b.instances[2].scale = 1.3f;
        b.instances.push_back(b.instances[0]);
        b.instances.back().position.x += 6.0;
        b.ground.height = 0.2;
        b.sun.temperature = 4000.0;
        b.sun.intensity = 1.5f;
        b.render.width = 96;
        b.render.height = 64;
        placeViewFrame(frame, b, sunRadiance(b.sun), b.render.width, b.render.height, 1);
        const RenderScene fresh = buildRenderScene(b, m_assets, sunRadiance(b.sun));
        const Film got = renderFilm(frame.rs.view()), want = renderFilm(fresh.view());
        QCOMPARE(got.width, 96);
        QCOMPARE(got.pixels.size(), want.pixels.size());
        int hits = 0;
        for (const SampleParts& p : want.pixels) hits += p.skyCover < 0.5f ? 1 : 0;
        QVERIFY2(hits > 500, "the trees and ground should fill part of the frame");
        QCOMPARE(differingPixels(got, want), 0);
    }

    void viewportFrameEqualsRenderFrame_data()
    {
        QTest::addColumn<float>("prune");
        QTest::newRow("pruning off") << 0.0f;
        QTest::newRow("pruning on") << 12.0f;
    }

    // The studio's frame (built once with every level of detail, re-placed at a new camera) traces exactly
    // the frame sylva render builds for that camera: the same levels of detail, the same top level, the
    // same pixels bit for bit.
    void viewportFrameEqualsRenderFrame()
    {
        QFETCH(float, prune);
        GrowOptions g;
        g.species = TreeSpecies::Broadleaf;
        g.targetTriangles = 8000;
        std::vector<SpeciesAssets> assets(1);
        assets[0].mesh = growTree(g).mesh;
        Scene a;
        a.species.resize(1);
        a.species[0].name = "grown";
        for (int i = 0; i < 12; ++i) {
            InstanceDesc in;
            in.position = {double(i % 3) * 9.0 - 9.0, 0.0, 8.0 + 14.0 * i};
            in.rotationDeg = {0.0f, 33.0f * float(i), 0.0f};
            a.instances.push_back(in);
        }
        a.camera.position = {0.0, 4.0, -6.0};
        a.camera.target = {0.0, 3.0, 40.0};
        a.render.pruneDistance = prune;
        a.render.width = 96;
        a.render.height = 64;
        ViewFrame frame = buildViewFrame(a, assets, sunRadiance(a.sun));
        QVERIFY(viewFrameFits(frame, a));
        Scene b = a;   // the camera walks into the stand: instances change level
        b.camera.position = {2.0, 5.0, 60.0};
        b.camera.target = {-1.0, 3.0, 120.0};
        placeViewFrame(frame, b, sunRadiance(b.sun), b.render.width, b.render.height, 1);
        const RenderScene fresh = buildRenderScene(b, assets, sunRadiance(b.sun));
        int levelsUsed = 0;
        for (size_t n : fresh.stats().instancesPerLevel) levelsUsed += n > 0 ? 1 : 0;
        QCOMPARE(levelsUsed > 2, prune > 0.0f);
        for (int l = 0; l < kMaxPruneLevels; ++l) QCOMPARE(frame.rs.stats().instancesPerLevel[l], fresh.stats().instancesPerLevel[l]);
        QCOMPARE(frame.rs.stats().instancedTriangles, fresh.stats().instancedTriangles);
        const Film got = renderFilm(frame.rs.view()), want = renderFilm(fresh.view());
        QCOMPARE(got.pixels.size(), want.pixels.size());
        int hits = 0;
        for (const SampleParts& p : want.pixels) hits += p.skyCover < 0.5f ? 1 : 0;
        QVERIFY(hits > 1000);
        QVERIFY(std::memcmp(got.pixels.data(), want.pixels.data(), got.pixels.size() * sizeof(SampleParts)) == 0);
        // A frame built without pruning does not fit a scene that prunes (the studio builds it again).
        Scene off = a;
        off.render.pruneDistance = 0.0f;
        const ViewFrame unpruned = buildViewFrame(off, assets, sunRadiance(off.sun));
        Scene on = a;
        on.render.pruneDistance = 12.0f;
        QVERIFY(!viewFrameFits(unpruned, on));
        QVERIFY(viewFrameFits(unpruned, off));
    }

    void workerRunsPassesAndRecomposes()
    {
        Scene s = treeScene();
        std::vector<AssetsPtr> assets{std::make_shared<const SpeciesAssets>(m_assets[0])};
        RenderWorker worker;
        worker.setPasses({{4, 1}, {1, 1}});
        QSignalSpy images(&worker, &RenderWorker::imageReady);
        worker.request(s, assets, QSize(128, 72));
        QTRY_COMPARE_WITH_TIMEOUT(images.count(), 2, 20000);
        QCOMPARE(images.at(0).at(0).value<QImage>().size(), QSize(32, 18));
        QCOMPARE(images.at(1).at(0).value<QImage>().size(), QSize(128, 72));
        QVERIFY(images.at(1).at(2).toBool());
        const QImage full = images.at(1).at(0).value<QImage>();

        // Mode alone: one recomposed image, no new passes.
        images.clear();
        s.render.mode = RenderMode::Lb;
        worker.request(s, assets, QSize(128, 72));
        QTRY_COMPARE_WITH_TIMEOUT(images.count(), 1, 20000);
        QVERIFY(images.at(0).at(2).toBool());
        QVERIFY(images.at(0).at(0).value<QImage>() != full);
        // ... and no pass after it: the worker answers requests in order, so the same request again is
        // answered by the next image, itself recomposed (full size, last, that request's serial). A trace
        // started after the first image would come first, or leave the film mid-schedule so that the
        // second answer is a quarter-size pass.
        worker.request(s, assets, QSize(128, 72));
        QTRY_COMPARE_WITH_TIMEOUT(images.count(), 2, 20000);
        QCOMPARE(images.at(1).at(4).toULongLong(), worker.latestRequest());
        QVERIFY(images.at(1).at(2).toBool());
        QCOMPARE(images.at(1).at(0).value<QImage>(), images.at(0).at(0).value<QImage>());

        // Camera moves in a burst: only the last one needs to finish.
        images.clear();
        for (int i = 0; i < 5; ++i) {
            s.camera.position.x += 0.5;
            worker.request(s, assets, QSize(128, 72));
        }
        QTRY_VERIFY_WITH_TIMEOUT(!images.isEmpty() && images.last().at(2).toBool(), 20000);

        // Errors come back as a signal, and the next good request renders again.
        QSignalSpy failed(&worker, &RenderWorker::failed);
        Scene bad = s;
        bad.camera.target = bad.camera.position;
        worker.request(bad, assets, QSize(64, 36));
        QTRY_COMPARE_WITH_TIMEOUT(failed.count(), 1, 20000);
        images.clear();
        worker.request(s, assets, QSize(64, 36));
        QTRY_VERIFY_WITH_TIMEOUT(!images.isEmpty() && images.last().at(2).toBool(), 20000);
    }

    // Progressive refinement under a Preetham sky with 16 virtual lights in 4 subsets:
    // while the camera moves (every request restarts the schedule) the schedule's frames light with the
    // sun alone; once it stops, frames of 4 samples (one cycle of the subsets) are accumulated until the
    // scene's 8 spp, and that last picture equals the frame `sylva render` traces (buildRenderScene at the
    // scene's spp, all samples at once) within one 8-bit step.
    void refinementAccumulatesToTheRenderFrame()
    {
        Scene s = treeScene();
        s.skyModel.kind = sky::SkyKind::Preetham;
        s.skyModel.lights = 16;
        s.skyModel.interleave = 4;
        s.render.spp = 8;
        s.render.mode = RenderMode::Local;
        loadSceneSky(s);
        const QSize size(64, 36);
        std::vector<AssetsPtr> assets{std::make_shared<const SpeciesAssets>(m_assets[0])};
        RenderWorker worker;
        worker.setPasses({{4, 1}, {1, 1}});
        QSignalSpy images(&worker, &RenderWorker::imageReady);
        worker.request(s, assets, size);
        QTRY_VERIFY_WITH_TIMEOUT(!images.isEmpty() && images.last().at(2).toBool(), 60000);
        QCOMPARE(images.count(), 2 + 2);   // the schedule, then 8 spp in 2 frames of 4
        for (int i = 0; i + 1 < images.count(); ++i) QVERIFY(!images.at(i).at(2).toBool());
        QCOMPARE(images.at(3).at(1).toInt(), 3);
        const QImage moving = images.at(1).at(0).value<QImage>(), settled = images.last().at(0).value<QImage>();

        Scene cli = s;
        cli.render.width = size.width();
        cli.render.height = size.height();
        const RenderScene rs = buildRenderScene(cli, m_assets, sunRadiance(cli.sun));
        QVERIFY(rs.view().sky.lightCount == 16);
        const QImage reference = filmImage(renderFilm(rs.view()), cli.render.mode, composeSky(cli), cli.render.exposureKey);
        const int worst = maxStep(settled, reference);
        QVERIFY2(worst <= 1, qPrintable(QString("the settled viewport is %1 steps off sylva render's frame").arg(worst)));
        // The moving frame is the sun's alone: darker than the settled one (no sky light), and the same
        // picture as a 1-spp frame with the sky lights off.
        Scene oneSample = cli;
        oneSample.render.spp = 1;
        const RenderScene rs1 = buildRenderScene(oneSample, m_assets, sunRadiance(cli.sun));
        RenderView sunOnly = rs1.view();
        sunOnly.sky.lightCount = 0;
        const QImage sunPicture = filmImage(renderFilm(sunOnly), cli.render.mode, composeSky(cli), cli.render.exposureKey);
        QVERIFY2(maxStep(moving, sunPicture) <= 1, qPrintable(QString("moving frame %1 steps off the sun-only frame").arg(maxStep(moving, sunPicture))));
        QVERIFY2(maxStep(moving, settled) > 8, qPrintable(QString("moving frame only %1 steps off the settled one").arg(maxStep(moving, settled))));
    }

    // Side-by-side compare (Geist & Steele, "A Lighting Model for Fast Rendering of Forest Ecosystems", Figure 2): both halves come from one trace. Turning compare on
    // (or changing its mode) recomposes the last film without tracing: the left half equals the
    // mode-A picture and the right half the mode-B picture of that same film, pixel for pixel. A
    // fresh trace with compare on matches the two pictures of a headless buildRenderScene frame.
    void compareHalvesComeFromOneTrace()
    {
        Scene s = treeScene();
        s.render.mode = RenderMode::Full;
        std::vector<AssetsPtr> assets{std::make_shared<const SpeciesAssets>(m_assets[0])};
        RenderWorker worker;
        worker.setPasses({{1, 1}});
        QSignalSpy images(&worker, &RenderWorker::imageReady);
        const QSize size(96, 64);
        worker.request(s, assets, size);
        QTRY_COMPARE_WITH_TIMEOUT(images.count(), 1, 20000);
        const QImage full = images.at(0).at(0).value<QImage>();
        Scene lb = s;
        lb.render.mode = RenderMode::Lb;
        worker.request(lb, assets, size);
        QTRY_COMPARE_WITH_TIMEOUT(images.count(), 2, 20000);
        const QImage lbImage = images.at(1).at(0).value<QImage>();
        QVERIFY(lbImage != full);

        auto halvesMatch = [](const QImage& got, const QImage& left, const QImage& right, int tolerance) {
            if (got.size() != left.size() || got.size() != right.size()) return QString("sizes differ");
            const int split = got.width() / 2;
            for (int y = 0; y < got.height(); ++y)
                for (int x = 0; x < got.width(); ++x) {
                    const QRgb g = got.pixel(x, y), w = (x < split ? left : right).pixel(x, y);
                    if (std::abs(qRed(g) - qRed(w)) > tolerance || std::abs(qGreen(g) - qGreen(w)) > tolerance ||
                        std::abs(qBlue(g) - qBlue(w)) > tolerance)
                        return QString("pixel (%1, %2) differs from the %3 picture").arg(x).arg(y).arg(x < split ? "left" : "right");
                }
            return QString();
        };

        // Compare on: one recomposed image (no new pass), left = full, right = lb, exactly.
        images.clear();
        worker.request(s, assets, size, RenderMode::Lb);
        QTRY_COMPARE_WITH_TIMEOUT(images.count(), 1, 20000);
        // No pass after it (as for a mode change above): the same request again is answered by the next
        // image, recomposed, the same picture.
        worker.request(s, assets, size, RenderMode::Lb);
        QTRY_COMPARE_WITH_TIMEOUT(images.count(), 2, 20000);
        QCOMPARE(images.at(1).at(4).toULongLong(), worker.latestRequest());
        QVERIFY(images.at(1).at(2).toBool());
        QCOMPARE(images.at(1).at(0).value<QImage>(), images.at(0).at(0).value<QImage>());
        const QImage cmp = images.at(0).at(0).value<QImage>();
        const QString mismatch = halvesMatch(cmp, full, lbImage, 0);
        QVERIFY2(mismatch.isEmpty(), qPrintable(mismatch));
        QVERIFY(cmp != full && cmp != lbImage);
        // The mode on the left changes: local | lb, still the same film.
        images.clear();
        Scene local = s;
        local.render.mode = RenderMode::Local;
        worker.request(local, assets, size);
        QTRY_COMPARE_WITH_TIMEOUT(images.count(), 1, 20000);
        const QImage localImage = images.at(0).at(0).value<QImage>();
        images.clear();
        worker.request(local, assets, size, RenderMode::Lb);
        QTRY_COMPARE_WITH_TIMEOUT(images.count(), 1, 20000);
        QVERIFY(halvesMatch(images.at(0).at(0).value<QImage>(), localImage, lbImage, 0).isEmpty());

        // A new camera with compare on traces once; the halves match the headless frame's pictures
        // (to one level of 8-bit rounding: the re-placed frame agrees to float rounding).
        Scene moved = s;
        moved.camera.position = {-4.0, 4.0, -12.0};
        images.clear();
        worker.request(moved, assets, size, RenderMode::Ambient);
        QTRY_COMPARE_WITH_TIMEOUT(images.count(), 1, 20000);
        moved.render.width = size.width();
        moved.render.height = size.height();
        moved.render.spp = 1;
        const RenderScene fresh = buildRenderScene(moved, m_assets, sunRadiance(moved.sun));
        const Film film = renderFilm(fresh.view());
        const QImage want = compareImage(film, RenderMode::Full, RenderMode::Ambient, moved.sky, moved.render.exposureKey);
        const QString m2 = halvesMatch(images.at(0).at(0).value<QImage>(), filmImage(film, RenderMode::Full, moved.sky, moved.render.exposureKey),
                                       filmImage(film, RenderMode::Ambient, moved.sky, moved.render.exposureKey), 1);
        QVERIFY2(m2.isEmpty(), qPrintable(m2));
        QVERIFY(halvesMatch(want, filmImage(film, RenderMode::Full, moved.sky, moved.render.exposureKey),
                            filmImage(film, RenderMode::Ambient, moved.sky, moved.render.exposureKey), 0)
                    .isEmpty());
    }
};

QTEST_MAIN(TstViewFrame)
#include "tst_view_frame.moc"
