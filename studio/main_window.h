// The studio's main window: outliner, properties, viewport, jobs and log around one SceneDocument.
// Every menu action has a method here that tests (and scripts) call without the file dialogs.
#pragma once

#include <functional>

#include <QDateTime>
#include <memory>
#include <optional>

#include <QMainWindow>
#include <QMessageBox>
#include <QPointer>
#include <QTimer>

#include "studio/asset_store.h"
#include "studio/dialogs.h"
#include "studio/scene_document.h"

class QCheckBox;
class QComboBox;
class QDockWidget;
class QMenu;
class QPlainTextEdit;
class QTreeView;

namespace sylva {

class GridCache;
class Job;
class JobManager;
class JobPanel;
class OutlinerModel;
class PropertyPanel;
class Viewport;
class VolumeInspector;

class MainWindow : public QMainWindow {
    Q_OBJECT

public:
    explicit MainWindow(QWidget* parent = nullptr);
    ~MainWindow() override;

    SceneDocument* document() const { return m_doc; }
    OutlinerModel* outlinerModel() const { return m_model; }
    QTreeView* outliner() const { return m_outliner; }
    PropertyPanel* propertyPanel() const { return m_properties; }
    Viewport* viewport() const { return m_viewport; }
    JobManager* jobs() const { return m_jobs; }
    JobPanel* jobPanel() const { return m_jobPanel; }
    AssetStore* assetStore() { return &m_assets; }
    QComboBox* modeSelector() const { return m_modeBox; }
    // Side-by-side compare: the toggle and the second mode (the right half of the viewport).
    QCheckBox* compareToggle() const { return m_compareToggle; }
    QComboBox* compareSelector() const { return m_compareBox; }
    VolumeInspector* inspector() const { return m_inspector; }
    QDockWidget* inspectorDock() const { return m_inspectorDock; }
    QString logText() const;
    void clearLog();

    // How errors and the unsaved-changes question reach the user. Defaults: modal message boxes.
    // Tests install non-blocking ones; errorReported is emitted either way.
    using ErrorReporter = std::function<void(const QString& title, const QString& message)>;
    void setErrorReporter(ErrorReporter reporter) { m_reportError = std::move(reporter); }
    using SavePrompt = std::function<QMessageBox::StandardButton(const QString& documentName)>;
    void setSavePrompt(SavePrompt prompt) { m_askSave = std::move(prompt); }

    // Crash recovery: the question asked when a recovery file is found (origin: the scene's file, empty
    // when untitled; when: the autosave's time). Default: a modal question box. Answer true to recover.
    using RecoveryPrompt = std::function<bool(const QString& origin, const QDateTime& when)>;
    void setRecoveryPrompt(RecoveryPrompt prompt) { m_askRecover = std::move(prompt); }

    // Autosave: every interval (default 60 s, settings key autosave/intervalSeconds; 0 = off) a modified
    // scene goes to recoveryFilePath(); a clean save, a clean document or a close deletes it.
    void setAutosaveInterval(int milliseconds);
    int autosaveInterval() const { return m_autosaveTimer.isActive() ? m_autosaveTimer.interval() : 0; }
    // Writes the recovery file now when the scene is modified and changed since the last autosave;
    // true when it wrote one.
    bool autosaveNow();
    // Where autosave writes: QStandardPaths::AppDataLocation/recovery/autosave.sylva.json, with
    // autosave.json beside it naming the scene's own file.
    static QString recoveryFilePath();
    // Offers the recovery file, if there is one (the window does this once, just after it is built):
    // recovering replaces the document with the file's scene on top of the saved one (one undo step,
    // modified); either way the recovery file is deleted. True when a scene was recovered.
    bool offerRecovery();

    // How the leaf/wood question reaches the user: the species' materials in, its new leaf_materials
    // out (nullopt: cancelled). Default: MaterialDialog, modal.
    using MaterialEditor =
        std::function<std::optional<std::vector<std::string>>(const QString& species, const std::vector<MaterialChoice>& materials)>;
    void setMaterialEditor(MaterialEditor editor) { m_editMaterials = std::move(editor); }

    // Lighting starts by itself (debounced) when species, sun or mode change; off: Render > Compute Lighting.
    void setAutoLighting(bool on);
    bool autoLighting() const { return m_autoLighting; }

    // File
    bool newScene();                       // false when the user cancelled the unsaved-changes prompt
    bool openFile(const QString& path);    // false (and an error report) on a bad file; prompts first
    bool saveFile(const QString& path);    // false (and an error report) when it cannot be written
    bool save();                           // to the current file, or Save As when untitled
    QStringList recentFiles() const;
    // Import a mesh file as a new species with one instance at the origin (a background job; the
    // scene changes when it succeeds, never when it fails).
    Job* importMesh(const QString& path);
    void growSpecies(const GrowSpec& spec);
    void loadExampleForest();
    // Render
    // Loads/grows, voxelizes and lights what the viewport needs (reload: drop the in-memory assets
    // first, so the grid cache answers). Returns the job, or null when everything is in memory.
    Job* computeLighting(bool reload = false);
    Job* exportRender(const ExportSettings& settings);
    // Writes a species' grids (loadSpeciesGrids) into folder as NAME.density.npy (+ NAME.density.wood.npy)
    // and NAME.lighting.npy, each with its JSON sidecar (CONTRACTS.md); NAME is the species name with
    // characters other than letters, digits, '.', '-', '_' replaced by '_'. Null (and an error report)
    // for a bad species index.
    Job* exportSpeciesGrids(int species, const QString& folder);
    static QString gridFileBase(const QString& speciesName);
    // Edit
    void deleteSelection();
    // Adds spec.count instances of a species scattered over a rectangle (scatterInstances) as one undo
    // step; false (and an error report) for a bad spec or species.
    bool scatter(const ScatterSpec& spec);
    // The scatter form's starting values: the selected species, 100 instances over the instances'
    // footprint (20 m around the origin when there are none) on the ground.
    ScatterSpec defaultScatter() const;
    // Edit > Species Materials: reads the species' mesh in a job (its materials, what the importer's
    // rules make of each, what leaf_materials makes of them now), asks the MaterialEditor, and writes
    // the answer with setLeafMaterials. Null (and an error report) for a grown species or a bad index.
    Job* editMaterials(int species);
    // Sets a species' leaf_materials (empty: the importer's rules) as one undo step; false when unchanged.
    bool setLeafMaterials(int species, const std::vector<std::string>& names);
    // The species the outliner selection points at (a species row, or an instance's species); -1 if none.
    int selectedSpecies() const;
    // Lighting volume inspector: loads the species' density and lighting grids (the lighting job's
    // calls, through the grid cache) in a job and shows them. Null when nothing needs loading.
    Job* inspectSpecies(int species);

Q_SIGNALS:
    void errorReported(const QString& title, const QString& message);
    void lightingFinished(bool succeeded);
    void inspectorUpdated();   // the inspector shows new grids (or a message)
    void autosaved(const QString& path);
    void logLineAdded(const QString& line);

protected:
    void closeEvent(QCloseEvent* event) override;
    void showEvent(QShowEvent* event) override;
    void dragEnterEvent(QDragEnterEvent* event) override;
    void dropEvent(QDropEvent* event) override;

private:
    void buildActions();
    void buildDocks();
    void appendLog(const QString& line);
    void reportError(const QString& title, const QString& message);
    bool maybeSave();
    void addRecentFile(const QString& path);
    void updateRecentMenu();
    void updateTitle();
    void onDocumentChanged(ScenePart parts);
    void updateViewport();
    void updateCompare();
    bool viewNeedsLighting() const;
    void onSelectionChanged();
    void refreshInspector();
    void removeRecoveryFile();
    void addSpecies(SpeciesDesc species, const Bounds3& bounds, const QString& undoText);
    void openDialog();
    bool saveAsDialog();
    void importDialog();
    void growDialog();
    void exportDialog();
    void exportGridsDialog();
    void scatterDialog();

    SceneDocument* m_doc;
    JobManager* m_jobs;
    AssetStore m_assets;
    std::unique_ptr<GridCache> m_cache;
    OutlinerModel* m_model;
    QTreeView* m_outliner;
    PropertyPanel* m_properties;
    Viewport* m_viewport;
    JobPanel* m_jobPanel;
    QPlainTextEdit* m_log;
    QComboBox* m_modeBox;
    QCheckBox* m_compareToggle;
    QComboBox* m_compareBox;
    VolumeInspector* m_inspector = nullptr;
    QDockWidget* m_inspectorDock = nullptr;
    QPointer<Job> m_inspectorJob;
    std::string m_inspectedKey;       // asset key of what the inspector shows (or is loading)
    QMenu* m_recentMenu = nullptr;
    QMenu* m_viewMenu = nullptr;

    ErrorReporter m_reportError;
    SavePrompt m_askSave;
    RecoveryPrompt m_askRecover;
    MaterialEditor m_editMaterials;
    QTimer m_autosaveTimer;
    quint64 m_autosavedRevision = 0;
    bool m_recoveryPending = false;   // a recovery file waits to be offered: neither overwrite nor delete it
    bool m_autoLighting = true;
    QTimer m_lightingTimer;
    QPointer<Job> m_lightingJob;
    std::vector<std::string> m_lightingTarget;   // asset keys the running lighting job produces
    bool m_lightingAgain = false;
    ExportSettings m_lastExport;
    bool m_docksSized = false;
};

} // namespace sylva
