// ScatterTool: scatterInstances into the document, the form's defaults.
#include "studio/scatter_tool.h"

#include <algorithm>
#include <cmath>

#include "studio/camera_nav.h"
#include "studio/dialogs.h"
#include "studio/scene_document.h"

namespace sylva {

ScatterTool::ScatterTool(SceneDocument* doc, std::function<int()> selectedSpecies, QWidget* window, QObject* parent)
    : StudioController(parent), m_doc(doc), m_selectedSpecies(std::move(selectedSpecies)), m_window(window)
{
}

ScatterSpec ScatterTool::defaultScatter() const
{
    const Scene& s = m_doc->scene();
    ScatterSpec spec;
    spec.species = uint32_t(std::max(0, m_selectedSpecies()));
    spec.count = 100;
    spec.height = s.ground.height;
    spec.scaleMin = 0.8f;
    spec.scaleMax = 1.2f;
    spec.clearCentre = {s.camera.position.x, s.camera.position.z};
    const Bounds3 box = m_speciesBox && spec.species < s.species.size() ? m_speciesBox(int(spec.species)) : Bounds3{};
    spec.clearRadius = std::max(kDefaultClearance, crownReach(box) * double(spec.scaleMax));
    if (!s.instances.empty()) {
        glm::dvec2 lo(1e300), hi(-1e300);
        for (const InstanceDesc& in : s.instances) {
            lo = glm::min(lo, glm::dvec2(in.position.x, in.position.z));
            hi = glm::max(hi, glm::dvec2(in.position.x, in.position.z));
        }
        const glm::dvec2 pad(10.0);
        spec.min = lo - pad;
        spec.max = hi + pad;
    }
    return spec;
}

double ScatterTool::crownReach(const Bounds3& b)
{
    if (!b.valid()) return 0.0;
    const double x = std::max(std::abs(double(b.lo.x)), std::abs(double(b.hi.x)));
    const double z = std::max(std::abs(double(b.lo.z)), std::abs(double(b.hi.z)));
    return std::sqrt(x * x + z * z);
}

bool ScatterTool::scatter(const ScatterSpec& spec, bool frame)
{
    Scene s = m_doc->scene();
    if (spec.species >= s.species.size()) {
        fail(tr("Scatter failed"), tr("Species %1 does not exist; grow or import one first.").arg(spec.species));
        return false;
    }
    std::vector<InstanceDesc> added;
    try {
        added = scatterInstances(spec);
    } catch (const std::exception& e) {
        fail(tr("Scatter failed"), QString::fromStdString(e.what()));
        return false;
    }
    if (added.empty()) return false;
    const bool first = s.instances.empty();
    s.instances.insert(s.instances.end(), added.begin(), added.end());
    if (first) {
        Bounds3 b;
        b.extend({float(spec.min.x), float(spec.height), float(spec.min.y)});
        b.extend({float(spec.max.x), float(spec.height) + 5.0f, float(spec.max.y)});
        s.camera = framingCamera(s.camera, b);
    }
    const int placed = int(added.size());
    m_doc->edit(s, tr("Scatter %n instance(s) of %1", nullptr, placed).arg(QString::fromStdString(s.species[spec.species].name)));
    log(tr("scattered %1 instances of %2 (seed %3)")
            .arg(placed)
            .arg(QString::fromStdString(s.species[spec.species].name))
            .arg(spec.seed));
    if (placed < spec.count)
        log(tr("%1 of the %2 instances found no place outside the %3 m kept clear around the camera and were left out")
                .arg(spec.count - placed)
                .arg(spec.count)
                .arg(spec.clearRadius));
    if (frame) Q_EMIT frameRequested();
    return true;
}

void ScatterTool::scatterDialog()
{
    const Scene& s = m_doc->scene();
    if (s.species.empty()) {
        fail(tr("Scatter failed"), tr("The scene has no species: grow or import one first."));
        return;
    }
    QStringList names;
    for (const SpeciesDesc& sp : s.species) names << QString::fromStdString(sp.name);
    ScatterDialog d(names, defaultScatter(), m_window);
    if (d.exec() == QDialog::Accepted) scatter(d.spec(), d.frameResult());
}

} // namespace sylva
