// MainWindow: the layout (viewport and docks), menus and their wiring, the document's file commands;
// the controllers it owns do the rest (docs/STUDIO.md, "How it is built").
#include "studio/main_window.h"

#include <algorithm>
#include <initializer_list>
#include <utility>

#include <QAction>
#include <QCheckBox>
#include <QCloseEvent>
#include <QComboBox>
#include <QDateTime>
#include <QDir>
#include <QDockWidget>
#include <QDragEnterEvent>
#include <QDropEvent>
#include <QFileDialog>
#include <QHeaderView>
#include <QLabel>
#include <QScrollArea>
#include <QSpinBox>
#include <QMenuBar>
#include <QMimeData>
#include <QPlainTextEdit>
#include <QSettings>
#include <QStatusBar>
#include <QToolBar>
#include <QTreeView>
#include <QVBoxLayout>

#include "pipeline/backend_select.h"
#include "pipeline/cache/grid_cache.h"
#include "pipeline/io/env_map_io.h"
#include "pipeline/render/render_job.h"
#include "studio/autosave_controller.h"
#include "studio/camera_nav.h"
#include "studio/background_priority.h"
#include "studio/export_controller.h"
#include "studio/help_dialogs.h"
#include "studio/inspector_controller.h"
#include "studio/job_manager.h"
#include "studio/job_panel.h"
#include "studio/lighting_scheduler.h"
#include "studio/sky_panel.h"
#include "studio/materials_controller.h"
#include "studio/outliner_model.h"
#include "studio/property_panel.h"
#include "studio/recent_files.h"
#include "studio/render_window.h"
#include "studio/scatter_tool.h"
#include "studio/species_importer.h"
#include "studio/view_transform.h"
#include "studio/viewport.h"
#include "studio/volume_dialogs.h"
#include "studio/volume_inspector.h"
#include "studio/words.h"

namespace sylva {
namespace {

const char* kSceneFilter = "Sylva scenes (*.sylva.json)";

} // namespace

MainWindow::MainWindow(QWidget* parent)
    : QMainWindow(parent), m_doc(new SceneDocument(this)), m_jobs(new JobManager(this)), m_cache(std::make_unique<GridCache>())
{
    setObjectName("MainWindow");
    setAcceptDrops(true);
    lowerTbbWorkerPriority();
    m_reportError = [this](const QString& title, const QString& message) { QMessageBox::critical(this, title, message); };
    m_chooseOpen = [this](const QString& folder) {
        return QFileDialog::getOpenFileName(this, tr("Open Scene"), folder, tr(kSceneFilter));
    };
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
    // Artists' words (studio/words.cpp); the items' data are the scene's values.
    bar->addWidget(new QLabel(tr(" Light: ")));
    m_modeBox = new QComboBox;
    m_modeBox->setObjectName("renderMode");
    for (RenderMode m : {RenderMode::Full, RenderMode::Local, RenderMode::Ambient, RenderMode::Lb}) {
        m_modeBox->addItem(renderModeLabel(m), int(m));
        m_modeBox->setItemData(m_modeBox->count() - 1, renderModeToolTip(m), Qt::ToolTipRole);
    }
    bar->addWidget(m_modeBox);
    bar->addWidget(new QLabel(tr(" Method: ")));
    m_integratorBox = new QComboBox;
    m_integratorBox->setObjectName("integrator");
    m_integratorBox->addItem(tr("Lighting model"), int(Integrator::Lb));
    m_integratorBox->addItem(tr("Path tracer"), int(Integrator::Path));
    bar->addWidget(m_integratorBox);
    bar->addSeparator();
    m_compareToggle = new QCheckBox(tr("Compare with"));
    m_compareToggle->setObjectName("compareToggle");
    bar->addWidget(m_compareToggle);
    m_compareBox = new QComboBox;
    m_compareBox->setObjectName("compareMode");
    for (RenderMode m : {RenderMode::Full, RenderMode::Local, RenderMode::Ambient, RenderMode::Lb}) {
        m_compareBox->addItem(renderModeLabel(m), int(m));
        m_compareBox->setItemData(m_compareBox->count() - 1, renderModeToolTip(m), Qt::ToolTipRole);
    }
    m_compareBox->setCurrentIndex(m_compareBox->findData(int(RenderMode::Lb)));
    m_compareBox->setEnabled(false);
    bar->addWidget(m_compareBox);
    bar->addSeparator();
    bar->addWidget(new QLabel(tr(" Viewport samples: ")));
    m_sampleLimitBox = new QSpinBox;
    m_sampleLimitBox->setObjectName("viewportSamples");
    m_sampleLimitBox->setRange(0, kMaxViewportSamples);
    m_sampleLimitBox->setSpecialValueText(tr("as the render"));
    m_sampleLimitBox->setKeyboardTracking(false);
    bar->addWidget(m_sampleLimitBox);
    applyToolTips(bar);
    cl->addWidget(bar);
    m_viewport = new Viewport;
    m_sampleLimitBox->setValue(m_viewport->sampleLimit());
    connect(m_sampleLimitBox, &QSpinBox::valueChanged, this, [this](int v) { m_viewport->setSampleLimit(v); });
    cl->addWidget(m_viewport, 1);
    setCentralWidget(centre);
    connect(m_modeBox, &QComboBox::activated, this, [this](int index) {
        Scene s = m_doc->scene();
        s.render.mode = RenderMode(m_modeBox->itemData(index).toInt());
        m_doc->edit(s, tr("Light: %1").arg(m_modeBox->itemText(index)));
    });
    connect(m_integratorBox, &QComboBox::activated, this, [this](int index) {
        Scene s = m_doc->scene();
        s.render.integrator = Integrator(m_integratorBox->itemData(index).toInt());
        m_doc->edit(s, tr("Method: %1").arg(m_integratorBox->itemText(index)));
    });
    connect(m_compareToggle, &QCheckBox::toggled, this, [this] { updateCompare(); });
    connect(m_compareBox, &QComboBox::currentIndexChanged, this, [this] { updateCompare(); });
    // A zoom or pan far enough leaves no distance between the eye and the target in double (1e20 m out): a camera
    // the scene file refuses is not applied.
    connect(m_viewport, &Viewport::navigated, m_doc, [this](const CameraDesc& camera) {
        if (cameraUsable(camera)) m_doc->navigate(camera);
    });
    connect(m_viewport, &Viewport::instanceEdited, this, [this](int instance, const InstanceDesc& placed, const QString& text, int key) {
        Scene s = m_doc->scene();
        if (instance < 0 || size_t(instance) >= s.instances.size()) return;
        s.instances[size_t(instance)] = placed;
        m_doc->edit(s, text, key);
    });
    // A click in the viewport selects the instance under the cursor in the outliner (nothing: clears it).
    connect(m_viewport, &Viewport::instancePicked, this, [this](int instance) {
        if (instance >= 0) {
            const QModelIndex index = m_model->indexOf({OutlinerItem::Kind::Instance, instance});
            m_outliner->setCurrentIndex(index);
            m_outliner->scrollTo(index);
        } else {
            m_outliner->selectionModel()->clear();
        }
    });
    connect(m_viewport, &Viewport::imageShown, this, [this](int pass, bool last, double seconds) {
        statusBar()->showMessage(tr("Viewport: pass %1%2, %3, %4 s after the change")
                                     .arg(pass + 1)
                                     .arg(last ? tr(" (final)") : QString())
                                     .arg(m_viewport->sampleCounterText())
                                     .arg(seconds, 0, 'f', 3));
    });
    connect(m_viewport, &Viewport::renderFailed, this, [this](const QString& m) { appendLog(tr("viewport: %1").arg(m)); });

    // Controllers that need no dock; the inspector's comes with its dock, recent files with the menu.
    // One backend for every job (selectBackend falls back to the CPU without a device). A fallback
    // after a device error is reported from the job's thread; the log hears of it on this one.
    m_backend = selectBackend("auto", [this](const std::string& note) {
        QMetaObject::invokeMethod(this, [this, line = QString::fromStdString(note)] { appendLog(tr("backend: %1").arg(line)); },
                                  Qt::QueuedConnection);
    });
    m_lighting = new LightingScheduler(m_doc, m_jobs, &m_assets, m_cache.get(), m_backend.get(), m_viewport, this);
    m_export = new ExportController(m_doc, m_jobs, &m_assets, m_cache.get(), m_backend.get(), this, this);
    m_materials = new MaterialsController(m_doc, m_jobs, this, this);
    m_scatter = new ScatterTool(m_doc, [this] { return selectedSpecies(); }, this, this);
    connect(m_scatter, &ScatterTool::frameRequested, this, [this] { m_viewport->frameAll(); });
    m_scatter->setSpeciesBox([this](int species) {
        const std::vector<Bounds3>& boxes = m_viewport->speciesBoxes();
        return species >= 0 && size_t(species) < boxes.size() ? boxes[size_t(species)] : Bounds3{};
    });
    m_importer = new SpeciesImporter(m_doc, m_jobs, this, this);
    m_volumeTools = new VolumeTools(m_doc, m_jobs, this, this);
    for (StudioController* c : std::initializer_list<StudioController*>{m_lighting, m_export, m_materials, m_scatter, m_importer, m_volumeTools})
        adopt(c);
    connect(m_importer, &SpeciesImporter::instanceAdded, this,
            [this](int instance) { m_outliner->setCurrentIndex(m_model->indexOf({OutlinerItem::Kind::Instance, instance})); });
    connect(m_lighting, &LightingScheduler::settled, this, [this] { refreshInspector(); });
    connect(m_volumeTools, &VolumeTools::volumeAdded, this,
            [this](int volume) { m_outliner->setCurrentIndex(m_model->indexOf({OutlinerItem::Kind::Volume, volume})); });

    buildDocks();
    buildActions();

    connect(m_doc, &SceneDocument::changed, this, &MainWindow::onDocumentChanged);
    connect(m_doc, &SceneDocument::modifiedChanged, this, [this] { updateTitle(); });
    connect(m_doc, &SceneDocument::filePathChanged, this, [this] { updateTitle(); });
    connect(m_jobs, &JobManager::logLine, this, &MainWindow::appendLog);
    m_autosave = new AutosaveController(m_doc, this, this);
    adopt(m_autosave);
    updateTitle();
    m_lighting->updateViewport();
    statusBar()->showMessage(tr("Ready"));
}

MainWindow::~MainWindow()
{
    m_jobs->cancelAll();
    m_jobs->waitForAll();
    // Children outlive this body: nothing they emit while being deleted (the undo stack's clear,
    // a last image) may reach this half-destroyed window or its controllers (autosave would delete
    // the recovery file a crash-like exit must leave behind).
    m_doc->disconnect(this);
    m_jobs->disconnect(this);
    m_viewport->disconnect(this);
    delete std::exchange(m_renderWindow, nullptr);
    delete std::exchange(m_autosave, nullptr);
    delete std::exchange(m_inspection, nullptr);
    delete std::exchange(m_importer, nullptr);
    delete std::exchange(m_volumeTools, nullptr);
    delete std::exchange(m_scatter, nullptr);
    delete std::exchange(m_materials, nullptr);
    delete std::exchange(m_export, nullptr);
    delete std::exchange(m_lighting, nullptr);
    delete std::exchange(m_recent, nullptr);
}

void MainWindow::refreshInspector()
{
    if (m_inspection) m_inspection->refresh();
}

void MainWindow::adopt(StudioController* controller)
{
    connect(controller, &StudioController::logLine, this, &MainWindow::appendLog);
    connect(controller, &StudioController::errorRaised, this, &MainWindow::reportError);
}

void MainWindow::buildDocks()
{
    m_model = new OutlinerModel(m_doc, this);
    m_outliner = new QTreeView;
    m_outliner->setObjectName("outliner");
    m_outliner->setModel(m_model);
    m_outliner->setSelectionMode(QAbstractItemView::SingleSelection);
    // Names as wide as they are; details as wide as their widest text or the room left (a long detail scrolls
    // sideways instead of being cut off; its tooltip holds it too).
    m_outliner->header()->setSectionResizeMode(0, QHeaderView::ResizeToContents);
    m_outliner->header()->setSectionResizeMode(1, QHeaderView::Interactive);
    m_outliner->header()->setStretchLastSection(false);
    m_outliner->setHorizontalScrollMode(QAbstractItemView::ScrollPerPixel);
    m_outliner->expandAll();
    connect(m_model, &QAbstractItemModel::modelReset, m_outliner, &QTreeView::expandAll);
    connect(m_model, &QAbstractItemModel::modelReset, this, &MainWindow::fitOutlinerDetails, Qt::QueuedConnection);
    connect(m_model, &QAbstractItemModel::dataChanged, this, &MainWindow::fitOutlinerDetails, Qt::QueuedConnection);
    connect(m_outliner->header(), &QHeaderView::sectionResized, this, [this](int section) {
        if (section == 0) fitOutlinerDetails();
    });
    m_outliner->viewport()->installEventFilter(this);
    // Rows came or went (a delete, an undo, another file): the selection is gone, and the properties with it.
    connect(m_model, &QAbstractItemModel::modelReset, this, &MainWindow::onSelectionChanged);
    connect(m_outliner->selectionModel(), &QItemSelectionModel::currentChanged, this, &MainWindow::onSelectionChanged);
    auto* outlinerDock = new QDockWidget(tr("Outliner"), this);
    outlinerDock->setObjectName("outlinerDock");
    outlinerDock->setWidget(m_outliner);

    m_properties = new PropertyPanel(m_doc);
    auto* propDock = new QDockWidget(tr("Properties"), this);
    propDock->setObjectName("propertiesDock");
    propDock->setWidget(m_properties);

    m_skyPanel = new SkyPanel(m_doc);
    auto* skyDock = new QDockWidget(tr("Sky"), this);
    skyDock->setObjectName("skyDock");
    // Scrolled: the panel is taller than the Properties beside it, and the docks' column must not grow the window.
    auto* skyScroll = new QScrollArea;
    skyScroll->setWidgetResizable(true);
    skyScroll->setFrameShape(QFrame::NoFrame);
    skyScroll->setWidget(m_skyPanel);
    skyDock->setWidget(skyScroll);
    connect(m_doc, &SceneDocument::editRefused, this,
            [this](const QString& text, const QString& why) { appendLog(tr("%1 refused: %2").arg(text, why)); });

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
    appendLog(tr("compute backend: %1").arg(QString::fromStdString(m_backend->name())));

    m_inspector = new VolumeInspector;
    m_inspectorDock = new QDockWidget(tr("Lighting Inspector"), this);
    m_inspectorDock->setObjectName("inspectorDock");
    m_inspectorDock->setWidget(m_inspector);
    m_inspection = new InspectorController(m_doc, m_jobs, &m_assets, m_cache.get(), m_backend.get(), m_lighting, m_inspector,
                                           m_inspectorDock, [this] { return selectedSpecies(); }, this);
    adopt(m_inspection);
    m_inspection->setSelectedVolume([this] {
        const OutlinerItem it = m_model->itemAt(m_outliner->currentIndex());
        return it.kind == OutlinerItem::Kind::Volume ? it.row : -1;
    });

    // Outliner over properties on the right, full height; jobs beside the log under the viewport.
    setCorner(Qt::BottomRightCorner, Qt::RightDockWidgetArea);
    addDockWidget(Qt::RightDockWidgetArea, outlinerDock);
    splitDockWidget(outlinerDock, propDock, Qt::Vertical);
    tabifyDockWidget(propDock, skyDock);
    propDock->raise();
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
    restoreLayout();   // the last session's window and docks, over these defaults
}

// ---- window layout (QSettings window/geometry, window/state) ----

namespace {
constexpr int kLayoutVersion = 1;   // bump when the docks change, so an old layout is ignored
}

void MainWindow::saveLayout() const
{
    QSettings settings;
    settings.setValue("window/geometry", saveGeometry());
    settings.setValue("window/state", saveState(kLayoutVersion));
}

bool MainWindow::restoreLayout()
{
    const QSettings settings;
    const QByteArray geometry = settings.value("window/geometry").toByteArray();
    const QByteArray state = settings.value("window/state").toByteArray();
    const bool placed = !geometry.isEmpty() && restoreGeometry(geometry);
    const bool docked = !state.isEmpty() && restoreState(state, kLayoutVersion);
    return placed && docked;
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
    m_recent = new RecentFiles(file->addMenu(tr("Open &Recent")), this);
    connect(m_recent, &RecentFiles::openRequested, this, [this](const QString& path) { openFile(path); });
    add(file, tr("Open &Example Forest"), "actionExample", QKeySequence(), [this] { loadExampleForest(); });
    file->addSeparator();
    add(file, tr("&Save"), "actionSave", QKeySequence::Save, [this] { save(); });
    add(file, tr("Save &As..."), "actionSaveAs", QKeySequence::SaveAs, [this] { saveAsDialog(); });
    file->addSeparator();
    add(file, tr("&Import Mesh..."), "actionImport", QKeySequence(Qt::CTRL | Qt::Key_I), [this] { m_importer->importDialog(); });
    add(file, tr("&Grow Species..."), "actionGrow", QKeySequence(Qt::CTRL | Qt::Key_G), [this] { m_importer->growDialog(); });
    add(file, tr("&Export Render..."), "actionExport", QKeySequence(Qt::CTRL | Qt::Key_E), [this] { m_export->exportDialog(); });
    add(file, tr("Export Species &Grids..."), "actionExportGrids", QKeySequence(), [this] { m_export->exportGridsDialog(selectedSpecies()); });
    add(file, tr("Export Species Grids as &OpenVDB..."), "actionExportGridsVdb", QKeySequence(),
        [this] { m_export->exportGridsDialog(selectedSpecies(), GridFileFormat::Vdb); });
    add(file, tr("Export Scene as g&lTF..."), "actionExportGltf", QKeySequence(), [this] { m_export->exportGltfDialog(); });
    file->addSeparator();
    add(file, tr("&Quit"), "actionQuit", QKeySequence::Quit, [this] { close(); });

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
    add(edit, tr("Species &Materials..."), "actionMaterials", QKeySequence(), [this] { m_materials->editMaterials(selectedSpecies()); });
    add(edit, tr("&Scatter Instances..."), "actionScatter", QKeySequence(Qt::CTRL | Qt::SHIFT | Qt::Key_T), [this] { m_scatter->scatterDialog(); });
    add(edit, tr("Add &Cloud..."), "actionAddCloud", QKeySequence(), [this] { m_volumeTools->cloudDialog(); });
    add(edit, tr("Simulate S&moke..."), "actionSimulateSmoke", QKeySequence(), [this] { m_volumeTools->smokeDialog(); });

    QMenu* render = menuBar()->addMenu(tr("&Render"));
    add(render, tr("Render &Image"), "actionRenderImage", QKeySequence(Qt::Key_F12), [this] { renderImage(); });
    render->addSeparator();
    add(render, tr("Compute &Lighting"), "actionLight", QKeySequence(Qt::CTRL | Qt::Key_L), [this] { m_lighting->computeLighting(); });
    add(render, tr("&Reload Lighting"), "actionReload", QKeySequence(Qt::CTRL | Qt::SHIFT | Qt::Key_L),
        [this] { m_lighting->computeLighting(true); });
    add(render, tr("Build Relighting &Basis"), "actionRelightBasis", QKeySequence(), [this] { m_lighting->buildRelightingBasis(); });
    QAction* autoLight = render->addAction(tr("&Automatic Lighting"));
    autoLight->setObjectName("actionAutoLighting");
    autoLight->setCheckable(true);
    autoLight->setChecked(m_lighting->autoLighting());
    connect(autoLight, &QAction::toggled, m_lighting, &LightingScheduler::setAutoLighting);
    connect(m_lighting, &LightingScheduler::autoLightingChanged, autoLight, [autoLight](bool on) {
        const QSignalBlocker block(autoLight);
        autoLight->setChecked(on);
    });
    render->addSeparator();
    add(render, tr("&Cancel All Jobs"), "actionCancelJobs", QKeySequence(Qt::Key_Escape), [this] { m_jobs->cancelAll(); });

    m_viewMenu = menuBar()->addMenu(tr("&View"));
    for (QDockWidget* d : findChildren<QDockWidget*>()) m_viewMenu->addAction(d->toggleViewAction());
    m_viewMenu->addSeparator();
    // Blender's View All (Home) and View Selected (numpad period).
    add(m_viewMenu, tr("Frame &All"), "actionFrameAll", QKeySequence(Qt::Key_Home), [this] { m_viewport->frameAll(); });
    add(m_viewMenu, tr("Frame &Selected"), "actionFrameSelected", QKeySequence(Qt::KeypadModifier | Qt::Key_Period),
        [this] { m_viewport->frameSelected(); });
    // A view toggle remembered across sessions (on at first): the viewport's setter called with its state.
    auto rememberedToggle = [this](const QString& text, const char* name, const QString& tip, const char* key,
                                   void (Viewport::*set)(bool)) {
        QAction* a = m_viewMenu->addAction(text);
        a->setObjectName(QString::fromLatin1(name));
        a->setCheckable(true);
        a->setToolTip(tip);
        const QString settingsKey = QString::fromLatin1(key);
        connect(a, &QAction::toggled, this, [this, set, settingsKey](bool on) {
            (m_viewport->*set)(on);
            QSettings().setValue(settingsKey, on);
        });
        a->setChecked(QSettings().value(settingsKey, true).toBool());
        (m_viewport->*set)(a->isChecked());
    };
    // The render's frame over the viewport.
    rememberedToggle(tr("&Camera Frame"), "actionCameraFrame",
                     tr("Show the render's frame in the viewport (its size's proportions; outside it darkened): "
                        "what lies inside is what Render Image and Export Render show"),
                     "view/cameraFrame", &Viewport::setCameraFrame);
    // The refinement's sample counter and progress bar over the picture.
    rememberedToggle(tr("&Sample Counter"), "actionSampleCounter",
                     tr("Show how many samples the viewport has added up, and a progress bar toward its limit, at the "
                        "bottom of the picture"),
                     "view/sampleCounter", &Viewport::setSampleCounter);
    // F in the viewport toggles it too (a window-wide F shortcut would eat the key in text fields).
    QAction* fly = m_viewMenu->addAction(tr("&Fly Navigation (F in the viewport)"));
    fly->setObjectName("actionFly");
    fly->setCheckable(true);
    connect(fly, &QAction::toggled, m_viewport, &Viewport::setFlyMode);
    connect(m_viewport, &Viewport::flyModeChanged, this, [this, fly](bool on) {
        const QSignalBlocker block(fly);
        fly->setChecked(on);
        statusBar()->showMessage(on ? tr("Fly: W/S forward/back, A/D left/right, Q/E down/up (Shift: faster), drag to look; F: back to orbit")
                                    : tr("Orbit: drag to orbit, Shift+drag or middle drag to pan, wheel to zoom, click to select"),
                                 on ? 0 : 4000);
    });

    m_viewMenu->addSeparator();
    m_viewMenu->addMenu(new ViewTransformMenu(m_doc, m_viewMenu));

    QMenu* help = menuBar()->addMenu(tr("&Help"));
    add(help, tr("&Manual"), "actionManual", QKeySequence(Qt::Key_F1), [this] { showManual(); });
    add(help, tr("&Keyboard Shortcuts"), "actionShortcuts", QKeySequence(), [this] { showShortcuts(); });
    help->addSeparator();
    add(help, tr("&About Sylva Studio"), "actionAbout", QKeySequence(), [this] {
        QMessageBox::about(this, tr("About Sylva Studio"),
                           tr("<b>Sylva Studio</b> %1<br>Forests lit with the lattice-Boltzmann lighting model.")
                               .arg(QString::fromLatin1(SYLVA_VERSION)));
    });
}

RenderWindow* MainWindow::renderImage()
{
    if (!m_renderWindow) m_renderWindow = new RenderWindow(m_doc, m_export, this);
    m_renderWindow->show();
    m_renderWindow->raise();
    m_renderWindow->activateWindow();
    m_renderWindow->render();
    return m_renderWindow;
}

ManualDialog* MainWindow::showManual()
{
    if (!m_manual) m_manual = new ManualDialog(this);
    m_manual->show();
    m_manual->raise();
    return m_manual;
}

ShortcutSheet* MainWindow::showShortcuts()
{
    delete m_shortcuts;   // made again: the actions' shortcuts as they are now
    m_shortcuts = new ShortcutSheet(this, this);
    m_shortcuts->show();
    return m_shortcuts;
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
    m_lighting->cancel();   // exports of the old scene may finish
    Scene fresh = newSceneDefaults();
    loadSceneSky(fresh);   // a uniform sky: built from the colour, cannot fail
    m_doc->reset(fresh, QString());
    appendLog(tr("new scene"));
    return true;
}

bool MainWindow::openFile(const QString& path) { return maybeSave() && loadFile(path); }

bool MainWindow::loadFile(const QString& path)
{
    try {
        m_doc->open(path);
    } catch (const std::exception& e) {
        reportError(tr("Open failed"), QString::fromStdString(e.what()));
        return false;
    }
    m_recent->add(m_doc->filePath());
    rememberFolder(QStringLiteral("scenes"), m_doc->filePath());
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
    m_recent->add(m_doc->filePath());
    rememberFolder(QStringLiteral("scenes"), m_doc->filePath());
    appendLog(tr("saved %1").arg(m_doc->filePath()));
    statusBar()->showMessage(tr("Saved %1").arg(m_doc->filePath()), 3000);
    return true;
}

bool MainWindow::save() { return m_doc->filePath().isEmpty() ? saveAsDialog() : saveFile(m_doc->filePath()); }

void MainWindow::onDocumentChanged(ScenePart parts)
{
    const Scene& s = m_doc->scene();
    {
        const QSignalBlocker block(m_modeBox);
        m_modeBox->setCurrentIndex(m_modeBox->findData(int(s.render.mode)));
    }
    {
        const QSignalBlocker block(m_integratorBox);
        m_integratorBox->setCurrentIndex(m_integratorBox->findData(int(s.render.integrator)));
    }
    if (parts == ScenePart::All) m_properties->showItem(m_properties->item());
    m_lighting->updateViewport();
    if (hasPart(parts, ScenePart::Species) || hasPart(parts, ScenePart::Sun) || hasPart(parts, ScenePart::Instances))
        refreshInspector();
}

void MainWindow::updateCompare()
{
    m_compareBox->setEnabled(m_compareToggle->isChecked());
    const std::optional<RenderMode> mode =
        m_compareToggle->isChecked() ? std::optional<RenderMode>(RenderMode(m_compareBox->currentData().toInt())) : std::nullopt;
    if (mode == m_viewport->compare()) return;
    m_viewport->setCompare(mode);
    m_lighting->updateViewport();   // the second mode may need lighting the first does not
}

void MainWindow::fitOutlinerDetails()
{
    const int room = m_outliner->viewport()->width() - m_outliner->header()->sectionSize(0);
    // (QTreeView makes sizeHintForColumn protected; the item view declares it public.)
    const int want = std::max(static_cast<const QAbstractItemView*>(m_outliner)->sizeHintForColumn(1), room);
    if (m_outliner->header()->sectionSize(1) != want) m_outliner->header()->resizeSection(1, want);
}

bool MainWindow::eventFilter(QObject* watched, QEvent* event)
{
    if (m_outliner && watched == m_outliner->viewport() && event->type() == QEvent::Resize) fitOutlinerDetails();
    return QMainWindow::eventFilter(watched, event);
}

void MainWindow::onSelectionChanged()
{
    const OutlinerItem item = m_model->itemAt(m_outliner->currentIndex());
    m_properties->showItem(item);
    m_viewport->setSelectedInstance(item.kind == OutlinerItem::Kind::Instance ? item.row : -1);
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

void MainWindow::loadExampleForest()
{
    if (!maybeSave()) return;
    m_doc->reset(defaultScene(), QString());
    appendLog(tr("example forest: %1 species, %2 instances")
                  .arg(m_doc->scene().species.size())
                  .arg(m_doc->scene().instances.size()));
}

void MainWindow::deleteSelection()
{
    const OutlinerItem it = m_model->itemAt(m_outliner->currentIndex());
    Scene s = m_doc->scene();
    if (it.kind == OutlinerItem::Kind::Instance && it.row >= 0 && size_t(it.row) < s.instances.size()) {
        s.instances.erase(s.instances.begin() + it.row);
        m_doc->edit(s, tr("Delete instance"));
    } else if (it.kind == OutlinerItem::Kind::Volume && it.row >= 0 && size_t(it.row) < s.volumes.size()) {
        const std::string name = s.volumes[size_t(it.row)].name;
        s.volumes.erase(s.volumes.begin() + it.row);
        m_doc->edit(s, tr("Delete volume %1").arg(QString::fromStdString(name)));
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
    // The question about the open scene before the chooser: the answer may be Cancel, and then no file is asked for.
    if (!maybeSave()) return;
    const QString path = m_chooseOpen ? m_chooseOpen(lastFolder(QStringLiteral("scenes"))) : QString();
    if (!path.isEmpty()) loadFile(path);
}

bool MainWindow::saveAsDialog()
{
    const QString folder = lastFolder(QStringLiteral("scenes"));
    const QString suggested = !m_doc->filePath().isEmpty() ? m_doc->filePath()
                              : folder.isEmpty()           ? tr("forest.sylva.json")
                                                           : QDir(folder).filePath(tr("forest.sylva.json"));
    QString path = QFileDialog::getSaveFileName(this, tr("Save Scene As"), suggested, tr(kSceneFilter));
    return !path.isEmpty() && saveFile(path);
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
    m_autosave->removeRecoveryFile();   // a clean close: nothing to recover
    saveLayout();
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
        else m_importer->importMesh(path);
    }
    event->acceptProposedAction();
}

} // namespace sylva
