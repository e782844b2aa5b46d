// The open scene: the Scene value, its file, its undo stack; every edit is one undoable command.
#pragma once

#include <QObject>
#include <QString>
#include <QUndoCommand>
#include <QUndoStack>

#include <map>

#include "core/scene/scene.h"

namespace sylva {

// Which parts of the scene an edit touched (listeners redo only what depends on them).
enum class ScenePart : unsigned {
    None = 0,
    Species = 1u << 0,     // the species list, a species' settings or the lighting block (what their grids follow)
    Instances = 1u << 1,   // the instance list or an instance's placement
    Ground = 1u << 2,
    Sun = 1u << 3,
    Sky = 1u << 4,
    Camera = 1u << 5,
    Render = 1u << 6,      // render settings (mode, size, spp, exposure, leaf tint)
    Terrain = 1u << 7,     // the terrain: DEM, its colours, cells, tiles, tiling, density
    Volumes = 1u << 8,     // the volume list or a volume's grid, optics or placements
    All = 0x1ffu,
};
inline ScenePart operator|(ScenePart a, ScenePart b) { return ScenePart(unsigned(a) | unsigned(b)); }
inline bool hasPart(ScenePart set, ScenePart part) { return (unsigned(set) & unsigned(part)) != 0; }

// Which parts differ between two scenes.
ScenePart changedParts(const Scene& a, const Scene& b);

// Everything a species' scene-file entry holds except its name, as text: equal text, equal species.
std::string speciesFingerprint(const SpeciesDesc& species);

class SceneDocument : public QObject {
    Q_OBJECT

public:
    explicit SceneDocument(QObject* parent = nullptr);

    const Scene& scene() const { return m_scene; }
    QString filePath() const { return m_filePath; }
    QString displayName() const;          // file name, or "untitled"
    bool isModified() const { return !m_undo.isClean(); }
    QUndoStack* undoStack() { return &m_undo; }
    // Counts every applied state (edits, undo, redo, load): a cheap "did the scene change" stamp.
    quint64 revision() const { return m_revision; }

    // Pushes one undoable edit that replaces the scene with `after` (no-op when nothing differs).
    // Consecutive edits with the same non-zero mergeKey collapse into one undo step (a drag, a spin).
    // The sky is built for `after` first (refreshSceneSky: a Preetham sky follows the sun, a map is
    // read); when that fails nothing is pushed and editRefused says why.
    void edit(const Scene& after, const QString& text, int mergeKey = 0);

    // Navigation (the viewport's orbit, pan, zoom, fly and framing): sets the scene's camera with no undo
    // step and without marking the document modified, as moving the view does in other 3D packages. The
    // camera is the scene's (renders and the next save use it). Undo and redo of other edits keep it; an edit
    // that set the camera itself (the camera's property page) puts its own camera back.
    void navigate(const CameraDesc& camera);

    // Replaces the document (new or opened file): clears undo history, marks clean.
    void reset(const Scene& scene, const QString& filePath);
    // Reads a scene file; throws Error with the reader's message. The document is unchanged on error.
    void open(const QString& path);
    // Writes atomically (writeSceneFile) and marks clean; throws Error. The scene must have at least
    // one species and one instance (what the reader accepts).
    void saveAs(const QString& path);

    // Merge keys for continuous edits; a fresh key per gesture keeps separate gestures apart.
    static int newMergeKey();

Q_SIGNALS:
    void changed(sylva::ScenePart parts);   // after every applied state, with what differs
    void filePathChanged(const QString& path);
    void modifiedChanged(bool modified);
    // An edit was not applied: its sky cannot be built (a map that cannot be read, a sun the model refuses).
    void editRefused(const QString& text, const QString& reason);

private:
    friend class SceneEditCommand;
    void setState(const Scene& scene);

    Scene m_scene;
    QString m_filePath;
    QUndoStack m_undo;
    quint64 m_revision = 0;
    // Undo and redo end merging: a new edit after them never folds into an older step.
    bool m_pushing = false;
    int m_mergeEpoch = 0;
};

// "Replace scene state": before and after, whole. Scenes are small (hundreds of instances), so a
// copy per step is cheaper to get right than one command class per field.
class SceneEditCommand : public QUndoCommand {
public:
    SceneEditCommand(SceneDocument* doc, Scene before, Scene after, const QString& text, int mergeKey);
    void undo() override;
    void redo() override;
    int id() const override { return m_mergeKey == 0 ? -1 : 1; }
    bool mergeWith(const QUndoCommand* other) override;

private:
    SceneDocument* m_doc;
    // The state to apply: `state` with the document's current camera unless this edit set the camera.
    Scene withCamera(const Scene& state) const;

    Scene m_before, m_after;
    bool m_setsCamera;   // the edit changed the camera (else undo and redo keep the navigated one)
    int m_mergeKey;
    int m_epoch;
};

// The merge key of an editor's edit: edits of one editor less than a second apart (arrow keys held, a
// dial dragged) are one undo step; a pause or another editor starts the next.
class EditMerger {
public:
    int keyFor(const QObject* editor);
    void clear() { m_keys.clear(); }

private:
    struct State {
        int key = 0;
        qint64 lastMs = 0;
    };
    std::map<const QObject*, State> m_keys;
};

} // namespace sylva
