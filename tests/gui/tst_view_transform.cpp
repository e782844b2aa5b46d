// The studio's view transforms without GL (studio/view_transform.h): View > View Transform sets the scene's view
// as one undo step, its checks follow the document; the viewport's picture through a view.
#include <QAction>
#include <QSignalSpy>
#include <QStandardPaths>
#include <QTest>

#include <cmath>

#include "core/render/render_cpu.h"
#include "core/render/tonemap.h"
#include "pipeline/render/display_view.h"
#include "pipeline/render/render_job.h"
#include "pipeline/scene/scene_file.h"
#include "studio/render_worker.h"
#include "studio/scene_document.h"
#include "studio/view_transform.h"
#include "tests/common/files.h"

using namespace sylva;

namespace {

// A sunlit ground and a constant sky, 40 x 24, traced here.
Scene groundScene(const QString& dir)
{
    const QString path = dir + "/ground.sylva.json";
    test::writeText(path, R"({"version": 1, "ground": {"color": [0.5, 0.3, 0.2]}, "sun": {"elevation": 30, "azimuth": 30},
        "sky": {"color": [0.3, 0.4, 0.6]}, "camera": {"position": [0, 2, 0], "target": [0, 1.5, 10], "fov": 60},
        "render": {"width": 40, "height": 24}})");
    return readSceneFile(path.toStdString());
}

QString checkedView(const QMenu& menu)
{
    for (QAction* a : menu.findChildren<QAction*>())
        if (a->isChecked()) return a->objectName();
    return {};
}

} // namespace

class TstViewTransform : public QObject {
    Q_OBJECT

private Q_SLOTS:
    void initTestCase()
    {
        QStandardPaths::setTestModeEnabled(true);
        qunsetenv("OCIO");   // the bundled config
    }

    // The menu lists the bundled config's views, the scene's checked; a choice is one undo step that names the
    // view (the default display left unnamed); undo checks Sylva Reinhard again.
    void menuSetsTheSceneView()
    {
        const QString dir = test::outputDir("gui_view_transform_menu");
        SceneDocument doc;
        doc.reset(groundScene(dir), QString());
        ViewTransformMenu menu(&doc);
        QStringList names;
        for (QAction* a : menu.actions()) names << a->objectName();
        QCOMPARE(names, (QStringList{"viewTransform:sRGB/Sylva Reinhard", "viewTransform:sRGB/Standard",
                                     "viewTransform:sRGB/ACES 1.0 SDR-video", "viewTransform:sRGB/Sylva Filmic"}));
        QCOMPARE(checkedView(menu), QStringLiteral("viewTransform:sRGB/Sylva Reinhard"));
        QSignalSpy changed(&doc, &SceneDocument::changed);
        menu.findChild<QAction*>("viewTransform:sRGB/Sylva Filmic")->trigger();
        QCOMPARE(doc.scene().render.view, std::string("Sylva Filmic"));
        QVERIFY(doc.scene().render.display.empty());
        QCOMPARE(doc.undoStack()->count(), 1);
        QCOMPARE(changed.count(), 1);
        QVERIFY(hasPart(changed.at(0).at(0).value<ScenePart>(), ScenePart::Render));
        QCOMPARE(checkedView(menu), QStringLiteral("viewTransform:sRGB/Sylva Filmic"));
        menu.findChild<QAction*>("viewTransform:sRGB/Sylva Filmic")->trigger();   // the same view: no step
        QCOMPARE(doc.undoStack()->count(), 1);
        doc.undoStack()->undo();
        QCOMPARE(doc.scene().render.view, std::string(kReinhardView));
        QCOMPARE(checkedView(menu), QStringLiteral("viewTransform:sRGB/Sylva Reinhard"));
        // A scene naming a view this config lacks shows (and checks) Sylva Reinhard.
        Scene other = doc.scene();
        other.render.view = "Filmic Log";
        doc.reset(other, QString());
        QVERIFY(viewTransformOf(doc.scene()).isReinhard());
        QCOMPARE(checkedView(menu), QStringLiteral("viewTransform:sRGB/Sylva Reinhard"));
    }

    // The viewport's picture: Sylva Reinhard is filmImage's, bit for bit; another view is each value of the
    // composed picture exposed with the key through the view (Standard: the sRGB formula, within one 8-bit
    // step), in compare each half its mode's own picture.
    void pictureThroughTheView()
    {
        const QString dir = test::outputDir("gui_view_transform_picture");
        Scene s = groundScene(dir);
        const Film film = renderScene(s, nullptr).film;
        const glm::vec3 sky = composeSky(s);
        QVERIFY(scenePicture(film, s) == filmImage(film, s.render.mode, sky, s.render.exposureKey));
        s.render.view = "Standard";
        const QImage standard = scenePicture(film, s);
        const std::vector<glm::vec3> linear = composeMode(film, s.render.mode, sky);
        const float scale = toneMapScale(logAverageLuminance(&linear[0].x, linear.size(), 3), ToneMapParams{s.render.exposureKey});
        // The largest 8-bit step between a picture and the sRGB formula of this film's values x scale.
        auto worstStep = [&](const QImage& picture, float exposed) {
            int worst = 0;
            for (int y = 0; y < film.height; ++y)
                for (int x = 0; x < film.width; ++x) {
                    const QRgb p = picture.pixel(x, y);
                    const glm::vec3 v = linear[size_t(y) * size_t(film.width) + size_t(x)] * exposed;
                    const int got[3] = {qRed(p), qGreen(p), qBlue(p)};
                    for (int c = 0; c < 3; ++c) {
                        const double l = std::clamp(double(v[c]), 0.0, 1.0);
                        const double e = l <= 0.0031308 ? 12.92 * l : 1.055 * std::pow(l, 1.0 / 2.4) - 0.055;
                        worst = std::max(worst, std::abs(got[c] - int(std::lround(e * 255.0))));
                    }
                }
            return worst;
        };
        const int worst = worstStep(standard, scale);
        QVERIFY2(worst <= 1, qPrintable(QString::number(worst)));
        QVERIFY(standard != filmImage(film, s.render.mode, sky, s.render.exposureKey));

        // Held exposure (the viewport's passes): exposed with the scale of another film's picture (a sun four
        // times as bright), reported, and the pixels the sRGB formula of this film's values at that scale.
        Scene bright = s;
        bright.sun.intensity *= 4.0f;
        const Film brightFilm = renderScene(bright, nullptr).film;
        const std::vector<glm::vec3> brightLinear = composeMode(brightFilm, s.render.mode, sky);
        const float heldScale = toneMapScale(logAverageLuminance(&brightLinear[0].x, brightLinear.size(), 3), ToneMapParams{s.render.exposureKey});
        QVERIFY2(heldScale < 0.8f * scale, qPrintable(QStringLiteral("%1 vs %2").arg(heldScale).arg(scale)));
        float reported = 0.0f;
        const QImage held = scenePicture(film, s, std::nullopt, &brightFilm, &reported);
        QVERIFY2(std::abs(reported - heldScale) <= 1e-6f * heldScale, qPrintable(QStringLiteral("%1 vs %2").arg(reported).arg(heldScale)));
        const int worstHeld = worstStep(held, heldScale);
        QVERIFY2(worstHeld <= 1, qPrintable(QString::number(worstHeld)));
        QVERIFY(held != standard);
        const QImage both = scenePicture(film, s, RenderMode::Local);
        Scene local = s;
        local.render.mode = RenderMode::Local;
        const QImage right = scenePicture(film, local);
        for (int y = 0; y < film.height; ++y)
            for (int x = 0; x < film.width; ++x)
                QCOMPARE(both.pixel(x, y), (x < film.width / 2 ? standard : right).pixel(x, y));
    }
};

QTEST_MAIN(TstViewTransform)
#include "tst_view_transform.moc"
