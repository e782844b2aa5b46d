// The viewport's progressive refinement and the look controls, under Xvfb: the passes of a still view are shown
// at one exposure (the first pass's, its scale checked against a log-average the test takes itself of the first
// pass traced headless) with no jump in brightness between passes; samples accumulate past the scene's samples
// to the viewport's limit (the `final` quality preset's by default), the settled picture is the headless frame of
// that many samples, and the counter and the progress bar drawn over the picture say how far it is. The sky
// panel's exposure (stops), leaf tint and ground colour, typed into their boxes: each change one named undo step,
// the picture changing as the test's own oracle says (+1 EV: every display value where Reinhard's curve puts the
// doubled luminance; a red leaf tint: the leaves' albedo times the tint in the film, leaf pixels red; a red
// ground: ground pixels red), saved and read back.
#include <QAction>
#include <QDoubleSpinBox>
#include <QSpinBox>
#include <QUndoStack>

#include <algorithm>
#include <cmath>
#include <memory>
#include <vector>

#include "tests/common/pinhole.h"
#include "core/render/tonemap.h"
#include "core/render/tonemap_film.h"
#include "core/scene/quality.h"
#include "pipeline/scene/scene_file.h"
#include "studio/sky_panel.h"
#include "studio_picture.h"
#include "studio_test_util.h"

using namespace sylva;
using namespace sylva::test;

namespace {

// One picture the viewport showed, with what it said about it and the framebuffer drawn for it.
struct Shown {
    QImage image, framebuffer;
    int samples = 0, target = 0;
    double exposure = 0.0;
    QString counter;
    bool last = false;
};

// Types `text` into a spin box as a user does (select all, type, Enter).
void typeInto(QAbstractSpinBox* box, const QString& text)
{
    box->setFocus();
    QTest::keyClick(box, Qt::Key_A, Qt::ControlModifier);
    QTest::keyClicks(box, text);
    QTest::keyClick(box, Qt::Key_Return);
}

// Linear luminance of a display pixel (sRGB decoded, Rec. 709 weights): the Reinhard output Ld.
double displayLuminance(QRgb p)
{
    auto lin = [](int v) {
        const double e = v / 255.0;
        return e <= 0.04045 ? e / 12.92 : std::pow((e + 0.055) / 1.055, 2.4);
    };
    return 0.2126 * lin(qRed(p)) + 0.7152 * lin(qGreen(p)) + 0.0722 * lin(qBlue(p));
}

// Where world point p lands in a w x h picture of camera c (pixels, y down), from the camera's parameters alone.
QPointF project(const CameraDesc& c, double w, double h, const glm::dvec3& p)
{
    const glm::dvec2 q = test::pinholeProject(c, w, h, p);
    return {q.x, q.y};
}

// Degrees between the horizontal parts of two view directions.
double headingChange(const CameraDesc& a, const CameraDesc& b)
{
    const glm::dvec3 u = a.target - a.position, v = b.target - b.position;
    const double d = std::atan2(v.x, v.z) - std::atan2(u.x, u.z);
    return std::abs(std::remainder(d, 2.0 * 3.14159265358979323846)) * 180.0 / 3.14159265358979323846;
}

// Mean luma (0..255) of a picture.
double meanLuma(const QImage& image)
{
    double mean = 0.0, sd = 0.0;
    lumaStats(image, &mean, &sd);
    return mean;
}

} // namespace

class TstStudioProgressive : public QObject {
    Q_OBJECT

    QTemporaryDir m_dir;
    std::unique_ptr<MainWindow> m_win;
    QStringList m_errors;
    static constexpr int W = 320, H = 180;

    const Scene& scene() const { return m_win->document()->scene(); }
    SceneDocument* doc() const { return m_win->document(); }
    Viewport* viewport() const { return m_win->viewport(); }
    std::vector<SpeciesAssets> assets() const
    {
        return assetCopies(m_win->assetStore()->forScene(scene(), modeNeedsLighting(scene().render.mode)));
    }

    // Everything the viewport shows from now until its picture settles (or timeoutMs).
    std::vector<Shown> collect(const std::function<void()>& change, int timeoutMs = 120000)
    {
        std::vector<Shown> shown;
        const QMetaObject::Connection c = connect(viewport(), &Viewport::imageShown, this, [&](int, bool last, double) {
            Shown s;
            s.image = viewport()->lastImage();
            s.framebuffer = viewport()->grabFramebuffer().convertToFormat(QImage::Format_RGB32);
            s.samples = viewport()->samplesShown();
            s.target = viewport()->sampleTarget();
            s.exposure = viewport()->exposureShown();
            s.counter = viewport()->sampleCounterText();
            s.last = last;
            shown.push_back(s);
        });
        change();
        if (!QTest::qWaitFor([&] { return !shown.empty() && shown.back().last; }, timeoutMs))
            qWarning("the viewport did not settle within %d ms", timeoutMs);
        disconnect(c);
        return shown;
    }

    // Waits for the settled picture unless it is shown already.
    void settle()
    {
        if (!viewport()->lastImageFinal()) QVERIFY(waitForFinalImage(viewport(), 120000));
    }

    // The camera moved a little sideways: a new view (a new request, a new exposure).
    void nudgeCamera(double dx)
    {
        Scene s = scene();
        s.camera.position.x += dx;
        s.camera.target.x += dx;
        doc()->edit(s, QStringLiteral("nudge"));
    }

private Q_SLOTS:
    void initTestCase()
    {
        SYLVA_SKIP_WITHOUT_X();
        QVERIFY(m_dir.isValid());
        isolate(m_dir);
        m_win = std::make_unique<MainWindow>();
        quietWindow(*m_win, &m_errors);
        m_win->resize(1200, 760);
        QVERIFY(showWithViewport(*m_win, W, H));
        // The counter and the bar over the picture (the tests' settings turn them off).
        QAction* counter = m_win->findChild<QAction*>(QStringLiteral("actionSampleCounter"));
        QVERIFY(counter && !counter->isChecked());
        counter->trigger();
        QVERIFY(viewport()->sampleCounter());
        Scene s = treeScene();
        s.render.spp = 1;   // the scene's own samples: the viewport goes past them
        doc()->reset(s, QString());
        QVERIFY(waitForFinalImage(viewport(), 120000));
        QVERIFY2(m_errors.isEmpty(), qPrintable(m_errors.join('\n')));
    }

    void cleanupTestCase()
    {
        if (m_win) doc()->undoStack()->setClean();
        m_win.reset();
    }

    // Without a setting the limit is the `final` quality preset's samples; the toolbar's box shows the limit,
    // its lowest value reads "as the render".
    void defaultLimitIsTheFinalPreset()
    {
        const QVariant kept = QSettings().value("viewport/sampleLimit");
        QSettings().remove("viewport/sampleLimit");
        {
            Viewport fresh;
            QCOMPARE(fresh.sampleLimit(), findQualityPreset("final")->spp);
            QCOMPARE(fresh.sampleLimit(), 64);
        }
        QSettings().setValue("viewport/sampleLimit", kept);
        QSpinBox* box = m_win->sampleLimitBox();
        QVERIFY(box);
        QCOMPARE(box->value(), 0);   // the tests' settings: as the render
        QCOMPARE(box->text(), QStringLiteral("as the render"));
        QVERIFY(!box->toolTip().isEmpty());
    }

    // A limit of 16 typed into the toolbar: the still view's passes go 1, 1, 4 (the schedule) and then 4, 8, 12, 16
    // accumulated, past the scene's 1 sample; every picture at the first pass's exposure, the brightness steady,
    // the counter and the bar saying how far; the settled picture is the headless 16-sample frame.
    void refinesToTheLimitAtOneExposure()
    {
        const int limit = 16;
        std::vector<Shown> shown = collect([&] { typeInto(m_win->sampleLimitBox(), QString::number(limit)); });
        QCOMPARE(viewport()->sampleLimit(), limit);
        QCOMPARE(QSettings().value("viewport/sampleLimit").toInt(), limit);
        // Again on a fresh view (the limit's change restarted the one shown): a camera nudge.
        shown = collect([&] { nudgeCamera(0.25); });
        QVERIFY(!shown.empty() && shown.back().last);
        std::vector<int> samples;
        for (const Shown& s : shown) samples.push_back(s.samples);
        QCOMPARE(samples, (std::vector<int>{1, 1, 4, 4, 8, 12, 16}));
        QVERIFY(samples.back() > scene().render.spp);

        // One exposure: the scale of every picture equal to the first's, which is the key over the log-average
        // luminance (exp of the mean of log(1e-4 + L), taken here) of the first pass traced headless.
        const Film first = firstPassFilm(scene(), assets(), viewport()->renderSize());
        double logSum = 0.0;
        size_t n = 0;
        for (const SampleParts& p : first.pixels) {
            const float l = luminance(composeSample(p, scene().render.mode, composeSky(scene()), 0.0f));
            if (!std::isfinite(l)) continue;
            logSum += std::log(1e-4 + std::max(0.0, double(l)));
            ++n;
        }
        const double scale = double(scene().render.exposureKey) / std::exp(logSum / double(n));
        qInfo("exposure scale %.6g (the first pass's, headless: %.6g)", shown.front().exposure, scale);
        QVERIFY(std::abs(shown.front().exposure / scale - 1.0) < 1e-3);
        for (const Shown& s : shown) QCOMPARE(s.exposure, shown.front().exposure);

        // No jump in brightness from one pass to the next: the mean luma (0..255) within 2 levels.
        QString means;
        for (size_t k = 0; k < shown.size(); ++k) {
            means += QString::number(meanLuma(shown[k].image), 'f', 2) + ' ';
            if (k > 0)
                QVERIFY2(std::abs(meanLuma(shown[k].image) - meanLuma(shown[k - 1].image)) < 2.0,
                         qPrintable(QString("pass %1 to %2: mean luma %3").arg(k).arg(k + 1).arg(means)));
        }
        qInfo("mean luma per pass: %s", qPrintable(means));

        // The counter and the bar: "Samples k / 16", the bar's blue over k / 16 of the lower edge.
        const QColor blue = Viewport::progressBarColor();
        for (const Shown& s : shown) {
            QCOMPARE(s.target, limit);
            QCOMPARE(s.counter, QStringLiteral("Samples %1 / %2").arg(s.samples).arg(limit));
            const QImage& fb = s.framebuffer;
            const int y = fb.height() - 2;
            int filled = 0;
            for (int x = 0; x < fb.width(); ++x) {
                const QColor c(fb.pixel(x, y));
                if (std::abs(c.red() - blue.red()) <= 2 && std::abs(c.green() - blue.green()) <= 2 &&
                    std::abs(c.blue() - blue.blue()) <= 2)
                    ++filled;
            }
            const double want = double(fb.width()) * s.samples / limit;
            QVERIFY2(std::abs(filled - want) <= 1.0, qPrintable(QString("%1 of %2 samples: bar %3 px, want %4")
                                                                     .arg(s.samples)
                                                                     .arg(limit)
                                                                     .arg(filled)
                                                                     .arg(want)));
        }

        // The settled picture accumulated the 16 samples: the headless frame of 16, not of the schedule's 4.
        const QImage want16 = settledPicture(scene(), assets(), viewport()->renderSize(), limit);
        const QImage want4 = settledPicture(scene(), assets(), viewport()->renderSize(), 0);
        const int worst = maxStep(viewport()->lastImage(), want16);
        qInfo("settled at 16 samples vs headless: worst step %d; vs the 4-sample frame: %d pixels over 2 steps", worst,
              pixelsOver(viewport()->lastImage(), want4, 2));
        QVERIFY(worst <= 1);
        QVERIFY(pixelsOver(viewport()->lastImage(), want4, 2) > 0);

        // Under a sky that lights the plants (32 virtual lights in 16 groups) every pass is lit by the sky too: the
        // passes show 1, 1, 4, then one cycle of the 16 groups, at one exposure, with no jump in brightness (the sky's
        // light is not added only once the view stands still).
        Scene lit = scene();
        lit.skyModel.kind = sky::SkyKind::Uniform;
        shown = collect([&] { doc()->edit(lit, QStringLiteral("sky light")); });
        QVERIFY(!shown.empty() && shown.back().last);
        samples.clear();
        for (const Shown& s : shown) samples.push_back(s.samples);
        QCOMPARE(samples, (std::vector<int>{1, 1, 4, 16}));
        means.clear();
        for (size_t k = 0; k < shown.size(); ++k) {
            QCOMPARE(shown[k].exposure, shown.front().exposure);
            means += QString::number(meanLuma(shown[k].image), 'f', 2) + ' ';
            if (k > 0)
                QVERIFY2(std::abs(meanLuma(shown[k].image) - meanLuma(shown[k - 1].image)) < 2.0,
                         qPrintable(QString("sky light, pass %1 to %2: mean luma %3").arg(k).arg(k + 1).arg(means)));
        }
        qInfo("mean luma per pass under the sky light: %s", qPrintable(means));
        QVERIFY(maxStep(viewport()->lastImage(), settledPicture(scene(), assets(), viewport()->renderSize(), limit)) <= 1);
        collect([&] { doc()->undoStack()->undo(); });
        QVERIFY(scene().skyModel.kind == sky::SkyKind::Constant);

        // Back to the scene's samples for the tests below.
        collect([&] { typeInto(m_win->sampleLimitBox(), QStringLiteral("0")); });
        QCOMPARE(viewport()->sampleLimit(), 0);
    }

    // +1 EV in the sky panel: one undo step, the key doubled, the exposure scale doubled, and every display value
    // where Reinhard's curve puts twice the luminance (L = Ld / (1 - Ld) from the picture before, 2L / (1 + 2L));
    // undo gives the picture before back.
    void exposureInStops()
    {
        SkyPanel* panel = m_win->skyPanel();
        QVERIFY(panel->exposure());
        QCOMPARE(panel->exposure()->value(), 0.0);
        QVERIFY(!panel->exposure()->toolTip().isEmpty());
        settle();
        const QImage before = viewport()->lastImage();
        const double scaleBefore = viewport()->exposureShown();
        const int steps = doc()->undoStack()->index();
        collect([&] { typeInto(panel->exposure(), QStringLiteral("1")); });
        QCOMPARE(doc()->undoStack()->index(), steps + 1);
        QCOMPARE(doc()->undoStack()->undoText(), QStringLiteral("Change exposure"));
        QCOMPARE(scene().render.exposureKey, 0.36f);
        QVERIFY(std::abs(viewport()->exposureShown() / scaleBefore - 2.0) < 1e-5);
        const QImage after = viewport()->lastImage();
        QCOMPARE(after.size(), before.size());
        double sumWant = 0.0, sumGot = 0.0;
        int used = 0;
        for (int y = 0; y < before.height(); ++y)
            for (int x = 0; x < before.width(); ++x) {
                const QRgb a = before.pixel(x, y), b = after.pixel(x, y);
                if (std::max({qRed(b), qGreen(b), qBlue(b)}) >= 250) continue;   // a channel clipped by sRGB's 1
                const double ld = displayLuminance(a);
                if (ld < 0.02 || ld > 0.6) continue;   // 8-bit steps too coarse to invert at the ends
                const double l = ld / (1.0 - ld);
                sumWant += 2.0 * l / (1.0 + 2.0 * l);
                sumGot += displayLuminance(b);
                ++used;
            }
        qInfo("+1 EV over %d pixels: mean display luminance %.5f, Reinhard's %.5f", used, sumGot / used, sumWant / used);
        QVERIFY(used > before.width() * before.height() / 4);
        QVERIFY(std::abs(sumGot / sumWant - 1.0) < 0.01);
        QVERIFY(meanLuma(after) > meanLuma(before) + 10.0);

        collect([&] { doc()->undoStack()->undo(); });
        QCOMPARE(scene().render.exposureKey, 0.18f);
        QCOMPARE(panel->exposure()->value(), 0.0);
        QCOMPARE(maxStep(viewport()->lastImage(), before), 0);
        collect([&] { doc()->undoStack()->redo(); });
        QCOMPARE(panel->exposure()->value(), 1.0);
    }

    // Leaf tint (1, 0.1, 0.1) typed into the panel: two undo steps (green, blue), the film's albedo the untinted
    // one times the tint on leaves and unchanged elsewhere (bark, ground, sky), and the viewport's leaves red.
    void leafTint()
    {
        SkyPanel* panel = m_win->skyPanel();
        for (int c = 0; c < 3; ++c) {
            QCOMPARE(panel->leafTint(c)->value(), 1.0);
            QVERIFY(!panel->leafTint(c)->toolTip().isEmpty());
        }
        settle();
        const QImage before = viewport()->lastImage();
        const Scene untinted = scene();
        const int steps = doc()->undoStack()->index();
        collect([&] { typeInto(panel->leafTint(1), QStringLiteral("0.1")); });
        QCOMPARE(doc()->undoStack()->index(), steps + 1);
        QCOMPARE(doc()->undoStack()->undoText(), QStringLiteral("Change leaf tint"));
        collect([&] { typeInto(panel->leafTint(2), QStringLiteral("0.1")); });
        QCOMPARE(doc()->undoStack()->index(), steps + 2);
        QCOMPARE(scene().render.leafTint, glm::vec3(1.0f, 0.1f, 0.1f));

        // The film (one sample at the viewport's size): albedo = untinted albedo x tint where a leaf is seen, the
        // same elsewhere.
        const QSize size = viewport()->renderSize();
        auto film = [&](Scene s) {
            s.render.width = size.width();
            s.render.height = size.height();
            s.render.spp = 1;
            return renderFilm(buildRenderScene(s, assets(), sunRadiance(s.sun)).view());
        };
        const Film a = film(untinted), b = film(scene());
        std::vector<bool> leaf(a.pixels.size(), false);
        int leaves = 0, others = 0;
        for (size_t i = 0; i < a.pixels.size(); ++i) {
            const glm::vec3 u = a.pixels[i].albedo, t = b.pixels[i].albedo;
            if (u == t) {
                ++others;
                continue;
            }
            QVERIFY2(glm::length(t - u * glm::vec3(1.0f, 0.1f, 0.1f)) <= 1e-5f * glm::length(u),
                     qPrintable(QString("pixel %1: albedo (%2 %3 %4) tinted to (%5 %6 %7)")
                                    .arg(i)
                                    .arg(u.x)
                                    .arg(u.y)
                                    .arg(u.z)
                                    .arg(t.x)
                                    .arg(t.y)
                                    .arg(t.z)));
            leaf[i] = true;
            ++leaves;
        }
        qInfo("leaf tint: %d leaf pixels tinted, %d others unchanged", leaves, others);
        QVERIFY(leaves > int(a.pixels.size()) / 50);
        QVERIFY(others > int(a.pixels.size()) / 4);

        // The viewport: where the film sees a leaf, the picture is red-dominant now, and its green against its red
        // (linear, so the exposure and Reinhard's curve, which keep a pixel's hue, drop out) fell to the tint's 0.1
        // of what it was (within the light that does not come from the leaf's colour: at most 0.25 of it).
        auto linear = [](int v) {
            const double e = v / 255.0;
            return e <= 0.04045 ? e / 12.92 : std::pow((e + 0.055) / 1.055, 2.4);
        };
        const QImage after = viewport()->lastImage();
        QCOMPARE(after.size(), size);
        int red = 0;
        double ratioBefore = 0.0, ratioAfter = 0.0;
        for (int y = 0; y < after.height(); ++y)
            for (int x = 0; x < after.width(); ++x) {
                if (!leaf[size_t(y) * size_t(after.width()) + size_t(x)]) continue;
                const QRgb p = before.pixel(x, y), q = after.pixel(x, y);
                if (qRed(q) > qGreen(q) && qRed(q) > qBlue(q)) ++red;
                ratioBefore += linear(qGreen(p)) / std::max(1e-4, linear(qRed(p)));
                ratioAfter += linear(qGreen(q)) / std::max(1e-4, linear(qRed(q)));
            }
        qInfo("leaf tint in the viewport: of %d leaf pixels %d red-dominant; mean green / red %.3f before, %.3f after",
              leaves, red, ratioBefore / leaves, ratioAfter / leaves);
        QVERIFY(red >= leaves * 9 / 10);
        QVERIFY(ratioAfter < 0.25 * ratioBefore);
    }

    // Ground colour (1, 0, 0): one undo step per channel, ground pixels (picked as ground under the cursor) red.
    void groundColour()
    {
        SkyPanel* panel = m_win->skyPanel();
        QVERIFY(!panel->groundColor(0)->toolTip().isEmpty());
        QCOMPARE(panel->groundColor(0)->value(), 0.18);
        settle();
        // Ground pixels: the lower rows where the pick says ground.
        std::vector<QPoint> ground;
        for (int x = 8; x < W; x += 16)
            for (int y : {H - 12, H - 24}) {
                const std::optional<ViewPick> hit = viewport()->pickAt(QPointF(x + 0.5, y + 0.5), 2000);
                if (hit && hit->kind == SurfaceKind::Ground) ground.emplace_back(x, y);
            }
        QVERIFY(ground.size() >= 10);
        const QImage before = viewport()->lastImage();
        for (const QPoint& p : ground) QVERIFY(qGreen(before.pixel(p)) >= qRed(before.pixel(p)) * 6 / 10);
        const int steps = doc()->undoStack()->index();
        collect([&] { typeInto(panel->groundColor(0), QStringLiteral("1")); });
        collect([&] { typeInto(panel->groundColor(1), QStringLiteral("0")); });
        collect([&] { typeInto(panel->groundColor(2), QStringLiteral("0")); });
        QCOMPARE(doc()->undoStack()->index(), steps + 3);
        QCOMPARE(doc()->undoStack()->undoText(), QStringLiteral("Change ground colour"));
        QCOMPARE(scene().ground.color, glm::vec3(1.0f, 0.0f, 0.0f));
        const QImage after = viewport()->lastImage();
        for (const QPoint& p : ground) {
            const QRgb c = after.pixel(p);
            QVERIFY2(qRed(c) >= 40 && qGreen(c) <= 2 && qBlue(c) <= 2,
                     qPrintable(QString("ground at (%1, %2): %3 %4 %5").arg(p.x()).arg(p.y()).arg(qRed(c)).arg(qGreen(c)).arg(qBlue(c))));
        }
    }

    // An orbit drag starting on a tree turns about the point picked under the cursor at the press: after the drag
    // that point is on the same pixel (the test's pinhole projection of the new camera), the view turned by the
    // drag's 0.4 degree a pixel, and the target moved. Started over the sky, it turns about the target.
    void orbitAboutThePointUnderTheCursor()
    {
        settle();
        QPoint from;
        std::optional<ViewPick> hit;
        for (int y : {H / 2, H / 3, 2 * H / 3})
            for (int x = W / 4; x < 3 * W / 4 && !hit; x += 3) {
                const std::optional<ViewPick> h = viewport()->pickAt(QPointF(x, y), 2000);
                if (h && h->kind == SurfaceKind::Instances) {
                    hit = h;
                    from = QPoint(x, y);
                }
            }
        QVERIFY(hit);
        const CameraDesc before = scene().camera;
        const QPoint to = from + QPoint(40, 15);
        int steps = doc()->undoStack()->index();
        QTest::mousePress(viewport(), Qt::LeftButton, Qt::NoModifier, from);
        QTest::mouseMove(viewport(), from + QPoint(20, 8));
        QTest::mouseMove(viewport(), to);
        QTest::mouseRelease(viewport(), Qt::LeftButton, Qt::NoModifier, to);
        QCOMPARE(doc()->undoStack()->index(), steps);   // navigation: no step
        const CameraDesc after = scene().camera;
        const QPointF now = project(after, W, H, hit->point);
        qInfo("orbit about (%.3f %.3f %.3f): picked at %d, %d, after the drag at %.3f, %.3f", hit->point.x, hit->point.y,
              hit->point.z, from.x(), from.y(), now.x(), now.y());
        QVERIFY2(std::abs(now.x() - from.x()) < 0.75 && std::abs(now.y() - from.y()) < 0.75,
                 qPrintable(QStringLiteral("%1, %2 vs %3, %4").arg(now.x()).arg(now.y()).arg(from.x()).arg(from.y())));
        QVERIFY(std::abs(headingChange(before, after) - 0.4 * 40) < 1e-6);
        QVERIFY(glm::length(after.target - before.target) > 0.01);
        QVERIFY(glm::length(after.position - before.position) > 0.1);
        QVERIFY(waitForFinalImage(viewport(), 120000));   // the orbited view's picture

        // Over the sky (the top row): about the target, which stays.
        const QPoint sky(W / 2, 2);
        const std::optional<ViewPick> none = viewport()->pickAt(QPointF(sky), 2000);
        QVERIFY(none && none->kind == SurfaceKind::None);
        steps = doc()->undoStack()->index();
        QTest::mousePress(viewport(), Qt::LeftButton, Qt::NoModifier, sky);
        QTest::mouseMove(viewport(), sky + QPoint(15, 0));
        QTest::mouseMove(viewport(), sky + QPoint(30, 0));
        QTest::mouseRelease(viewport(), Qt::LeftButton, Qt::NoModifier, sky + QPoint(30, 0));
        QCOMPARE(doc()->undoStack()->index(), steps);
        QCOMPARE(scene().camera.target, after.target);
        QVERIFY(std::abs(headingChange(after, scene().camera) - 0.4 * 30) < 1e-6);
        QVERIFY(waitForFinalImage(viewport(), 120000));
    }

    // Fly speed follows the scene's size: a tree seen from 14 m steps 5% of the eye-target distance; the same tree
    // in a row 2 km long steps 0.5% of the row's length (the row's box from the instances' positions and the mesh's
    // box), and W moves the eye that far along the view.
    void flySpeedFollowsTheSceneSize()
    {
        settle();
        const std::vector<Bounds3>& boxes = viewport()->speciesBoxes();
        QVERIFY(!boxes.empty() && boxes[0].valid());
        Scene small = scene();   // the look set above stays (saved below)
        small.instances.resize(1);
        small.instances[0].position = glm::dvec3(0.0);
        small.camera.position = {0.0, 2.0, -14.0};
        small.camera.target = {0.0, 2.0, 0.0};
        collect([&] { doc()->edit(small, QStringLiteral("one tree")); });
        QVERIFY(std::abs(viewport()->flyStep() - 0.05 * 14.0) < 1e-9);

        Scene large = small;
        for (int i = 1; i <= 20; ++i) {
            InstanceDesc in;
            in.position = {100.0 * i, 0.0, 0.0};
            large.instances.push_back(in);
        }
        collect([&] { doc()->edit(large, QStringLiteral("a row of trees")); });
        const double length = 2000.0 + double(boxes[0].hi.x) - double(boxes[0].lo.x);
        qInfo("fly step: %.3f m in a row %.1f m long", viewport()->flyStep(), length);
        QVERIFY(std::abs(viewport()->flyStep() - 0.005 * length) < 1e-3);

        viewport()->setFocus();
        QTest::keyClick(viewport(), Qt::Key_F);
        QVERIFY(viewport()->flyMode());
        const CameraDesc before = scene().camera;
        QTest::keyClick(viewport(), Qt::Key_W);
        const glm::dvec3 moved = scene().camera.position - before.position;
        QVERIFY(std::abs(glm::length(moved) - 0.005 * length) < 1e-3);
        QVERIFY(glm::length(glm::normalize(moved) - glm::normalize(before.target - before.position)) < 1e-9);
        QTest::keyClick(viewport(), Qt::Key_F);
        QVERIFY(!viewport()->flyMode());
        settle();
    }

    // The look is saved with the scene and read back: the file's keys and the panel after opening it.
    void savedAndReopened()
    {
        const QString path = m_dir.filePath("look.sylva.json");
        doc()->saveAs(path);
        const Scene read = readSceneFile(path.toStdString());
        QCOMPARE(read.render.exposureKey, 0.36f);
        QCOMPARE(read.render.leafTint, glm::vec3(1.0f, 0.1f, 0.1f));
        QCOMPARE(read.ground.color, glm::vec3(1.0f, 0.0f, 0.0f));
        doc()->reset(treeScene(), QString());
        QCOMPARE(m_win->skyPanel()->exposure()->value(), 0.0);
        doc()->open(path);
        SkyPanel* panel = m_win->skyPanel();
        QCOMPARE(panel->exposure()->value(), 1.0);
        QCOMPARE(panel->leafTint(0)->value(), 1.0);
        QCOMPARE(panel->leafTint(1)->value(), 0.1);
        QCOMPARE(panel->groundColor(0)->value(), 1.0);
        QCOMPARE(panel->groundColor(2)->value(), 0.0);
        QVERIFY2(m_errors.isEmpty(), qPrintable(m_errors.join('\n')));
    }
};

QTEST_MAIN(TstStudioProgressive)
#include "tst_studio_progressive.moc"
