// MainWindow: menus and docks, document <-> viewport wiring, import/lighting/export jobs.
#include "studio/main_window.h"

#include <cmath>
#include <numeric>

#include <QAction>
#include <QApplication>
#include <QCheckBox>
#include <QCloseEvent>
#include <QComboBox>
#include <QDateTime>
#include <QDir>
#include <QDockWidget>
#include <QDragEnterEvent>
#include <QDropEvent>
#include <QFileDialog>
#include <QFileInfo>
#include <QHBoxLayout>
#include <QHeaderView>
#include <QJsonDocument>
#include <QJsonObject>
#include <QLabel>
#include <QMenuBar>
#include <QMimeData>
#include <QPlainTextEdit>
#include <QSaveFile>
#include <QSettings>
#include <QStandardPaths>
#include <QStatusBar>
#include <QToolBar>
#include <QTreeView>
#include <QVBoxLayout>

#include "core/base/error.h"
#include "core/lb/lb_params.h"
#include "core/render/render_cpu.h"
#include "pipeline/cache/grid_cache.h"
#include "pipeline/grow/tree_grower.h"
#include "pipeline/import/mesh_import.h"
#include "pipeline/io/npy.h"
#include "pipeline/render/render_job.h"
#include "pipeline/scene/scene_file.h"
#include "studio/background_priority.h"
#include "studio/job_manager.h"
#include "studio/job_panel.h"
#include "studio/outliner_model.h"
#include "studio/property_panel.h"
#include "studio/viewport.h"
#include "studio/volume_inspector.h"

namespace sylva {
namespace {

constexpr int kMaxRecentFiles = 8;
const char* kSceneFilter = "Sylva scenes (*.sylva.json)";

QString meshFilter()
{
    return QObject::tr("Meshes (*.obj *.fbx *.gltf *.glb *.ply *.dae *.3ds *.stl);;All files (*)");
}

// A unique species name from a wish ("Tree_1", then "Tree_1 (2)", ...).
std::string uniqueSpeciesName(const Scene& s, const std::string& wish)
{
    auto taken = [&](const std::string& n) {
        for (const SpeciesDesc& sp : s.species)
            if (sp.name == n) return true;
        return false;
    };
    const std::string base = wish.empty() ? std::string("species") : wish;
    if (!taken(base)) return base;
    for (int i = 2;; ++i) {
        const std::string n = base + " (" + std::to_string(i) + ")";
        if (!taken(n)) return n;
    }
}

// A camera that shows world box b whole, from the front-left and a little above.
CameraDesc framingCamera(const CameraDesc& current, const Bounds3& b)
{
    CameraDesc c = current;
    const glm::dvec3 centre = glm::dvec3(b.center());
    const double radius = std::max(0.1, 0.5 * double(glm::length(b.extent())));
    const double dist = 1.15 * radius / std::sin(double(c.fovY) * 0.5 * 3.14159265358979323846 / 180.0);
    c.target = centre;
    c.position = centre + dist * glm::normalize(glm::dvec3(-0.35, 0.2, -1.0));
    c.up = glm::vec3(0.0f, 1.0f, 0.0f);
    return c;
}

SpeciesDesc newSpeciesDesc()
{
    SpeciesDesc sp;
    sp.preset = "leaf";
    sp.lighting = lb::paramsFromPreset(*lb::findPreset("leaf"));
    sp.grid = QSettings().value("import/grid", 64).toInt();
    return sp;
}

} // namespace

MainWindow::MainWindow(QWidget* parent)
    : QMainWindow(parent), m_doc(new SceneDocument(this)), m_jobs(new JobManager(this)), m_cache(std::make_unique<GridCache>())
{
    setObjectName("MainWindow");
    setAcceptDrops(true);
    lowerTbbWorkerPriority();
    m_reportError = [this](const QString& title, const QString& message) { QMessageBox::critical(this, title, message); };
    m_askSave = [this](const QString& name) {
        return QMessageBox::warning(this, tr("Unsaved changes"), tr("Save the changes to %1?").arg(name),
                                    QMessageBox::Save | QMessageBox::Discard | QMessageBox::Cancel, QMessageBox::Save);
    };

    // Centre: render mode bar over the viewport.
    auto* centre = new QWidget;
    auto* cl = new QVBoxLayout(centre);
    cl->setContentsMargins(0, 0, 0, 0);
    cl->setSpacing(0);
    auto* bar = new QToolBar;
    bar->addWidget(new QLabel(tr(" Mode ")));
    m_modeBox = new QComboBox;
    m_modeBox->setObjectName("renderMode");
    for (RenderMode m : {RenderMode::Full, RenderMode::Local, RenderMode::Ambient, RenderMode::Lb})
        m_modeBox->addItem(QString::fromLatin1(renderModeName(m)), int(m));
    m_modeBox->setToolTip(tr("full = sun + LB indirect; local = sun only; ambient = sun + constant; lb = indirect only"));
    bar->addWidget(m_modeBox);
    bar->addSeparator();
    m_compareToggle = new QCheckBox(tr("Compare with"));
    m_compareToggle->setObjectName("compareToggle");
    m_compareToggle->setToolTip(tr("Side by side: the left half in the mode on the left, the right half in this mode, from one trace"));
    bar->addWidget(m_compareToggle);
    m_compareBox = new QComboBox;
    m_compareBox->setObjectName("compareMode");
    for (RenderMode m : {RenderMode::Full, RenderMode::Local, RenderMode::Ambient, RenderMode::Lb})
        m_compareBox->addItem(QString::fromLatin1(renderModeName(m)), int(m));
    m_compareBox->setCurrentIndex(m_compareBox->findData(int(RenderMode::Lb)));
    m_compareBox->setEnabled(false);
    bar->addWidget(m_compareBox);
    cl->addWidget(bar);
    m_viewport = new Viewport;
    cl->addWidget(m_viewport, 1);
    setCentralWidget(centre);
    connect(m_modeBox, &QComboBox::activated, this, [this](int index) {
        Scene s = m_doc->scene();
        s.render.mode = RenderMode(m_modeBox->itemData(index).toInt());
        m_doc->edit(s, tr("Render mode %1").arg(m_modeBox->itemText(index)));
    });
    connect(m_compareToggle, &QCheckBox::toggled, this, [this] { updateCompare(); });
    connect(m_compareBox, &QComboBox::currentIndexChanged, this, [this] { updateCompare(); });
    connect(m_viewport, &Viewport::cameraEdited, this, [this](const CameraDesc& camera, int key) {
        Scene s = m_doc->scene();
        s.camera = camera;
        m_doc->edit(s, tr("Navigate"), key);
    });
    connect(m_viewport, &Viewport::imageShown, this, [this](int pass, bool last, double seconds) {
        statusBar()->showMessage(tr("Viewport: pass %1%2, %3 s after the change")
                                     .arg(pass + 1)
                                     .arg(last ? tr(" (final)") : QString())
                                     .arg(seconds, 0, 'f', 3));
    });
    connect(m_viewport, &Viewport::renderFailed, this, [this](const QString& m) { appendLog(tr("viewport: %1").arg(m)); });

    buildDocks();
    buildActions();

    m_lightingTimer.setSingleShot(true);
    m_lightingTimer.setInterval(250);
    connect(&m_lightingTimer, &QTimer::timeout, this, [this] { computeLighting(); });
    connect(m_doc, &SceneDocument::changed, this, &MainWindow::onDocumentChanged);
    connect(m_doc, &SceneDocument::modifiedChanged, this, [this] { updateTitle(); });
    connect(m_doc, &SceneDocument::filePathChanged, this, [this] { updateTitle(); });
    connect(m_jobs, &JobManager::logLine, this, &MainWindow::appendLog);
    m_askRecover = [this](const QString& origin, const QDateTime& when) {
        return QMessageBox::question(this, tr("Recover unsaved changes?"),
                                     tr("Sylva Studio did not close cleanly. Recover the unsaved changes to %1 autosaved at %2?")
                                         .arg(origin.isEmpty() ? tr("an untitled scene") : origin,
                                              QLocale().toString(when, QLocale::ShortFormat)),
                                     QMessageBox::Yes | QMessageBox::No, QMessageBox::Yes) == QMessageBox::Yes;
    };
    connect(m_doc, &SceneDocument::modifiedChanged, this, [this](bool modified) {
        if (!modified) removeRecoveryFile();
    });
    m_editMaterials = [this](const QString& species, const std::vector<MaterialChoice>& materials) {
        MaterialDialog d(species, materials, this);
        return d.exec() == QDialog::Accepted ? std::optional<std::vector<std::string>>(d.leafMaterials()) : std::nullopt;
    };
    connect(&m_autosaveTimer, &QTimer::timeout, this, [this] { autosaveNow(); });
    setAutosaveInterval(QSettings().value("autosave/intervalSeconds", 60).toInt() * 1000);
    m_recoveryPending = QFileInfo::exists(recoveryFilePath());
    QTimer::singleShot(0, this, [this] { offerRecovery(); });
    updateTitle();
    updateViewport();
    statusBar()->showMessage(tr("Ready"));
}

MainWindow::~MainWindow()
{
    m_jobs->cancelAll();
    m_jobs->waitForAll();
    // Children outlive this body: nothing they emit while being deleted (the undo stack's clear,
    // a last image) may reach this half-destroyed window.
    m_doc->disconnect(this);
    m_jobs->disconnect(this);
    m_viewport->disconnect(this);
    m_lightingTimer.stop();
    m_autosaveTimer.stop();
}

// ---- autosave and crash recovery ----

QString MainWindow::recoveryFilePath()
{
    return QStandardPaths::writableLocation(QStandardPaths::AppDataLocation) + QStringLiteral("/recovery/autosave.sylva.json");
}

namespace {
QString recoveryInfoPath() { return QFileInfo(MainWindow::recoveryFilePath()).absolutePath() + QStringLiteral("/autosave.json"); }
} // namespace

void MainWindow::setAutosaveInterval(int milliseconds)
{
    if (milliseconds <= 0) {
        m_autosaveTimer.stop();
        return;
    }
    m_autosaveTimer.start(milliseconds);
}

bool MainWindow::autosaveNow()
{
    if (m_recoveryPending) return false;
    const Scene& s = m_doc->scene();
    if (!m_doc->isModified()) {
        removeRecoveryFile();
        return false;
    }
    if (m_doc->revision() == m_autosavedRevision && QFileInfo::exists(recoveryFilePath())) return false;
    if (s.species.empty() || s.instances.empty()) {
        removeRecoveryFile();   // not a scene file the reader accepts; an older autosave would mislead
        return false;
    }
    try {
        writeSceneFile(s, recoveryFilePath().toStdString());
        QSaveFile info(recoveryInfoPath());
        QJsonObject o;
        o["file"] = m_doc->filePath();
        o["saved"] = QDateTime::currentDateTimeUtc().toString(Qt::ISODate);
        if (!info.open(QIODevice::WriteOnly) || info.write(QJsonDocument(o).toJson()) < 0 || !info.commit())
            throw Error(info.fileName().toStdString() + ": " + info.errorString().toStdString());
    } catch (const std::exception& e) {
        appendLog(tr("autosave failed: %1").arg(QString::fromStdString(e.what())));
        return false;
    }
    m_autosavedRevision = m_doc->revision();
    Q_EMIT autosaved(recoveryFilePath());
    return true;
}

void MainWindow::removeRecoveryFile()
{
    if (m_recoveryPending) return;
    QFile::remove(recoveryFilePath());
    QFile::remove(recoveryInfoPath());
    m_autosavedRevision = 0;
}

bool MainWindow::offerRecovery()
{
    m_recoveryPending = false;
    const QString path = recoveryFilePath();
    if (!QFileInfo::exists(path)) return false;
    QString origin;
    QDateTime when = QFileInfo(path).lastModified();
    QFile info(recoveryInfoPath());
    if (info.open(QIODevice::ReadOnly)) {
        const QJsonObject o = QJsonDocument::fromJson(info.readAll()).object();
        origin = o["file"].toString();
        const QDateTime t = QDateTime::fromString(o["saved"].toString(), Qt::ISODate);
        if (t.isValid()) when = t.toLocalTime();
    }
    const bool recover = m_askRecover ? m_askRecover(origin, when) : false;
    bool recovered = false;
    if (recover) {
        try {
            const Scene scene = readSceneFile(path.toStdString());
            // On top of the saved file (undo shows what was saved), else of an empty untitled scene.
            bool based = false;
            if (!origin.isEmpty() && QFileInfo::exists(origin)) {
                try {
                    m_doc->open(origin);
                    based = true;
                } catch (const std::exception& e) {
                    appendLog(tr("recovery: %1 cannot be read (%2); recovering as untitled").arg(origin, QString::fromStdString(e.what())));
                }
            }
            if (!based) m_doc->reset(Scene{}, QString());
            m_doc->edit(scene, tr("Recover unsaved changes"));
            appendLog(tr("recovered unsaved changes%1").arg(origin.isEmpty() ? QString() : tr(" to %1").arg(origin)));
            recovered = true;
        } catch (const std::exception& e) {
            reportError(tr("Recovery failed"), QString::fromStdString(e.what()));
        }
    }
    removeRecoveryFile();
    return recovered;
}

void MainWindow::buildDocks()
{
    m_model = new OutlinerModel(m_doc, this);
    m_outliner = new QTreeView;
    m_outliner->setObjectName("outliner");
    m_outliner->setModel(m_model);
    m_outliner->setSelectionMode(QAbstractItemView::SingleSelection);
    m_outliner->header()->setSectionResizeMode(0, QHeaderView::ResizeToContents);
    m_outliner->expandAll();
    connect(m_model, &QAbstractItemModel::modelReset, m_outliner, &QTreeView::expandAll);
    connect(m_outliner->selectionModel(), &QItemSelectionModel::currentChanged, this, &MainWindow::onSelectionChanged);
    auto* outlinerDock = new QDockWidget(tr("Outliner"), this);
    outlinerDock->setObjectName("outlinerDock");
    outlinerDock->setWidget(m_outliner);

    m_properties = new PropertyPanel(m_doc);
    auto* propDock = new QDockWidget(tr("Properties"), this);
    propDock->setObjectName("propertiesDock");
    propDock->setWidget(m_properties);

    m_jobPanel = new JobPanel(m_jobs);
    auto* jobDock = new QDockWidget(tr("Jobs"), this);
    jobDock->setObjectName("jobsDock");
    jobDock->setWidget(m_jobPanel);

    m_log = new QPlainTextEdit;
    m_log->setObjectName("log");
    m_log->setReadOnly(true);
    m_log->setMaximumBlockCount(5000);
    auto* logDock = new QDockWidget(tr("Log"), this);
    logDock->setObjectName("logDock");
    logDock->setWidget(m_log);

    m_inspector = new VolumeInspector;
    m_inspectorDock = new QDockWidget(tr("Lighting Inspector"), this);
    m_inspectorDock->setObjectName("inspectorDock");
    m_inspectorDock->setWidget(m_inspector);
    connect(m_inspectorDock, &QDockWidget::visibilityChanged, this, [this](bool visible) {
        if (visible) refreshInspector();
    });

    // Outliner over properties on the right, full height; jobs beside the log under the viewport.
    setCorner(Qt::BottomRightCorner, Qt::RightDockWidgetArea);
    addDockWidget(Qt::RightDockWidgetArea, outlinerDock);
    splitDockWidget(outlinerDock, propDock, Qt::Vertical);
    addDockWidget(Qt::BottomDockWidgetArea, jobDock);
    splitDockWidget(jobDock, logDock, Qt::Horizontal);
    // The inspector on the left, hidden until View > Lighting Inspector.
    addDockWidget(Qt::LeftDockWidgetArea, m_inspectorDock);
    m_inspectorDock->hide();
}

void MainWindow::showEvent(QShowEvent* event)
{
    QMainWindow::showEvent(event);
    if (m_docksSized) return;
    m_docksSized = true;
    // Dock sizes only hold once the window has its size: the viewport gets what the docks leave.
    auto dock = [this](const char* name) { return findChild<QDockWidget*>(QString::fromLatin1(name)); };
    resizeDocks({dock("outlinerDock")}, {320}, Qt::Horizontal);
    resizeDocks({dock("outlinerDock"), dock("propertiesDock")}, {2, 3}, Qt::Vertical);
    resizeDocks({dock("jobsDock"), dock("logDock")}, {1, 2}, Qt::Horizontal);
    resizeDocks({dock("jobsDock")}, {130}, Qt::Vertical);
}

void MainWindow::buildActions()
{
    QMenu* file = menuBar()->addMenu(tr("&File"));
    auto add = [this](QMenu* menu, const QString& text, const char* name, const QKeySequence& key, auto slot) {
        QAction* a = menu->addAction(text);
        a->setObjectName(QString::fromLatin1(name));
        if (!key.isEmpty()) a->setShortcut(key);
        connect(a, &QAction::triggered, this, slot);
        return a;
    };
    add(file, tr("&New"), "actionNew", QKeySequence::New, [this] { newScene(); });
    add(file, tr("&Open..."), "actionOpen", QKeySequence::Open, [this] { openDialog(); });
    m_recentMenu = file->addMenu(tr("Open &Recent"));
    add(file, tr("Open &Example Forest"), "actionExample", QKeySequence(), [this] { loadExampleForest(); });
    file->addSeparator();
    add(file, tr("&Save"), "actionSave", QKeySequence::Save, [this] { save(); });
    add(file, tr("Save &As..."), "actionSaveAs", QKeySequence::SaveAs, [this] { saveAsDialog(); });
    file->addSeparator();
    add(file, tr("&Import Mesh..."), "actionImport", QKeySequence(Qt::CTRL | Qt::Key_I), [this] { importDialog(); });
    add(file, tr("&Grow Species..."), "actionGrow", QKeySequence(Qt::CTRL | Qt::Key_G), [this] { growDialog(); });
    add(file, tr("&Export Render..."), "actionExport", QKeySequence(Qt::CTRL | Qt::Key_E), [this] { exportDialog(); });
    add(file, tr("Export Species &Grids..."), "actionExportGrids", QKeySequence(), [this] { exportGridsDialog(); });
    file->addSeparator();
    add(file, tr("&Quit"), "actionQuit", QKeySequence::Quit, [this] { close(); });
    updateRecentMenu();

    QMenu* edit = menuBar()->addMenu(tr("&Edit"));
    QAction* undo = m_doc->undoStack()->createUndoAction(this, tr("&Undo"));
    undo->setObjectName("actionUndo");
    undo->setShortcut(QKeySequence::Undo);
    QAction* redo = m_doc->undoStack()->createRedoAction(this, tr("&Redo"));
    redo->setObjectName("actionRedo");
    redo->setShortcut(QKeySequence::Redo);
    edit->addAction(undo);
    edit->addAction(redo);
    edit->addSeparator();
    add(edit, tr("&Delete"), "actionDelete", QKeySequence::Delete, [this] { deleteSelection(); });
    add(edit, tr("Species &Materials..."), "actionMaterials", QKeySequence(), [this] { editMaterials(selectedSpecies()); });
    add(edit, tr("&Scatter Instances..."), "actionScatter", QKeySequence(Qt::CTRL | Qt::SHIFT | Qt::Key_T), [this] { scatterDialog(); });

    QMenu* render = menuBar()->addMenu(tr("&Render"));
    add(render, tr("Compute &Lighting"), "actionLight", QKeySequence(Qt::CTRL | Qt::Key_L), [this] { computeLighting(); });
    add(render, tr("&Reload Lighting"), "actionReload", QKeySequence(Qt::CTRL | Qt::SHIFT | Qt::Key_L),
        [this] { computeLighting(true); });
    QAction* autoLight = render->addAction(tr("&Automatic Lighting"));
    autoLight->setObjectName("actionAutoLighting");
    autoLight->setCheckable(true);
    autoLight->setChecked(m_autoLighting);
    connect(autoLight, &QAction::toggled, this, &MainWindow::setAutoLighting);
    render->addSeparator();
    add(render, tr("&Cancel All Jobs"), "actionCancelJobs", QKeySequence(Qt::Key_Escape), [this] { m_jobs->cancelAll(); });

    m_viewMenu = menuBar()->addMenu(tr("&View"));
    for (QDockWidget* d : findChildren<QDockWidget*>()) m_viewMenu->addAction(d->toggleViewAction());
    m_viewMenu->addSeparator();
    // F in the viewport toggles it too (a window-wide F shortcut would eat the key in text fields).
    QAction* fly = m_viewMenu->addAction(tr("&Fly Navigation (F in the viewport)"));
    fly->setObjectName("actionFly");
    fly->setCheckable(true);
    connect(fly, &QAction::toggled, m_viewport, &Viewport::setFlyMode);
    connect(m_viewport, &Viewport::flyModeChanged, this, [this, fly](bool on) {
        const QSignalBlocker block(fly);
        fly->setChecked(on);
        statusBar()->showMessage(on ? tr("Fly: W/S forward/back, A/D left/right, Q/E down/up (Shift: faster), drag to look; F: back to orbit")
                                    : tr("Orbit: drag to orbit, Shift+drag or middle drag to pan, wheel to zoom"),
                                 on ? 0 : 4000);
    });

    QMenu* help = menuBar()->addMenu(tr("&Help"));
    add(help, tr("&About Sylva Studio"), "actionAbout", QKeySequence(), [this] {
        QMessageBox::about(this, tr("About Sylva Studio"),
                           tr("<b>Sylva Studio</b> %1<br>Forests lit with the lattice-Boltzmann lighting model.")
                               .arg(QString::fromLatin1(SYLVA_VERSION)));
    });
}

QString MainWindow::logText() const { return m_log->toPlainText(); }

void MainWindow::clearLog() { m_log->clear(); }

void MainWindow::appendLog(const QString& line)
{
    m_log->appendPlainText(QDateTime::currentDateTime().toString(QStringLiteral("HH:mm:ss  ")) + line);
    Q_EMIT logLineAdded(line);
}

void MainWindow::reportError(const QString& title, const QString& message)
{
    appendLog(tr("error: %1").arg(message));
    Q_EMIT errorReported(title, message);
    if (m_reportError) m_reportError(title, message);
}

void MainWindow::setAutoLighting(bool on)
{
    m_autoLighting = on;
    if (auto* a = findChild<QAction*>("actionAutoLighting")) {
        const QSignalBlocker block(a);
        a->setChecked(on);
    }
    if (on) updateViewport();
    else m_lightingTimer.stop();
}

// ---- document and title ----

void MainWindow::updateTitle()
{
    setWindowTitle(tr("%1[*] - Sylva Studio").arg(m_doc->displayName()));
    setWindowModified(m_doc->isModified());
}

bool MainWindow::maybeSave()
{
    if (!m_doc->isModified()) return true;
    switch (m_askSave ? m_askSave(m_doc->displayName()) : QMessageBox::Discard) {
    case QMessageBox::Save: return save();
    case QMessageBox::Discard: return true;
    default: return false;
    }
}

bool MainWindow::newScene()
{
    if (!maybeSave()) return false;
    if (m_lightingJob) m_lightingJob->cancel();   // exports of the old scene may finish
    m_doc->reset(Scene{}, QString());
    appendLog(tr("new scene"));
    return true;
}

bool MainWindow::openFile(const QString& path)
{
    if (!maybeSave()) return false;
    try {
        m_doc->open(path);
    } catch (const std::exception& e) {
        reportError(tr("Open failed"), QString::fromStdString(e.what()));
        return false;
    }
    addRecentFile(m_doc->filePath());
    appendLog(tr("opened %1").arg(m_doc->filePath()));
    return true;
}

bool MainWindow::saveFile(const QString& path)
{
    QString p = path;
    if (!p.endsWith(QLatin1String(".sylva.json"))) p += QLatin1String(".sylva.json");
    try {
        m_doc->saveAs(p);
    } catch (const std::exception& e) {
        reportError(tr("Save failed"), QString::fromStdString(e.what()));
        return false;
    }
    addRecentFile(m_doc->filePath());
    appendLog(tr("saved %1").arg(m_doc->filePath()));
    statusBar()->showMessage(tr("Saved %1").arg(m_doc->filePath()), 3000);
    return true;
}

bool MainWindow::save() { return m_doc->filePath().isEmpty() ? saveAsDialog() : saveFile(m_doc->filePath()); }

QStringList MainWindow::recentFiles() const { return QSettings().value("recentFiles").toStringList(); }

void MainWindow::addRecentFile(const QString& path)
{
    QStringList files = recentFiles();
    files.removeAll(path);
    files.prepend(path);
    while (files.size() > kMaxRecentFiles) files.removeLast();
    QSettings().setValue("recentFiles", files);
    updateRecentMenu();
}

void MainWindow::updateRecentMenu()
{
    if (!m_recentMenu) return;
    m_recentMenu->clear();
    const QStringList files = recentFiles();
    for (int i = 0; i < files.size(); ++i) {
        const QString f = files[i];
        QAction* a = m_recentMenu->addAction(QStringLiteral("&%1 %2").arg(i + 1).arg(QFileInfo(f).fileName()));
        a->setToolTip(f);
        connect(a, &QAction::triggered, this, [this, f] { openFile(f); });
    }
    m_recentMenu->setEnabled(!files.isEmpty());
}

void MainWindow::onDocumentChanged(ScenePart parts)
{
    const Scene& s = m_doc->scene();
    {
        const QSignalBlocker block(m_modeBox);
        m_modeBox->setCurrentIndex(m_modeBox->findData(int(s.render.mode)));
    }
    if (parts == ScenePart::All) m_properties->showItem(m_properties->item());
    updateViewport();
    if (hasPart(parts, ScenePart::Species) || hasPart(parts, ScenePart::Sun) || hasPart(parts, ScenePart::Instances))
        refreshInspector();
}

bool MainWindow::viewNeedsLighting() const
{
    const std::optional<RenderMode> compare = m_viewport->compare();
    return modeNeedsLighting(m_doc->scene().render.mode) || (compare && modeNeedsLighting(*compare));
}

void MainWindow::updateCompare()
{
    m_compareBox->setEnabled(m_compareToggle->isChecked());
    const std::optional<RenderMode> mode =
        m_compareToggle->isChecked() ? std::optional<RenderMode>(RenderMode(m_compareBox->currentData().toInt())) : std::nullopt;
    if (mode == m_viewport->compare()) return;
    m_viewport->setCompare(mode);
    updateViewport();   // the second mode may need lighting the first does not
}

void MainWindow::updateViewport()
{
    const Scene& s = m_doc->scene();
    const bool lit = viewNeedsLighting();
    std::vector<AssetsPtr> assets = m_assets.forScene(s, lit);
    if (s.instances.empty() || !assets.empty()) {
        m_viewport->setScene(s, std::move(assets));
        return;
    }
    m_viewport->setScene(s, {});
    if (m_autoLighting) {
        m_viewport->setStatus(lit ? tr("Lighting the species...") : tr("Loading the species..."));
        m_lightingTimer.start();
    } else {
        m_viewport->setStatus(tr("Lighting not computed: Render > Compute Lighting (%1)")
                                  .arg(QKeySequence(Qt::CTRL | Qt::Key_L).toString(QKeySequence::NativeText)));
    }
}

void MainWindow::onSelectionChanged()
{
    m_properties->showItem(m_model->itemAt(m_outliner->currentIndex()));
    refreshInspector();
}

int MainWindow::selectedSpecies() const
{
    const OutlinerItem it = m_model->itemAt(m_outliner->currentIndex());
    const Scene& s = m_doc->scene();
    if (it.kind == OutlinerItem::Kind::Species && it.row >= 0 && size_t(it.row) < s.species.size()) return it.row;
    if (it.kind == OutlinerItem::Kind::Instance && it.row >= 0 && size_t(it.row) < s.instances.size() &&
        s.instances[size_t(it.row)].species < s.species.size())
        return int(s.instances[size_t(it.row)].species);
    return -1;
}

// ---- lighting volume inspector ----

void MainWindow::refreshInspector()
{
    if (!m_inspectorDock || !m_inspectorDock->isVisible()) return;
    const int species = selectedSpecies();
    if (species < 0) {
        if (m_inspectorJob) m_inspectorJob->cancel();
        m_inspectedKey.clear();
        m_inspector->setMessage(tr("Select a species (or one of its instances) to inspect its lighting grids."));
        Q_EMIT inspectorUpdated();
        return;
    }
    const Scene& s = m_doc->scene();
    const std::string key = assetKey(s.species[size_t(species)], s.sun, true);
    if (key == m_inspectedKey) return;   // shown or loading
    if (m_lightingJob || m_lightingTimer.isActive()) {
        // The lighting job solves these grids (or is about to): read them from the cache when it is
        // done rather than solve them twice at once.
        if (m_inspectorJob) m_inspectorJob->cancel();
        m_inspectedKey.clear();
        m_inspector->setMessage(tr("Waiting for the lighting job..."));
        return;
    }
    inspectSpecies(species);
}

Job* MainWindow::inspectSpecies(int species)
{
    const Scene scene = m_doc->scene();
    if (species < 0 || size_t(species) >= scene.species.size()) return nullptr;
    const SpeciesDesc& sp = scene.species[size_t(species)];
    const std::string key = assetKey(sp, scene.sun, true);
    if (m_inspectorJob) m_inspectorJob->cancel();
    m_inspectedKey = key;
    const QString name = QString::fromStdString(sp.name);
    m_inspector->setMessage(tr("Loading the grids of %1...").arg(name));
    // The species' mesh when the viewport already holds it (no second import).
    AssetsPtr held = m_assets.find(assetKey(sp, scene.sun, true));
    if (!held) held = m_assets.find(assetKey(sp, scene.sun, false));
    auto result = std::make_shared<std::shared_ptr<const SpeciesGrids>>();
    GridCache* cache = m_cache.get();
    m_inspectorJob = m_jobs->start(tr("Inspect %1").arg(name),
                                   [scene, species, held, cache, result](Job& job, Progress& progress) {
                                       JobLog log;
                                       SpeciesGrids g = loadSpeciesGrids(scene, size_t(species), cache, &progress, &log,
                                                                         held ? &held->mesh : nullptr);
                                       const std::string& n = scene.species[size_t(species)].name;
                                       for (const std::string& stage : log.stages)
                                           job.log(QString::fromStdString(stage.rfind(n + ":", 0) == 0 ? stage : n + ": " + stage));
                                       *result = std::make_shared<const SpeciesGrids>(std::move(g));
                                   },
                                   [this, key, name, result](Job* job) {
                                       if (key != m_inspectedKey) return;   // the selection moved on
                                       if (job->state() == Job::State::Succeeded) {
                                           m_inspector->setGrids(name, *result);
                                       } else {
                                           m_inspectedKey.clear();
                                           m_inspector->setMessage(job->state() == Job::State::Failed
                                                                       ? tr("The grids of %1 could not be loaded: %2").arg(name, job->error())
                                                                       : tr("Loading the grids of %1 was cancelled.").arg(name));
                                       }
                                       Q_EMIT inspectorUpdated();
                                   });
    return m_inspectorJob;
}

// ---- import, grow, lighting, export ----

void MainWindow::addSpecies(SpeciesDesc species, const Bounds3& bounds, const QString& undoText)
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
    m_outliner->setCurrentIndex(m_model->indexOf({OutlinerItem::Kind::Instance, int(s.instances.size() - 1)}));
}

Job* MainWindow::importMesh(const QString& path)
{
    struct Result {
        Bounds3 bounds;
        size_t triangles = 0;
        std::vector<std::string> warnings;
    };
    auto result = std::make_shared<Result>();
    const QString abs = QFileInfo(path).absoluteFilePath();
    const std::string file = abs.toStdString();
    appendLog(tr("importing %1").arg(abs));
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
                                 reportError(tr("Import failed"), job->error());
                                 return;
                             }
                             if (job->state() != Job::State::Succeeded) {
                                 appendLog(tr("import of %1 cancelled").arg(abs));
                                 return;
                             }
                             for (const std::string& w : result->warnings)
                                 appendLog(tr("warning: %1").arg(QString::fromStdString(w)));
                             SpeciesDesc sp = newSpeciesDesc();
                             sp.name = QFileInfo(abs).completeBaseName().toStdString();
                             sp.meshPath = abs.toStdString();
                             appendLog(tr("imported %1: %2 triangles").arg(abs).arg(result->triangles));
                             addSpecies(sp, result->bounds, tr("Import %1").arg(QFileInfo(abs).fileName()));
                         });
}

void MainWindow::growSpecies(const GrowSpec& spec)
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

void MainWindow::loadExampleForest()
{
    if (!maybeSave()) return;
    m_doc->reset(defaultScene(), QString());
    appendLog(tr("example forest: %1 species, %2 instances")
                  .arg(m_doc->scene().species.size())
                  .arg(m_doc->scene().instances.size()));
}

Job* MainWindow::computeLighting(bool reload)
{
    m_lightingTimer.stop();
    const Scene scene = m_doc->scene();
    const bool lit = viewNeedsLighting();
    std::vector<std::string> target;
    for (const SpeciesDesc& sp : scene.species) target.push_back(assetKey(sp, scene.sun, lit));
    if (m_lightingJob) {
        // One lighting job at a time. One that already makes what the scene needs (the camera or an
        // instance moved meanwhile) runs on; otherwise stop it and run again for the scene as it is now.
        if (!reload && target == m_lightingTarget && !m_lightingJob->cancelRequested()) {
            m_lightingAgain = false;
            return m_lightingJob;
        }
        m_lightingJob->cancel();
        m_lightingAgain = true;
        return nullptr;
    }
    if (reload) {
        std::vector<std::string> keep;
        m_assets.retainOnly(keep);
    } else {
        // Keep what the scene uses (and what undo may bring back soon: everything of this sun).
        std::vector<std::string> keep;
        for (const SpeciesDesc& sp : scene.species) {
            keep.push_back(assetKey(sp, scene.sun, true));
            keep.push_back(assetKey(sp, scene.sun, false));
        }
        if (m_assets.size() > 4 * keep.size() + 8) m_assets.retainOnly(keep);
    }
    if (m_assets.missingSpecies(scene, lit).empty()) {
        updateViewport();
        refreshInspector();
        return nullptr;
    }
    GridCache* cache = m_cache.get();
    AssetStore* store = &m_assets;
    appendLog(lit ? tr("lighting %n species", nullptr, int(m_assets.missingSpecies(scene, lit).size()))
                  : tr("loading %n species", nullptr, int(m_assets.missingSpecies(scene, lit).size())));
    m_lightingTarget = target;
    m_lightingJob = m_jobs->start(lit ? tr("Lighting") : tr("Loading"),
                                  [scene, lit, store, cache](Job& job, Progress& progress) {
                                      ensureAssets(scene, lit, *store, cache, &progress, [&job](const std::string& line) {
                                          job.log(QString::fromStdString(line));
                                      });
                                  },
                                  [this](Job* job) {
                                      m_lightingJob = nullptr;
                                      const bool ok = job->state() == Job::State::Succeeded;
                                      if (ok) appendLog(tr("lighting done in %1 s").arg(job->seconds(), 0, 'f', 2));
                                      else if (job->state() == Job::State::Cancelled) appendLog(tr("lighting cancelled"));
                                      else reportError(tr("Lighting failed"), job->error());
                                      if (m_lightingAgain) {
                                          m_lightingAgain = false;
                                          computeLighting();
                                      } else {
                                          updateViewport();
                                      }
                                      refreshInspector();
                                      Q_EMIT lightingFinished(ok);
                                  });
    return m_lightingJob;
}

Job* MainWindow::exportRender(const ExportSettings& settings)
{
    Scene scene = m_doc->scene();
    if (scene.instances.empty()) {
        reportError(tr("Export failed"), tr("The scene is empty."));
        return nullptr;
    }
    scene.render.width = settings.width;
    scene.render.height = settings.height;
    scene.render.spp = settings.spp;
    m_lastExport = settings;
    const std::string path = settings.path.toStdString();
    GridCache* cache = m_cache.get();
    AssetStore* store = &m_assets;
    appendLog(tr("exporting %1 (%2 x %3, %4 spp)").arg(settings.path).arg(settings.width).arg(settings.height).arg(settings.spp));
    return m_jobs->start(tr("Export %1").arg(QFileInfo(settings.path).fileName()),
                         [scene, path, store, cache](Job& job, Progress& progress) {
                             const bool lit = modeNeedsLighting(scene.render.mode);
                             SubProgress assetsPart(&progress, 0.0, 0.4);
                             Progress assetsProgress([&](double f, const std::string& m) { assetsPart.report(f, m); });
                             const std::vector<AssetsPtr> shared = ensureAssets(
                                 scene, lit, *store, cache, &assetsProgress,
                                 [&job](const std::string& line) { job.log(QString::fromStdString(line)); });
                             std::vector<SpeciesAssets> assets;
                             for (const AssetsPtr& a : shared) assets.push_back(*a);
                             progress.report(0.45, "building");
                             const RenderScene rs = buildRenderScene(scene, assets, sunRadiance(scene.sun));
                             SubProgress tracePart(&progress, 0.5, 0.98);
                             Progress traceProgress([&](double f, const std::string& m) { tracePart.report(f, m); });
                             const Film film = renderFilm(rs.view(), &traceProgress);
                             const std::vector<glm::vec3> linear = composeMode(film, scene.render.mode, scene.sky);
                             writeRender(path, linear, film.width, film.height, scene.render.exposureKey);
                             progress.report(1.0, "written");
                         },
                         [this, settings](Job* job) {
                             if (job->state() == Job::State::Succeeded)
                                 appendLog(tr("exported %1 in %2 s").arg(settings.path).arg(job->seconds(), 0, 'f', 2));
                             else if (job->state() == Job::State::Failed) reportError(tr("Export failed"), job->error());
                             else appendLog(tr("export cancelled"));
                         });
}

QString MainWindow::gridFileBase(const QString& speciesName)
{
    QString out;
    for (QChar c : speciesName)
        out += (c.isLetterOrNumber() && c.unicode() < 128) || c == u'.' || c == u'-' || c == u'_' ? c : QChar(u'_');
    return out.isEmpty() ? QStringLiteral("species") : out;
}

Job* MainWindow::exportSpeciesGrids(int species, const QString& folder)
{
    const Scene scene = m_doc->scene();
    if (species < 0 || size_t(species) >= scene.species.size()) {
        reportError(tr("Export failed"), tr("Select a species (or one of its instances) to export its grids."));
        return nullptr;
    }
    const SpeciesDesc& sp = scene.species[size_t(species)];
    const QString base = QDir(folder).filePath(gridFileBase(QString::fromStdString(sp.name)));
    const std::string densityPath = (base + QStringLiteral(".density.npy")).toStdString();
    const std::string lightingPath = (base + QStringLiteral(".lighting.npy")).toStdString();
    AssetsPtr held = m_assets.find(assetKey(sp, scene.sun, true));
    if (!held) held = m_assets.find(assetKey(sp, scene.sun, false));
    GridCache* cache = m_cache.get();
    appendLog(tr("exporting the grids of %1 to %2").arg(QString::fromStdString(sp.name), QDir::toNativeSeparators(folder)));
    return m_jobs->start(tr("Export grids of %1").arg(QString::fromStdString(sp.name)),
                         [scene, species, held, cache, densityPath, lightingPath](Job& job, Progress& progress) {
                             const SpeciesDesc& d = scene.species[size_t(species)];
                             SubProgress loadPart(&progress, 0.0, 0.9);
                             Progress loadProgress([&](double f, const std::string& m) { loadPart.report(f, m); });
                             JobLog log;
                             const SpeciesGrids g = loadSpeciesGrids(scene, size_t(species), cache, &loadProgress, &log,
                                                                     held ? &held->mesh : nullptr);
                             for (const std::string& stage : log.stages)
                                 job.log(QString::fromStdString(stage.rfind(d.name + ":", 0) == 0 ? stage : d.name + ": " + stage));
                             progress.report(0.9, "writing");
                             writeDensityGrid(densityPath, g.density);
                             writeLightingGrid(lightingPath, g.lighting, lightingParamsJson(g.params, d.preset, g.lighting.geometry.dims));
                             progress.report(1.0, "written");
                         },
                         [this, densityPath, lightingPath](Job* job) {
                             if (job->state() == Job::State::Succeeded)
                                 appendLog(tr("exported %1 and %2").arg(QString::fromStdString(densityPath), QString::fromStdString(lightingPath)));
                             else if (job->state() == Job::State::Failed) reportError(tr("Export failed"), job->error());
                             else appendLog(tr("grid export cancelled"));
                         });
}

bool MainWindow::setLeafMaterials(int species, const std::vector<std::string>& names)
{
    Scene s = m_doc->scene();
    if (species < 0 || size_t(species) >= s.species.size() || s.species[size_t(species)].leafMaterials == names) return false;
    SpeciesDesc& sp = s.species[size_t(species)];
    sp.leafMaterials = names;
    m_doc->edit(s, tr("Materials of %1").arg(QString::fromStdString(sp.name)));
    appendLog(names.empty() ? tr("%1: leaf materials by the importer's rules").arg(QString::fromStdString(sp.name))
                            : tr("%1: leaf materials %2")
                                  .arg(QString::fromStdString(sp.name),
                                       QString::fromStdString(std::accumulate(std::next(names.begin()), names.end(), names.front(),
                                                                              [](std::string a, const std::string& b) { return a + ", " + b; }))));
    return true;
}

Job* MainWindow::editMaterials(int species)
{
    const Scene& scene = m_doc->scene();
    if (species < 0 || size_t(species) >= scene.species.size()) {
        reportError(tr("Materials"), tr("Select a species (or one of its instances) to assign its materials."));
        return nullptr;
    }
    const SpeciesDesc sp = scene.species[size_t(species)];
    if (sp.meshPath.empty()) {
        reportError(tr("Materials"), tr("%1 is grown: the grower marks its leaves and wood itself.").arg(QString::fromStdString(sp.name)));
        return nullptr;
    }
    auto result = std::make_shared<std::vector<MaterialChoice>>();
    return m_jobs->start(tr("Materials of %1").arg(QString::fromStdString(sp.name)),
                         [sp, result](Job&, Progress& progress) {
                             progress.report(0.0, "reading");
                             // The rules alone (no override), then what the species' list makes of them.
                             const TriangleMesh mesh = sylva::importMesh(sp.meshPath, ImportOptions{});
                             for (const Material& m : mesh.materials) {
                                 MaterialChoice c;
                                 c.name = QString::fromStdString(m.name);
                                 c.leafByRules = m.isLeaf;
                                 c.leaf = m.isLeaf;
                                 if (!sp.leafMaterials.empty()) {
                                     c.leaf = false;
                                     for (const std::string& n : sp.leafMaterials)
                                         c.leaf = c.leaf || QString::fromStdString(n).compare(c.name, Qt::CaseInsensitive) == 0;
                                 }
                                 result->push_back(c);
                             }
                             progress.report(1.0, "read");
                         },
                         [this, species, sp, result](Job* job) {
                             if (job->state() == Job::State::Failed) {
                                 reportError(tr("Materials"), job->error());
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

ScatterSpec MainWindow::defaultScatter() const
{
    const Scene& s = m_doc->scene();
    ScatterSpec spec;
    spec.species = uint32_t(std::max(0, selectedSpecies()));
    spec.count = 100;
    spec.height = s.ground.height;
    spec.scaleMin = 0.8f;
    spec.scaleMax = 1.2f;
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

bool MainWindow::scatter(const ScatterSpec& spec)
{
    Scene s = m_doc->scene();
    if (spec.species >= s.species.size()) {
        reportError(tr("Scatter failed"), tr("Species %1 does not exist; grow or import one first.").arg(spec.species));
        return false;
    }
    std::vector<InstanceDesc> added;
    try {
        added = scatterInstances(spec);
    } catch (const std::exception& e) {
        reportError(tr("Scatter failed"), QString::fromStdString(e.what()));
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
    m_doc->edit(s, tr("Scatter %n instance(s) of %1", nullptr, spec.count).arg(QString::fromStdString(s.species[spec.species].name)));
    appendLog(tr("scattered %1 instances of %2 (seed %3)")
                  .arg(spec.count)
                  .arg(QString::fromStdString(s.species[spec.species].name))
                  .arg(spec.seed));
    return true;
}

void MainWindow::scatterDialog()
{
    const Scene& s = m_doc->scene();
    if (s.species.empty()) {
        reportError(tr("Scatter failed"), tr("The scene has no species: grow or import one first."));
        return;
    }
    QStringList names;
    for (const SpeciesDesc& sp : s.species) names << QString::fromStdString(sp.name);
    ScatterDialog d(names, defaultScatter(), this);
    if (d.exec() == QDialog::Accepted) scatter(d.spec());
}

void MainWindow::deleteSelection()
{
    const OutlinerItem it = m_model->itemAt(m_outliner->currentIndex());
    Scene s = m_doc->scene();
    if (it.kind == OutlinerItem::Kind::Instance && it.row >= 0 && size_t(it.row) < s.instances.size()) {
        s.instances.erase(s.instances.begin() + it.row);
        m_doc->edit(s, tr("Delete instance"));
    } else if (it.kind == OutlinerItem::Kind::Species && it.row >= 0 && size_t(it.row) < s.species.size()) {
        // The species and its instances; later species move down one index.
        const uint32_t gone = uint32_t(it.row);
        const std::string name = s.species[gone].name;
        s.species.erase(s.species.begin() + it.row);
        std::vector<InstanceDesc> kept;
        for (InstanceDesc in : s.instances) {
            if (in.species == gone) continue;
            if (in.species > gone) --in.species;
            kept.push_back(in);
        }
        s.instances = std::move(kept);
        m_doc->edit(s, tr("Delete species %1").arg(QString::fromStdString(name)));
    }
}

// ---- dialogs ----

void MainWindow::openDialog()
{
    const QString path = QFileDialog::getOpenFileName(this, tr("Open Scene"), QString(), tr(kSceneFilter));
    if (!path.isEmpty()) openFile(path);
}

bool MainWindow::saveAsDialog()
{
    QString path = QFileDialog::getSaveFileName(this, tr("Save Scene As"),
                                                m_doc->filePath().isEmpty() ? tr("forest.sylva.json") : m_doc->filePath(),
                                                tr(kSceneFilter));
    return !path.isEmpty() && saveFile(path);
}

void MainWindow::importDialog()
{
    const QString path = QFileDialog::getOpenFileName(this, tr("Import Mesh"), QString(), meshFilter());
    if (!path.isEmpty()) importMesh(path);
}

void MainWindow::growDialog()
{
    GrowDialog d(this);
    if (d.exec() == QDialog::Accepted) growSpecies(d.spec());
}

void MainWindow::exportDialog()
{
    ExportSettings initial = m_lastExport;
    if (initial.path.isEmpty()) {
        const Scene& s = m_doc->scene();
        initial.path = QFileInfo(m_doc->filePath().isEmpty() ? tr("render") : m_doc->filePath()).absolutePath() +
                       QStringLiteral("/render.png");
        initial.width = s.render.width;
        initial.height = s.render.height;
        initial.spp = std::max(1, s.render.spp);
    }
    ExportDialog d(initial, this);
    if (d.exec() == QDialog::Accepted) exportRender(d.settings());
}

void MainWindow::exportGridsDialog()
{
    const int species = selectedSpecies();
    if (species < 0) {
        reportError(tr("Export failed"), tr("Select a species (or one of its instances) to export its grids."));
        return;
    }
    const QString folder = QFileDialog::getExistingDirectory(
        this, tr("Export the grids of %1 to").arg(QString::fromStdString(m_doc->scene().species[size_t(species)].name)),
        m_doc->filePath().isEmpty() ? QString() : QFileInfo(m_doc->filePath()).absolutePath());
    if (!folder.isEmpty()) exportSpeciesGrids(species, folder);
}

// ---- window events ----

void MainWindow::closeEvent(QCloseEvent* event)
{
    if (!maybeSave()) {
        event->ignore();
        return;
    }
    m_jobs->cancelAll();
    m_jobs->waitForAll();
    removeRecoveryFile();   // a clean close: nothing to recover
    event->accept();
}

void MainWindow::dragEnterEvent(QDragEnterEvent* event)
{
    if (event->mimeData()->hasUrls()) event->acceptProposedAction();
}

void MainWindow::dropEvent(QDropEvent* event)
{
    for (const QUrl& url : event->mimeData()->urls()) {
        if (!url.isLocalFile()) continue;
        const QString path = url.toLocalFile();
        if (path.endsWith(QLatin1String(".sylva.json"))) openFile(path);
        else importMesh(path);
    }
    event->acceptProposedAction();
}

} // namespace sylva
