// Volumes in the studio: Edit > Add Cloud (the pyroclastic generator's form, the same
// core/volume/pyroclastic code as `sylva volume cloud`) and Edit > Simulate Smoke (core/volume/smoke's
// simulation as a job with progress and cancel, `sylva simulate`'s domain and source); each adds one
// volume (its grid written beside the scene file, or in the studio's data folder) as one undo step.
#pragma once

#include <QDialog>
#include <QPointer>

#include "core/volume/pyroclastic.h"
#include "core/scene/volume.h"
#include "core/volume/smoke.h"
#include "studio/studio_controller.h"

class QDoubleSpinBox;
class QLineEdit;
class QSpinBox;

namespace sylva {

class Job;
class JobManager;
class SceneDocument;

// The pyroclastic parameters (core/volume/pyroclastic.h): radius, amplitude, noise frequency and octaves, resolution,
// density, seed, centre; and the volume's name.
class CloudDialog : public QDialog {
    Q_OBJECT

public:
    CloudDialog(const volume::PyroclasticParams& initial, const QString& name, QWidget* parent = nullptr);
    volume::PyroclasticParams params() const;
    QString name() const;
    void setParams(const volume::PyroclasticParams& p);

private:
    QLineEdit* m_name;
    QDoubleSpinBox *m_radius, *m_amplitude, *m_frequency, *m_density;
    QSpinBox *m_octaves, *m_resolution;
    QLineEdit* m_seed;
    QDoubleSpinBox* m_centre[3];
};

// Hot smoke's source temperature, a parameter of the studio's smoke job alone.
inline constexpr ParamSpec kSmokeSourceKelvin{.key = "source_kelvin", .metavar = "K", .lo = 0.0, .hi = 40000.0, .def = {0.0},
                                              .help = "hot smoke: the sources' temperature in kelvin, drawn as blackbody emission "
                                                      "(1000 K and up glow); 0 = cold"};

// What the smoke job simulates: cells, domain width (metres), steps, and where the domain's floor centre
// stands in the world. The ranges are core/volume/smoke.h's; the form starts smaller than `sylva simulate`'s
// defaults (a quarter of the cells, 40 steps) so that a first try takes seconds.
struct SmokeSpec {
    glm::ivec3 cells{32, 48, 32};
    float width = float(volume::kSmokeWidth.def[0]);
    int steps = 40;
    uint64_t seed = uint64_t(volume::kSmokeSeed.def[0]);
    glm::dvec3 position{0.0};
    QString name = QStringLiteral("smoke");
    // Hot smoke (> 0): the sources' temperature in kelvin. The job then also writes the temperature
    // grid (kelvin: blackbody emission, RENDERING.md) and the volume references it; the buoyancy per
    // kelvin is the default's per unit over this, so the plume rises as cold smoke of unit temperature.
    float sourceKelvin = float(kSmokeSourceKelvin.def[0]);
};

class SmokeDialog : public QDialog {
    Q_OBJECT

public:
    SmokeDialog(const SmokeSpec& initial, QWidget* parent = nullptr);
    SmokeSpec spec() const;

private:
    SmokeSpec m_initial;
    QLineEdit* m_name;
    QSpinBox *m_cells[3], *m_steps;
    QLineEdit* m_seed;
    QDoubleSpinBox *m_width, *m_kelvin;
    QDoubleSpinBox* m_position[3];
};

class VolumeTools : public StudioController {
    Q_OBJECT

public:
    VolumeTools(SceneDocument* doc, JobManager* jobs, QWidget* window, QObject* parent = nullptr);

    // Form defaults: a cloud at the camera's target a few metres across (a tenth of the view distance), a
    // smoke domain standing on the ground below the target.
    volume::PyroclasticParams defaultCloud() const;
    SmokeSpec defaultSmoke() const;
    // A volume name not yet in the scene: base, "base 2", ...
    QString uniqueName(const QString& base) const;
    // Where a new volume's grid goes: beside the scene file (NAME.npy), else the studio's data folder
    // (volumes/); never an existing file.
    QString gridPathFor(const QString& name) const;

    // Makes the cloud (centred on params.centre: the grid's own frame is centred on 0 and the placement
    // carries the centre), writes its grid and adds the volume as one undo step; false (and an error) on
    // bad parameters or an unwritable file, the scene unchanged.
    bool addCloud(const volume::PyroclasticParams& params, const QString& name);
    void cloudDialog();

    // Runs the simulation as a job ("Simulate smoke", progress per step, cancel between stages); when it
    // succeeds the last density frame is written and added as a volume (preset smoke) in one undo step;
    // cancelled or failed, nothing is written or changed. Null (and an error) for bad settings.
    Job* simulateSmoke(const SmokeSpec& spec);
    void smokeDialog();

Q_SIGNALS:
    void volumeAdded(int volume);

private:
    bool addVolume(VolumeDesc v, const QString& undoText);

    SceneDocument* m_doc;
    JobManager* m_jobs;
    QWidget* m_window;
};

} // namespace sylva
