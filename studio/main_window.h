// The studio's main window: outliner, properties, viewport, jobs and log around one SceneDocument.
// The window keeps the layout, the menus and their wiring, and the document's file commands (new,
// open, save, delete); each other job is a controller it owns (see docs/STUDIO.md): autosave and
// recovery, recent files, lighting scheduling, the inspector's loading, exports, materials, scatter,
// import and grow. Every menu action has a method (here or on its controller) that tests (and
// scripts) call without the file dialogs.
#pragma once

#include <functional>
#include <memory>

#include <QMainWindow>
#include <QMessageBox>

#include "studio/asset_store.h"
#include "studio/scene_document.h"

class QCheckBox;
class QComboBox;
class QDockWidget;
class QMenu;
class QPlainTextEdit;
class QSpinBox;
class QTreeView;

namespace sylva {

class Backend;

class AutosaveController;
class ExportController;
class GridCache;
class InspectorController;
class JobManager;
class JobPanel;
class LightingScheduler;
class MaterialsController;
class OutlinerModel;
class PropertyPanel;
class SkyPanel;
class RecentFiles;
class RenderWindow;
class ManualDialog;
class ShortcutSheet;
class ScatterTool;
class SpeciesImporter;
class StudioController;
class Viewport;
class VolumeInspector;
class VolumeTools;

class MainWindow : public QMainWindow {
    Q_OBJECT

public:
    explicit MainWindow(QWidget* parent = nullptr);
    ~MainWindow() override;

    SceneDocument* document() const { return m_doc; }
    OutlinerModel* outlinerModel() const { return m_model; }
    QTreeView* outliner() const { return m_outliner; }
    PropertyPanel* propertyPanel() const { return m_properties; }
    SkyPanel* skyPanel() const { return m_skyPanel; }
    Viewport* viewport() const { return m_viewport; }
    JobManager* jobs() const { return m_jobs; }
    JobPanel* jobPanel() const { return m_jobPanel; }
    // The species assets in memory (filled by the lighting jobs, read by the viewport, exports and
    // the inspector) and the grid cache on disk below them.
    AssetStore* assetStore() { return &m_assets; }
    GridCache* gridCache() const { return m_cache.get(); }
    // Where the lighting jobs, inspections and exports solve and trace: selectBackend("auto"), the
    // GPU when there is one, else the CPU (the log says which at start-up and after a fallback).
    Backend* backend() const { return m_backend.get(); }
    QComboBox* modeSelector() const { return m_modeBox; }
    QComboBox* integratorSelector() const { return m_integratorBox; }
    // Side-by-side compare: the toggle and the second mode (the right half of the viewport).
    QCheckBox* compareToggle() const { return m_compareToggle; }
    QComboBox* compareSelector() const { return m_compareBox; }
    // The viewport's sample limit (Viewport::setSampleLimit; 0 shows "as the render").
    QSpinBox* sampleLimitBox() const { return m_sampleLimitBox; }
    VolumeInspector* inspector() const { return m_inspector; }
    QDockWidget* inspectorDock() const { return m_inspectorDock; }
    QString logText() const;
    void clearLog();

    // The controllers (owned by the window).
    AutosaveController* autosave() const { return m_autosave; }
    RecentFiles* recentFiles() const { return m_recent; }
    LightingScheduler* lighting() const { return m_lighting; }
    InspectorController* inspectorController() const { return m_inspection; }
    ExportController* exporter() const { return m_export; }
    MaterialsController* materials() const { return m_materials; }
    ScatterTool* scatterTool() const { return m_scatter; }
    SpeciesImporter* importer() const { return m_importer; }
    VolumeTools* volumeTools() const { return m_volumeTools; }
    // Render > Render Image (F12): shows the render window and starts its render; the window (made on first use).
    RenderWindow* renderImage();
    RenderWindow* renderWindow() const { return m_renderWindow; }
    // Help > Manual (F1) and Help > Keyboard Shortcuts: shown (not modal), made on first use.
    ManualDialog* showManual();
    ShortcutSheet* showShortcuts();

    // How errors and the unsaved-changes question reach the user. Defaults: modal message boxes.
    // Tests install non-blocking ones; errorReported is emitted either way (for the controllers'
    // errors too).
    using ErrorReporter = std::function<void(const QString& title, const QString& message)>;
    void setErrorReporter(ErrorReporter reporter) { m_reportError = std::move(reporter); }
    using SavePrompt = std::function<QMessageBox::StandardButton(const QString& documentName)>;
    void setSavePrompt(SavePrompt prompt) { m_askSave = std::move(prompt); }
    // How File > Open asks for the scene file, given the folder to start in (lastFolder("scenes")). Default:
    // QFileDialog. Asked only after the unsaved-changes question; an empty answer opens nothing.
    using OpenChooser = std::function<QString(const QString& folder)>;
    void setOpenChooser(OpenChooser chooser) { m_chooseOpen = std::move(chooser); }

    // File
    bool newScene();                       // false when the user cancelled the unsaved-changes prompt
    bool openFile(const QString& path);    // false (and an error report) on a bad file; prompts first
    bool saveFile(const QString& path);    // false (and an error report) when it cannot be written
    bool save();                           // to the current file, or Save As when untitled
    void loadExampleForest();
    // File > Open...: the unsaved-changes question first, then the file chooser, then the file.
    void openDialog();
    // Edit
    void deleteSelection();
    // The species the outliner selection points at (a species row, or an instance's species); -1 if none.
    int selectedSpecies() const;
    // The window's size, place and dock layout in QSettings (window/geometry, window/state): saved
    // on close, restored when the window first shows. restoreLayout: false when nothing (valid) was saved.
    void saveLayout() const;
    bool restoreLayout();

Q_SIGNALS:
    void errorReported(const QString& title, const QString& message);
    void logLineAdded(const QString& line);

protected:
    void closeEvent(QCloseEvent* event) override;
    bool eventFilter(QObject* watched, QEvent* event) override;   // the outliner's viewport resized: fitOutlinerDetails
    void showEvent(QShowEvent* event) override;
    void dragEnterEvent(QDragEnterEvent* event) override;
    void dropEvent(QDropEvent* event) override;

private:
    void buildActions();
    void buildDocks();
    // Connects a controller's log lines and errors to the log view and the error reporter.
    void adopt(StudioController* controller);
    void appendLog(const QString& line);
    void reportError(const QString& title, const QString& message);
    bool maybeSave();
    void updateTitle();
    void onDocumentChanged(ScenePart parts);
    void updateCompare();
    void onSelectionChanged();
    // The outliner's Details column: as wide as its widest text (the view scrolls sideways) or the room left, whichever is more.
    void fitOutlinerDetails();
    void refreshInspector();   // the inspector controller, once it exists (and until the window goes)
    bool saveAsDialog();
    bool loadFile(const QString& path);   // openFile without the unsaved-changes question

    SceneDocument* m_doc;
    JobManager* m_jobs;
    AssetStore m_assets;
    std::unique_ptr<GridCache> m_cache;
    std::unique_ptr<Backend> m_backend;
    OutlinerModel* m_model;
    QTreeView* m_outliner = nullptr;
    PropertyPanel* m_properties;
    SkyPanel* m_skyPanel = nullptr;
    Viewport* m_viewport;
    JobPanel* m_jobPanel;
    QPlainTextEdit* m_log;
    QComboBox* m_modeBox;
    QComboBox* m_integratorBox;
    QCheckBox* m_compareToggle;
    QComboBox* m_compareBox;
    QSpinBox* m_sampleLimitBox;
    VolumeInspector* m_inspector = nullptr;
    QDockWidget* m_inspectorDock = nullptr;
    QMenu* m_viewMenu = nullptr;

    AutosaveController* m_autosave = nullptr;
    RecentFiles* m_recent = nullptr;
    LightingScheduler* m_lighting = nullptr;
    InspectorController* m_inspection = nullptr;
    ExportController* m_export = nullptr;
    MaterialsController* m_materials = nullptr;
    ScatterTool* m_scatter = nullptr;
    SpeciesImporter* m_importer = nullptr;
    VolumeTools* m_volumeTools = nullptr;
    RenderWindow* m_renderWindow = nullptr;
    ManualDialog* m_manual = nullptr;
    ShortcutSheet* m_shortcuts = nullptr;

    ErrorReporter m_reportError;
    SavePrompt m_askSave;
    OpenChooser m_chooseOpen;
    bool m_docksSized = false;
};

} // namespace sylva
