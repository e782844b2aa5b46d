// MaterialsController: the species' materials (the pipeline's listMaterials), the question, the undo step.
#include "studio/materials_controller.h"

#include <iterator>
#include <memory>
#include <numeric>

#include "pipeline/services/material_list.h"
#include "studio/job_manager.h"
#include "studio/scene_document.h"

namespace sylva {

MaterialsController::MaterialsController(SceneDocument* doc, JobManager* jobs, QWidget* window, QObject* parent)
    : StudioController(parent), m_doc(doc), m_jobs(jobs)
{
    m_editMaterials = [window](const QString& species, const std::vector<MaterialChoice>& materials) {
        MaterialDialog d(species, materials, window);
        return d.exec() == QDialog::Accepted ? std::optional<std::vector<std::string>>(d.leafMaterials()) : std::nullopt;
    };
}

bool MaterialsController::setLeafMaterials(int species, const std::vector<std::string>& names)
{
    Scene s = m_doc->scene();
    if (species < 0 || size_t(species) >= s.species.size() || s.species[size_t(species)].leafMaterials == names) return false;
    SpeciesDesc& sp = s.species[size_t(species)];
    sp.leafMaterials = names;
    m_doc->edit(s, tr("Materials of %1").arg(QString::fromStdString(sp.name)));
    log(names.empty() ? tr("%1: leaf materials by the importer's rules").arg(QString::fromStdString(sp.name))
                      : tr("%1: leaf materials %2")
                            .arg(QString::fromStdString(sp.name),
                                 QString::fromStdString(std::accumulate(std::next(names.begin()), names.end(), names.front(),
                                                                        [](std::string a, const std::string& b) { return a + ", " + b; }))));
    return true;
}

Job* MaterialsController::editMaterials(int species)
{
    const Scene& scene = m_doc->scene();
    if (species < 0 || size_t(species) >= scene.species.size()) {
        fail(tr("Materials"), tr("Select a species (or one of its instances) to assign its materials."));
        return nullptr;
    }
    const SpeciesDesc sp = scene.species[size_t(species)];
    if (sp.meshPath.empty()) {
        fail(tr("Materials"), tr("%1 is grown: the grower marks its leaves and wood itself.").arg(QString::fromStdString(sp.name)));
        return nullptr;
    }
    auto result = std::make_shared<std::vector<MaterialChoice>>();
    return m_jobs->start(tr("Materials of %1").arg(QString::fromStdString(sp.name)),
                         [sp, result](Job&, Progress& progress) {
                             for (const MaterialAssignment& m : listMaterials(sp.meshPath, sp.leafMaterials, &progress))
                                 result->push_back({QString::fromStdString(m.name), m.leafByRules, m.leaf});
                         },
                         [this, species, sp, result](Job* job) {
                             if (job->state() == Job::State::Failed) {
                                 fail(tr("Materials"), job->error());
                                 return;
                             }
                             if (job->state() != Job::State::Succeeded) return;
                             // The species may have changed or gone meanwhile.
                             const Scene& now = m_doc->scene();
                             if (size_t(species) >= now.species.size() || now.species[size_t(species)].name != sp.name ||
                                 now.species[size_t(species)].meshPath != sp.meshPath)
                                 return;
                             const std::optional<std::vector<std::string>> names =
                                 m_editMaterials ? m_editMaterials(QString::fromStdString(sp.name), *result) : std::nullopt;
                             if (names) setLeafMaterials(species, *names);
                         });
}

} // namespace sylva
