// The studio's display transforms (view_transform.h): the viewport's picture through the scene's view, and the
// View > View Transform menu.
#include "studio/view_transform.h"

#include <vector>

#include <QActionGroup>

#include "core/base/error.h"
#include "studio/render_worker.h"
#include "studio/scene_document.h"

namespace sylva {

DisplayTransform viewTransformOf(const Scene& scene)
{
    try {
        return DisplayTransform::find(scene.render.display, scene.render.view);
    } catch (const Error&) {
        return DisplayTransform();
    }
}

QImage scenePicture(const Film& film, const Scene& scene, const std::optional<RenderMode>& compare, const Film* exposure,
                    float* scale)
{
    const glm::vec3 sky = composeSky(scene);
    const float key = scene.render.exposureKey;
    const RenderMode left = scene.render.mode, right = compare.value_or(left);
    const DisplayTransform view = viewTransformOf(scene);
    if (view.isReinhard()) return compare ? compareImage(film, left, right, sky, key) : filmImage(film, left, sky, key);
    if (film.width <= 0 || film.height <= 0) return {};
    QImage out(film.width, film.height, QImage::Format_RGBX8888);   // bytes R, G, B, 255
    const size_t n = size_t(film.width) * size_t(film.height);
    std::vector<float> encoded(n * 3);
    const bool split = right != left;
    for (int side = 0; side < (split ? 2 : 1); ++side) {
        const RenderMode mode = side == 0 ? left : right;
        const std::vector<glm::vec3> linear = composeMode(film, mode, sky);
        float s;
        if (exposure && exposure->width > 0) {
            const std::vector<glm::vec3> held = composeMode(*exposure, mode, sky);
            s = displayExposureScale(&held[0].x, held.size(), key);
        } else {
            s = displayExposureScale(&linear[0].x, n, key);
        }
        if (side == 0 && scale) *scale = s;
        view.apply(&linear[0].x, n, encoded.data(), s);
        // Each half is its mode's whole picture (exposed as that picture), as in compareImage.
        const int x0 = side == 0 ? 0 : film.width / 2, x1 = split && side == 0 ? film.width / 2 : film.width;
        for (int y = 0; y < film.height; ++y) {
            uchar* row = out.scanLine(y);
            for (int x = x0; x < x1; ++x) {
                const float* e = &encoded[(size_t(y) * size_t(film.width) + size_t(x)) * 3];
                for (int c = 0; c < 3; ++c) row[x * 4 + c] = uchar(e[c] * 255.0f + 0.5f);
                row[x * 4 + 3] = 255;
            }
        }
    }
    return out;
}

ViewTransformMenu::ViewTransformMenu(SceneDocument* doc, QWidget* parent) : QMenu(tr("View &Transform"), parent), m_doc(doc)
{
    setObjectName(QStringLiteral("menuViewTransform"));
    setToolTipsVisible(true);
    auto* group = new QActionGroup(this);
    group->setExclusive(true);
    std::vector<ColorConfigInfo::Display> displays;
    try {
        const ColorConfigInfo& config = colorConfig();
        m_defaultDisplay = config.defaultDisplay;
        displays = config.displays;
        setToolTip(tr("Views of the OpenColorIO config: %1").arg(QString::fromStdString(config.source)));
    } catch (const Error& e) {
        QAction* broken = addAction(tr("OpenColorIO config unreadable; only Sylva Reinhard"));
        broken->setEnabled(false);
        broken->setToolTip(QString::fromStdString(e.what()));
        displays.push_back({std::string(), {kReinhardView}});
    }
    for (const ColorConfigInfo::Display& d : displays) {
        QMenu* menu = displays.size() > 1 ? addMenu(QString::fromStdString(d.name)) : this;
        for (const std::string& v : d.views) {
            QAction* a = menu->addAction(QString::fromStdString(v));
            a->setObjectName(QString::fromStdString("viewTransform:" + d.name + "/" + v));
            a->setCheckable(true);
            a->setActionGroup(group);
            // The default display is stored as none, so the scene file names only what differs.
            const std::string display = d.name == m_defaultDisplay ? std::string() : d.name;
            a->setData(QStringList{QString::fromStdString(d.name), QString::fromStdString(v)});
            connect(a, &QAction::triggered, this, [this, display, v] {
                Scene s = m_doc->scene();
                if (s.render.view == v && s.render.display == display) return;
                s.render.view = v;
                s.render.display = display;
                m_doc->edit(s, tr("View transform %1").arg(QString::fromStdString(v)));
            });
        }
    }
    connect(m_doc, &SceneDocument::changed, this, [this](ScenePart parts) {
        if (hasPart(parts, ScenePart::Render)) sync();
    });
    sync();
}

void ViewTransformMenu::sync()
{
    // The entry of the picture shown: the scene's view, or Sylva Reinhard when the config has no such view.
    const DisplayTransform shown = viewTransformOf(m_doc->scene());
    const std::string display = shown.display().empty() ? m_defaultDisplay : shown.display();
    for (QAction* a : findChildren<QAction*>()) {
        const QStringList entry = a->data().toStringList();
        if (entry.size() != 2) continue;
        const QSignalBlocker block(a);
        a->setChecked(entry[1].toStdString() == shown.view() && entry[0].toStdString() == display);
    }
}

} // namespace sylva
