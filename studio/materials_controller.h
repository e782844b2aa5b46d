// Edit > Species Materials: an imported species' materials (read in a job), the leaf/wood question
// (MaterialDialog by default) and the answer written as the species' leaf_materials.
#pragma once

#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "studio/dialogs.h"
#include "studio/studio_controller.h"

class QWidget;

namespace sylva {

class Job;
class JobManager;
class SceneDocument;

class MaterialsController : public StudioController {
    Q_OBJECT

public:
    // window: the parent of the default material dialog.
    MaterialsController(SceneDocument* doc, JobManager* jobs, QWidget* window, QObject* parent = nullptr);

    // How the leaf/wood question reaches the user: the species' materials in, its new leaf_materials
    // out (nullopt: cancelled). Default: MaterialDialog, modal.
    using MaterialEditor =
        std::function<std::optional<std::vector<std::string>>(const QString& species, const std::vector<MaterialChoice>& materials)>;
    void setMaterialEditor(MaterialEditor editor) { m_editMaterials = std::move(editor); }

    // Reads the species' mesh in a job (its materials, what the importer's rules make of each, what
    // leaf_materials makes of them now), asks the MaterialEditor, and writes the answer with
    // setLeafMaterials. Null (and an error) for a grown species or a bad index.
    Job* editMaterials(int species);
    // Sets a species' leaf_materials (empty: the importer's rules) as one undo step; false when unchanged.
    bool setLeafMaterials(int species, const std::vector<std::string>& names);

private:
    SceneDocument* m_doc;
    JobManager* m_jobs;
    MaterialEditor m_editMaterials;
};

} // namespace sylva
