// Render > Render Image (F12): the final picture of the scene in its own window, at the scene's render
// size and samples (editable there: one undo step, saved with the scene), shown while its passes add
// samples, with a progress bar, a sample counter and Save (the export's writer, writeRenderFilm).
#pragma once

#include <array>

#include <QImage>
#include <QPointer>
#include <QWidget>

#include "core/render/render_cpu.h"
#include "core/scene/scene.h"

class QLabel;
class QProgressBar;
class QPushButton;
class QSpinBox;

namespace sylva {

class ExportController;
class Job;
class SceneDocument;

class RenderWindow : public QWidget {
    Q_OBJECT

public:
    RenderWindow(SceneDocument* doc, ExportController* exporter, QWidget* parent = nullptr);
    ~RenderWindow() override;   // cancels the render and waits for its job

    // Starts rendering the document's scene (the size and samples of the boxes first written into it);
    // the job, or null when it could not start. A render in progress is cancelled first.
    Job* render();
    void cancel();
    bool isRendering() const { return !m_job.isNull(); }

    // The picture shown (tone-mapped sRGB, the render size), and how many samples per pixel it has of how many.
    QImage image() const { return m_image; }
    int samples() const { return m_samples; }
    int targetSamples() const { return m_target; }
    // Writes the shown render (a cancelled one with the samples it has) with the export's writer (PNG/TIFF
    // tone-mapped, EXR linear, by the extension); false (and an error under the picture) when there is
    // none or it cannot be written.
    bool saveImage(const QString& path);
    // Save...: a file chooser, then saveImage.
    void saveDialog();

    QSpinBox* widthBox() const { return m_width; }
    QSpinBox* heightBox() const { return m_height; }
    QSpinBox* samplesBox() const { return m_spp; }
    QProgressBar* progressBar() const { return m_progress; }
    QLabel* sampleCounter() const { return m_counter; }

Q_SIGNALS:
    // A pass was shown: the picture now has `samples` of `target` samples per pixel.
    void passShown(int samples, int target);
    // The render ended (ok: every sample traced).
    void renderEnded(bool ok);

private:
    void showPass(const QImage& image, const Film& film, int samples);
    void syncFromScene();
    void setBusy(bool busy);

    SceneDocument* m_doc;
    ExportController* m_exporter;
    QPointer<Job> m_job;
    Scene m_scene;    // what the render shows
    Film m_film;      // its film so far, the samples shown (what Save writes)
    QImage m_image;
    int m_samples = 0, m_target = 0;
    std::array<int, 3> m_synced{0, 0, 0};   // the scene's width, height and spp the boxes last showed

    QSpinBox* m_width;
    QSpinBox* m_height;
    QSpinBox* m_spp;
    QPushButton* m_renderButton;
    QPushButton* m_cancelButton;
    QPushButton* m_saveButton;
    QProgressBar* m_progress;
    QLabel* m_counter;
    QLabel* m_picture;
    QLabel* m_message;
};

} // namespace sylva
