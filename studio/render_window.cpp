// RenderWindow: the render job of the export controller, its passes shown, Save through writeRenderFilm.
#include "studio/render_window.h"

#include <array>

#include <QFileDialog>
#include <QFileInfo>
#include <QFormLayout>
#include <QHBoxLayout>
#include <QLabel>
#include <QProgressBar>
#include <QPushButton>
#include <QScrollArea>
#include <QSpinBox>
#include <QVBoxLayout>

#include "pipeline/scene/scene_fields.h"
#include "pipeline/services/exports.h"
#include "studio/export_controller.h"
#include "studio/job_manager.h"
#include "studio/recent_files.h"
#include "studio/render_worker.h"
#include "studio/scene_document.h"
#include "studio/view_transform.h"

namespace sylva {

RenderWindow::RenderWindow(SceneDocument* doc, ExportController* exporter, QWidget* parent)
    : QWidget(parent, Qt::Window), m_doc(doc), m_exporter(exporter)
{
    setObjectName("renderWindow");
    setWindowTitle(tr("Render - Sylva Studio"));
    auto* top = new QHBoxLayout;
    auto* form = new QFormLayout;
    auto spin = [](const char* name, int lo, int hi, const QString& tip) {
        auto* b = new QSpinBox;
        b->setObjectName(QString::fromLatin1(name));
        b->setRange(lo, hi);
        b->setToolTip(tip);
        return b;
    };
    m_width = spin("renderWidth", 1, 16384, tr("Width of the rendered picture in pixels (saved with the scene)"));
    m_height = spin("renderHeight", 1, 16384, tr("Height of the rendered picture in pixels (saved with the scene)"));
    // The scene file's range (render.spp): the samples are saved with the scene, and the reader refuses more.
    m_spp = spin("renderSamples", 1, int(sceneFieldRange("render.spp").hi),
                 tr("Samples per pixel: more is smoother and slower (saved with the scene; the picture refines as they add up)"));
    auto* size = new QHBoxLayout;
    size->addWidget(m_width);
    size->addWidget(new QLabel(QStringLiteral("x")));
    size->addWidget(m_height);
    form->addRow(tr("Size"), size);
    form->addRow(tr("Samples"), m_spp);
    top->addLayout(form);
    m_renderButton = new QPushButton(tr("Render"));
    m_renderButton->setObjectName("renderButton");
    m_renderButton->setToolTip(tr("Render the scene from its camera at this size and samples (F12)"));
    m_cancelButton = new QPushButton(tr("Cancel"));
    m_cancelButton->setObjectName("renderCancel");
    m_cancelButton->setToolTip(tr("Stop the render; the picture keeps the samples it has"));
    m_saveButton = new QPushButton(tr("Save..."));
    m_saveButton->setObjectName("renderSave");
    m_saveButton->setToolTip(tr("Save the picture as shown (a cancelled render with the samples it has): PNG or TIFF "
                                "(8-bit) or EXR (linear, half float)"));
    top->addWidget(m_renderButton);
    top->addWidget(m_cancelButton);
    top->addWidget(m_saveButton);
    top->addStretch(1);

    m_progress = new QProgressBar;
    m_progress->setObjectName("renderProgress");
    m_progress->setRange(0, 1000);
    m_progress->setTextVisible(false);
    m_counter = new QLabel;
    m_counter->setObjectName("renderSampleCounter");
    auto* status = new QHBoxLayout;
    status->addWidget(m_progress, 1);
    status->addWidget(m_counter);

    m_picture = new QLabel;
    m_picture->setObjectName("renderPicture");
    m_picture->setAlignment(Qt::AlignCenter);
    auto* scroll = new QScrollArea;
    scroll->setWidget(m_picture);
    scroll->setWidgetResizable(true);
    scroll->setAlignment(Qt::AlignCenter);
    m_message = new QLabel;
    m_message->setObjectName("renderMessage");
    m_message->setStyleSheet(QStringLiteral("color: #c03030"));
    m_message->setWordWrap(true);

    auto* layout = new QVBoxLayout(this);
    layout->addLayout(top);
    layout->addLayout(status);
    layout->addWidget(scroll, 1);
    layout->addWidget(m_message);
    resize(960, 620);

    connect(m_renderButton, &QPushButton::clicked, this, [this] { render(); });
    connect(m_cancelButton, &QPushButton::clicked, this, &RenderWindow::cancel);
    connect(m_saveButton, &QPushButton::clicked, this, &RenderWindow::saveDialog);
    connect(m_doc, &SceneDocument::changed, this, [this] { syncFromScene(); });
    syncFromScene();
    setBusy(false);
}

RenderWindow::~RenderWindow()
{
    // The job posts its passes to this window: it must have returned before the window goes.
    if (Job* job = m_job.data()) {
        job->cancel();
        job->waitForFinished();
    }
}

void RenderWindow::syncFromScene()
{
    // Only when the scene's size or samples changed (an undo, another file): other edits (a camera move)
    // leave what was typed in the boxes and not rendered yet.
    const RenderSettings& r = m_doc->scene().render;
    const std::array<int, 3> now{r.width, r.height, r.spp};
    if (now == m_synced) return;
    m_synced = now;
    for (auto [box, value] : {std::pair{m_width, r.width}, std::pair{m_height, r.height}, std::pair{m_spp, r.spp}}) {
        const QSignalBlocker block(box);
        box->setValue(value);
    }
}

void RenderWindow::setBusy(bool busy)
{
    m_cancelButton->setEnabled(busy);
    m_saveButton->setEnabled(!busy && m_film.width > 0);
}

Job* RenderWindow::render()
{
    cancel();
    m_message->clear();
    // The boxes are the scene's render settings: a change is one undo step, saved with the scene.
    Scene s = m_doc->scene();
    if (s.render.width != m_width->value() || s.render.height != m_height->value() || s.render.spp != m_spp->value()) {
        s.render.width = m_width->value();
        s.render.height = m_height->value();
        s.render.spp = m_spp->value();
        m_doc->edit(s, tr("Render size and samples"));
    }
    m_scene = m_doc->scene();
    m_film = Film{};
    m_samples = 0;
    m_target = m_scene.render.spp;
    m_progress->setValue(0);
    m_counter->setText(tr("Samples 0 / %1").arg(m_target));
    const Scene scene = m_scene;
    Job* job = m_exporter->renderImage(scene, [this, scene](const Film& film, int samples) {
        // On the job's thread: the picture as the export writes it (composeMode, the tone map), then to the window.
        const QImage image = scenePicture(film, scene);
        QMetaObject::invokeMethod(this, [this, image, film, samples]() { showPass(image, film, samples); }, Qt::QueuedConnection);
    });
    m_job = job;
    if (!job) {
        m_message->setText(tr("The render could not start (see the log)."));
        return nullptr;
    }
    setBusy(true);
    connect(job, &Job::progressChanged, this, [this](double f) { m_progress->setValue(int(f * 1000.0)); });
    connect(job, &Job::finished, this, [this](Job* j) {
        const bool ok = j->state() == Job::State::Succeeded;
        if (ok) m_progress->setValue(m_progress->maximum());
        if (j->state() == Job::State::Failed) m_message->setText(j->error());
        m_job = nullptr;
        setBusy(false);
        Q_EMIT renderEnded(ok);
    });
    return job;
}

void RenderWindow::cancel()
{
    if (Job* job = m_job.data()) job->cancel();
}

void RenderWindow::showPass(const QImage& image, const Film& film, int samples)
{
    m_image = image;
    if (film.width > 0) m_film = film;
    m_samples = samples;
    m_picture->setPixmap(QPixmap::fromImage(image));
    m_counter->setText(tr("Samples %1 / %2").arg(samples).arg(m_target));
    Q_EMIT passShown(samples, m_target);
}

bool RenderWindow::saveImage(const QString& path)
{
    if (m_film.width <= 0) {
        m_message->setText(tr("Nothing to save yet: render first."));
        return false;
    }
    try {
        writeRenderFilm(path.toStdString(), m_film, m_scene);
    } catch (const std::exception& e) {
        m_message->setText(QString::fromStdString(e.what()));
        return false;
    }
    m_message->clear();
    rememberFolder(QStringLiteral("renders"), path);
    return true;
}

void RenderWindow::saveDialog()
{
    QString folder = lastFolder(QStringLiteral("renders"));
    if (folder.isEmpty() && !m_doc->filePath().isEmpty()) folder = QFileInfo(m_doc->filePath()).absolutePath();
    const QString suggested = folder.isEmpty() ? tr("render.png") : folder + tr("/render.png");
    const QString path = QFileDialog::getSaveFileName(this, tr("Save Render"), suggested,
                                                      tr("PNG (*.png);;TIFF (*.tif *.tiff);;OpenEXR, linear (*.exr)"));
    if (!path.isEmpty()) saveImage(path);
}

} // namespace sylva
