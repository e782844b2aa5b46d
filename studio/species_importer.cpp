// SpeciesImporter: import and grow into the document (the first instance frames the camera).
#include "studio/species_importer.h"

#include <memory>
#include <string>
#include <vector>

#include <QFileDialog>
#include <QFileInfo>
#include <QSettings>

#include "pipeline/grow/tree_grower.h"
#include "pipeline/import/mesh_import.h"
#include "pipeline/scene/scene_species.h"
#include "studio/camera_nav.h"
#include "studio/dialogs.h"
#include "studio/job_manager.h"
#include "studio/recent_files.h"
#include "studio/scene_document.h"

namespace sylva {
namespace {

QString meshFilter()
{
    return QObject::tr("Meshes (*.obj *.fbx *.gltf *.glb *.ply *.dae *.3ds *.stl);;All files (*)");
}

// The scene file's species defaults (the measured front's solve), on the grid the artist chose last.
SpeciesDesc newSpeciesDesc()
{
    SpeciesDesc sp = defaultSpecies();
    sp.grid = QSettings().value("import/grid", 64).toInt();
    return sp;
}

} // namespace

SpeciesImporter::SpeciesImporter(SceneDocument* doc, JobManager* jobs, QWidget* window, QObject* parent)
    : StudioController(parent), m_doc(doc), m_jobs(jobs), m_window(window)
{
}

void SpeciesImporter::addSpecies(SpeciesDesc species, const Bounds3& bounds, const QString& undoText)
{
    Scene s = m_doc->scene();
    species.name = uniqueSpeciesName(s, species.name);
    const bool first = s.instances.empty();
    s.species.push_back(species);
    InstanceDesc inst;
    inst.species = uint32_t(s.species.size() - 1);
    s.instances.push_back(inst);
    if (first && bounds.valid()) s.camera = framingCamera(s.camera, bounds);
    m_doc->edit(s, undoText);
    Q_EMIT instanceAdded(int(s.instances.size() - 1));
}

Job* SpeciesImporter::importMesh(const QString& path)
{
    struct Result {
        Bounds3 bounds;
        size_t triangles = 0;
        std::vector<std::string> warnings;
    };
    auto result = std::make_shared<Result>();
    const QString abs = QFileInfo(path).absoluteFilePath();
    const std::string file = abs.toStdString();
    log(tr("importing %1").arg(abs));
    return m_jobs->start(tr("Import %1").arg(QFileInfo(path).fileName()),
                         [file, result](Job&, Progress& progress) {
                             progress.report(0.0, "reading");
                             ImportReport report;
                             const TriangleMesh mesh = sylva::importMesh(file, ImportOptions{}, &report);
                             result->bounds = meshBounds(mesh);
                             result->triangles = mesh.triangleCount();
                             result->warnings = report.warnings;
                             progress.report(1.0, "read");
                         },
                         [this, abs, result](Job* job) {
                             if (job->state() == Job::State::Failed) {
                                 fail(tr("Import failed"), job->error());
                                 return;
                             }
                             if (job->state() != Job::State::Succeeded) {
                                 log(tr("import of %1 cancelled").arg(abs));
                                 return;
                             }
                             for (const std::string& w : result->warnings) log(tr("warning: %1").arg(QString::fromStdString(w)));
                             SpeciesDesc sp = newSpeciesDesc();
                             sp.name = QFileInfo(abs).completeBaseName().toStdString();
                             sp.meshPath = abs.toStdString();
                             log(tr("imported %1: %2 triangles").arg(abs).arg(result->triangles));
                             addSpecies(sp, result->bounds, tr("Import %1").arg(QFileInfo(abs).fileName()));
                         });
}

void SpeciesImporter::growSpecies(const GrowSpec& spec)
{
    SpeciesDesc sp = newSpeciesDesc();
    sp.name = spec.species + " " + std::to_string(spec.seed);
    sp.grow = spec;
    // The grower's box is known only after growing: frame a trunk of the expected height.
    const float h = spec.height > 0.0f ? spec.height : defaultTreeHeight(speciesFromName(spec.species));
    Bounds3 b;
    b.extend({-0.35f * h, 0.0f, -0.35f * h});
    b.extend({0.35f * h, h, 0.35f * h});
    addSpecies(sp, b, tr("Grow %1").arg(QString::fromStdString(sp.name)));
}

void SpeciesImporter::importDialog()
{
    const QString path = QFileDialog::getOpenFileName(m_window, tr("Import Mesh"), lastFolder(QStringLiteral("meshes")), meshFilter());
    if (path.isEmpty()) return;
    rememberFolder(QStringLiteral("meshes"), path);
    importMesh(path);
}

void SpeciesImporter::growDialog()
{
    GrowDialog d(m_window);
    if (d.exec() == QDialog::Accepted) growSpecies(d.spec());
}

} // namespace sylva
