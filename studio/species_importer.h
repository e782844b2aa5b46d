// New species: File > Import Mesh (read in a background job; the scene changes only when it succeeds)
// and File > Grow Species, each a species with one instance at the origin as one undo step, and
// their dialogs.
#pragma once

#include <QString>

#include "core/scene/scene.h"
#include "studio/studio_controller.h"

class QWidget;

namespace sylva {

class Job;
class JobManager;
class SceneDocument;
struct Bounds3;

class SpeciesImporter : public StudioController {
    Q_OBJECT

public:
    // window: the parent of the dialogs.
    SpeciesImporter(SceneDocument* doc, JobManager* jobs, QWidget* window, QObject* parent = nullptr);

    // Imports a mesh file as a new species (named after the file, made unique; leaf preset, the
    // settings' import/grid nodes) with one instance at the origin. A failure is an error and leaves
    // the scene as it was.
    Job* importMesh(const QString& path);
    // A grown species (named "SPECIES SEED") with one instance at the origin.
    void growSpecies(const GrowSpec& spec);

    void importDialog();
    void growDialog();

Q_SIGNALS:
    // A species and its instance were added (instance: its index), after the undo step.
    void instanceAdded(int instance);

private:
    void addSpecies(SpeciesDesc species, const Bounds3& bounds, const QString& undoText);

    SceneDocument* m_doc;
    JobManager* m_jobs;
    QWidget* m_window;
};

} // namespace sylva
