// SceneDocument: scene value + file + undo stack; SceneEditCommand swaps whole scene states.
#include "studio/scene_document.h"

#include <atomic>

#include <QDateTime>
#include <QFileInfo>

#include "core/base/error.h"
#include "pipeline/render/view_frame.h"
#include "pipeline/scene/scene_file.h"
#include "studio/scene_sky.h"

namespace sylva {
namespace {

bool sameInstance(const InstanceDesc& a, const InstanceDesc& b)
{
    return a.species == b.species && a.position == b.position && a.rotationDeg == b.rotationDeg && a.scale == b.scale;
}

bool sameSpecies(const std::vector<SpeciesDesc>& a, const std::vector<SpeciesDesc>& b)
{
    if (a.size() != b.size()) return false;
    for (size_t i = 0; i < a.size(); ++i)
        if (a[i].name != b[i].name || speciesFingerprint(a[i]) != speciesFingerprint(b[i])) return false;
    return true;
}

bool sameTerrain(const TerrainDesc& a, const TerrainDesc& b)
{
    return sameTerrainHeights(a, b) && sameLandscapeTiles(a, b) && sameLandscapeDensity(a, b) && a.rock == b.rock && a.snow == b.snow &&
           a.rockSlope == b.rockSlope && a.snowLine == b.snowLine;
}

} // namespace

std::string speciesFingerprint(const SpeciesDesc& species)
{
    Scene mini;
    mini.species.push_back(species);
    mini.species[0].name = "species";
    try {
        return sceneToJson(mini, "/");
    } catch (const Error& e) {
        return std::string("unwritable: ") + e.what() + " " + species.meshPath;
    }
}

ScenePart changedParts(const Scene& a, const Scene& b)
{
    ScenePart p = ScenePart::None;
    // The lighting block (direct light, LB boundary, forest grid) decides the species' grids: a species change.
    if (!sameSpecies(a.species, b.species) || !(a.lighting == b.lighting)) p = p | ScenePart::Species;
    bool sameInstances = a.instances.size() == b.instances.size();
    for (size_t i = 0; sameInstances && i < a.instances.size(); ++i) sameInstances = sameInstance(a.instances[i], b.instances[i]);
    if (!sameInstances) p = p | ScenePart::Instances;
    if (a.ground.enabled != b.ground.enabled || a.ground.height != b.ground.height || a.ground.color != b.ground.color)
        p = p | ScenePart::Ground;
    if (a.sun.direction != b.sun.direction || a.sun.temperature != b.sun.temperature || a.sun.intensity != b.sun.intensity ||
        !sameSunPlace(a.sun, b.sun))
        p = p | ScenePart::Sun;
    if (a.sky != b.sky || !sameSkySettings(a.skyModel, b.skyModel)) p = p | ScenePart::Sky;
    if (!sameTerrain(a.terrain, b.terrain)) p = p | ScenePart::Terrain;
    if (!sameVolumes(a.volumes, b.volumes)) p = p | ScenePart::Volumes;
    const CameraDesc &ca = a.camera, &cb = b.camera;
    if (ca.position != cb.position || ca.target != cb.target || ca.up != cb.up || ca.fovY != cb.fovY) p = p | ScenePart::Camera;
    const RenderSettings &ra = a.render, &rb = b.render;
    if (ra.width != rb.width || ra.height != rb.height || ra.spp != rb.spp || ra.mode != rb.mode || ra.accel != rb.accel ||
        ra.shadows != rb.shadows || ra.indirectScale != rb.indirectScale || ra.exposureKey != rb.exposureKey || ra.leafTint != rb.leafTint ||
        ra.integrator != rb.integrator || ra.maxBounces != rb.maxBounces || ra.view != rb.view || ra.display != rb.display ||
        a.version != b.version)
        p = p | ScenePart::Render;
    return p;
}

SceneDocument::SceneDocument(QObject* parent) : QObject(parent)
{
    connect(&m_undo, &QUndoStack::cleanChanged, this, [this](bool clean) { Q_EMIT modifiedChanged(!clean); });
}

QString SceneDocument::displayName() const
{
    return m_filePath.isEmpty() ? QStringLiteral("untitled") : QFileInfo(m_filePath).fileName();
}

int SceneDocument::newMergeKey()
{
    static std::atomic<int> next{1};
    return next.fetch_add(1);
}

int EditMerger::keyFor(const QObject* editor)
{
    State& m = m_keys[editor];
    const qint64 now = QDateTime::currentMSecsSinceEpoch();
    if (m.key == 0 || now - m.lastMs > 1000) m.key = SceneDocument::newMergeKey();
    m.lastMs = now;
    return m.key;
}

void SceneDocument::edit(const Scene& afterIn, const QString& text, int mergeKey)
{
    // The sky the edit asks for (a Preetham sky follows the sun), built before the step is pushed.
    Scene after = afterIn;
    std::string why;
    if (!refreshSceneSky(m_scene, after, &why)) {
        Q_EMIT editRefused(text, QString::fromStdString(why));
        return;
    }
    if (changedParts(m_scene, after) == ScenePart::None) return;
    m_pushing = true;
    m_undo.push(new SceneEditCommand(this, m_scene, after, text, mergeKey));
    m_pushing = false;
}

void SceneDocument::navigate(const CameraDesc& camera)
{
    if (camera.position == m_scene.camera.position && camera.target == m_scene.camera.target &&
        camera.up == m_scene.camera.up && camera.fovY == m_scene.camera.fovY)
        return;
    m_scene.camera = camera;
    ++m_revision;
    Q_EMIT changed(ScenePart::Camera);
}

void SceneDocument::setState(const Scene& scene)
{
    const ScenePart parts = changedParts(m_scene, scene);
    if (!m_pushing) ++m_mergeEpoch;
    m_scene = scene;
    ++m_revision;
    Q_EMIT changed(parts);
}

void SceneDocument::reset(const Scene& scene, const QString& filePath)
{
    m_undo.clear();
    m_scene = scene;
    ++m_revision;
    m_undo.setClean();
    if (m_filePath != filePath) {
        m_filePath = filePath;
        Q_EMIT filePathChanged(m_filePath);
    }
    Q_EMIT changed(ScenePart::All);
    Q_EMIT modifiedChanged(false);
}

void SceneDocument::open(const QString& path)
{
    Scene s = readSceneFile(path.toStdString());
    reset(s, QFileInfo(path).absoluteFilePath());
}

void SceneDocument::saveAs(const QString& path)
{
    writeSceneFile(m_scene, path.toStdString());
    const QString abs = QFileInfo(path).absoluteFilePath();
    if (m_filePath != abs) {
        m_filePath = abs;
        Q_EMIT filePathChanged(m_filePath);
    }
    m_undo.setClean();
}

SceneEditCommand::SceneEditCommand(SceneDocument* doc, Scene before, Scene after, const QString& text, int mergeKey)
    : QUndoCommand(text), m_doc(doc), m_before(std::move(before)), m_after(std::move(after)), m_mergeKey(mergeKey),
      m_epoch(doc->m_mergeEpoch)
{
    m_setsCamera = hasPart(changedParts(m_before, m_after), ScenePart::Camera);
}

Scene SceneEditCommand::withCamera(const Scene& state) const
{
    if (m_setsCamera) return state;
    Scene s = state;
    s.camera = m_doc->m_scene.camera;
    return s;
}

void SceneEditCommand::undo() { m_doc->setState(withCamera(m_before)); }

void SceneEditCommand::redo() { m_doc->setState(withCamera(m_after)); }

bool SceneEditCommand::mergeWith(const QUndoCommand* other)
{
    const auto* o = static_cast<const SceneEditCommand*>(other);
    if (m_mergeKey == 0 || o->m_mergeKey != m_mergeKey || o->m_epoch != m_epoch) return false;
    m_after = o->m_after;
    m_setsCamera = hasPart(changedParts(m_before, m_after), ScenePart::Camera);
    // A gesture that ends where it began (a drag back to its start) leaves no step: the stack drops it
    // (and is clean again if it was before the gesture).
    setObsolete(changedParts(m_before, m_after) == ScenePart::None);
    return true;
}

} // namespace sylva
