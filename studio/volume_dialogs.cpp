// VolumeTools: the cloud generator's form and the smoke simulation's job, each ending in one undoable edit.
#include "studio/volume_dialogs.h"

#include <cmath>
#include <memory>

#include <QDialogButtonBox>
#include <QDir>
#include <QDoubleSpinBox>
#include <QFileInfo>
#include <QFormLayout>
#include <QHBoxLayout>
#include <QLineEdit>
#include <QSpinBox>
#include <QStandardPaths>

#include "core/base/error.h"
#include "core/base/progress.h"
#include "pipeline/io/grid_file.h"
#include "pipeline/scene/scene_volumes.h"
#include "studio/job_manager.h"
#include "studio/param_widgets.h"
#include "studio/scene_document.h"

namespace sylva {
namespace {

QDoubleSpinBox* dspin(const char* name, double lo, double hi, int decimals, double value)
{
    auto* s = new QDoubleSpinBox;
    s->setObjectName(QString::fromLatin1(name));
    s->setRange(lo, hi);
    s->setDecimals(decimals);
    s->setValue(value);
    return s;
}

QWidget* triple(QWidget* a, QWidget* b, QWidget* c)
{
    auto* w = new QWidget;
    auto* l = new QHBoxLayout(w);
    l->setContentsMargins(0, 0, 0, 0);
    l->addWidget(a);
    l->addWidget(b);
    l->addWidget(c);
    return w;
}

QDialogButtonBox* okCancel(QDialog* d)
{
    auto* buttons = new QDialogButtonBox(QDialogButtonBox::Ok | QDialogButtonBox::Cancel);
    QObject::connect(buttons, &QDialogButtonBox::accepted, d, &QDialog::accept);
    QObject::connect(buttons, &QDialogButtonBox::rejected, d, &QDialog::reject);
    return buttons;
}

// A scene volume over the grid file `path` (read back as the scene reader does: loadSceneVolumes).
VolumeDesc loadedVolume(const QString& name, const QString& path, const std::string& preset, const glm::dvec3& position,
                        const QString& temperaturePath = {})
{
    Scene one;
    VolumeDesc v = defaultVolume();
    v.name = name.toStdString();
    v.grid = QFileInfo(path).absoluteFilePath().toStdString();
    if (!temperaturePath.isEmpty()) v.temperature = QFileInfo(temperaturePath).absoluteFilePath().toStdString();
    v.preset = preset;
    lb::LbParams optics;
    if (!volumePreset(preset, &optics)) throw Error("volume preset '" + preset + "' is unknown");
    optics.stepsPerEdge = v.lighting.stepsPerEdge;
    optics.storage = v.lighting.storage;
    v.lighting = optics;
    VolumePlacement p;
    p.position = position;
    v.instances.push_back(p);
    one.volumes.push_back(v);
    loadSceneVolumes(one);
    return one.volumes[0];
}

} // namespace

// ---- forms ----

CloudDialog::CloudDialog(const volume::PyroclasticParams& p, const QString& name, QWidget* parent) : QDialog(parent)
{
    setWindowTitle(tr("Add Cloud"));
    setObjectName("cloudDialog");
    auto* form = new QFormLayout(this);
    m_name = new QLineEdit(name);
    m_name->setObjectName("cloud.name");
    m_radius = paramSpin(volume::kCloudRadius, "cloud.radius", 3, p.radius);
    m_amplitude = paramSpin(volume::kCloudAmplitude, "cloud.amplitude", 3, p.amplitude);
    m_frequency = paramSpin(volume::kCloudFrequency, "cloud.frequency", 4, p.frequency);
    m_octaves = paramIntSpin(volume::kCloudOctaves, "cloud.octaves", p.octaves);
    m_resolution = paramIntSpin(volume::kCloudResolution, "cloud.resolution", p.resolution);
    m_density = paramSpin(volume::kCloudDensity, "cloud.density", 3, p.density);
    m_seed = paramSeedEdit(volume::kCloudSeed, "cloud.seed", p.seed);
    for (int a = 0; a < 3; ++a) m_centre[a] = paramSpin(volume::kCloudCentre, QStringLiteral("cloud.centre.") + QChar("xyz"[a]), 2, p.centre[a]);
    form->addRow(tr("Name"), m_name);
    form->addRow(tr("Radius (m)"), m_radius);
    form->addRow(tr("Amplitude (m)"), m_amplitude);
    form->addRow(tr("Frequency (1/m)"), m_frequency);
    form->addRow(tr("Octaves"), m_octaves);
    form->addRow(tr("Resolution (nodes)"), m_resolution);
    form->addRow(tr("Density"), m_density);
    form->addRow(tr("Seed"), m_seed);
    form->addRow(tr("Centre (m)"), triple(m_centre[0], m_centre[1], m_centre[2]));
    form->addRow(okCancel(this));
}

volume::PyroclasticParams CloudDialog::params() const
{
    volume::PyroclasticParams p;
    p.radius = float(m_radius->value());
    p.amplitude = float(m_amplitude->value());
    p.frequency = float(m_frequency->value());
    p.octaves = m_octaves->value();
    p.resolution = m_resolution->value();
    p.density = float(m_density->value());
    p.seed = paramSeed(m_seed);
    p.centre = glm::vec3(float(m_centre[0]->value()), float(m_centre[1]->value()), float(m_centre[2]->value()));
    return p;
}

void CloudDialog::setParams(const volume::PyroclasticParams& p)
{
    m_radius->setValue(p.radius);
    m_amplitude->setValue(p.amplitude);
    m_frequency->setValue(p.frequency);
    m_octaves->setValue(p.octaves);
    m_resolution->setValue(p.resolution);
    m_density->setValue(p.density);
    setParamSeed(m_seed, p.seed);
    for (int a = 0; a < 3; ++a) m_centre[a]->setValue(p.centre[a]);
}

QString CloudDialog::name() const { return m_name->text().trimmed(); }

SmokeDialog::SmokeDialog(const SmokeSpec& s, QWidget* parent) : QDialog(parent), m_initial(s)
{
    setWindowTitle(tr("Simulate Smoke"));
    setObjectName("smokeDialog");
    auto* form = new QFormLayout(this);
    m_name = new QLineEdit(s.name);
    m_name->setObjectName("smoke.name");
    const char* cellNames[3] = {"smoke.cells.x", "smoke.cells.y", "smoke.cells.z"};
    const char* posNames[3] = {"smoke.position.x", "smoke.position.y", "smoke.position.z"};
    for (int a = 0; a < 3; ++a) {
        m_cells[a] = paramIntSpin(volume::kSmokeCells, cellNames[a], s.cells[a]);
        m_position[a] = dspin(posNames[a], -kWidgetLimit, kWidgetLimit, 2, s.position[a]);
    }
    m_width = paramSpin(volume::kSmokeWidth, "smoke.width", 3, s.width);
    m_steps = paramIntSpin(volume::kSmokeSteps, "smoke.steps", s.steps);
    m_seed = paramSeedEdit(volume::kSmokeSeed, "smoke.seed", s.seed);
    m_kelvin = paramSpin(kSmokeSourceKelvin, "smoke.kelvin", 0, double(s.sourceKelvin));
    m_kelvin->setSpecialValueText(tr("cold (no emission)"));
    form->addRow(tr("Name"), m_name);
    form->addRow(tr("Cells"), triple(m_cells[0], m_cells[1], m_cells[2]));
    form->addRow(tr("Width (m)"), m_width);
    form->addRow(tr("Steps (%1 s each)").arg(QString::fromStdString(paramNumber(volume::kSmokeDt.def[0]))), m_steps);
    form->addRow(tr("Seed"), m_seed);
    form->addRow(tr("Source temperature (K)"), m_kelvin);
    form->addRow(tr("Floor centre (m)"), triple(m_position[0], m_position[1], m_position[2]));
    form->addRow(okCancel(this));
}

SmokeSpec SmokeDialog::spec() const
{
    SmokeSpec s = m_initial;
    s.name = m_name->text().trimmed();
    for (int a = 0; a < 3; ++a) {
        s.cells[a] = m_cells[a]->value();
        s.position[a] = m_position[a]->value();
    }
    s.width = float(m_width->value());
    s.steps = m_steps->value();
    s.seed = paramSeed(m_seed);
    s.sourceKelvin = float(m_kelvin->value());
    return s;
}

// ---- the tool ----

VolumeTools::VolumeTools(SceneDocument* doc, JobManager* jobs, QWidget* window, QObject* parent)
    : StudioController(parent), m_doc(doc), m_jobs(jobs), m_window(window)
{
}

volume::PyroclasticParams VolumeTools::defaultCloud() const
{
    const CameraDesc& c = m_doc->scene().camera;
    const double dist = glm::length(c.target - c.position);
    volume::PyroclasticParams p;
    p.radius = float(std::max(0.5, 0.1 * dist));
    p.amplitude = 0.5f * p.radius;
    p.frequency = 1.5f / p.radius;   // the same look at any size
    p.resolution = 64;
    p.centre = glm::vec3(c.target);
    return p;
}

SmokeSpec VolumeTools::defaultSmoke() const
{
    const Scene& s = m_doc->scene();
    const double dist = glm::length(s.camera.target - s.camera.position);
    SmokeSpec spec;
    spec.width = float(std::max(0.5, 0.2 * dist));
    spec.position = glm::dvec3(s.camera.target.x, s.ground.enabled ? s.ground.height : s.camera.target.y - 0.5 * spec.width, s.camera.target.z);
    spec.name = uniqueName(QStringLiteral("smoke"));
    return spec;
}

QString VolumeTools::uniqueName(const QString& base) const
{
    const Scene& s = m_doc->scene();
    auto taken = [&](const QString& n) {
        for (const VolumeDesc& v : s.volumes)
            if (QString::fromStdString(v.name) == n) return true;
        return false;
    };
    if (!taken(base)) return base;
    for (int i = 2;; ++i)
        if (!taken(QStringLiteral("%1 %2").arg(base).arg(i))) return QStringLiteral("%1 %2").arg(base).arg(i);
}

QString VolumeTools::gridPathFor(const QString& name) const
{
    const QString dir = m_doc->filePath().isEmpty()
                            ? QStandardPaths::writableLocation(QStandardPaths::AppLocalDataLocation) + QStringLiteral("/volumes")
                            : QFileInfo(m_doc->filePath()).absolutePath();
    QDir().mkpath(dir);
    QString stem;
    for (QChar ch : name) stem += (ch.isLetterOrNumber() || ch == QLatin1Char('-') || ch == QLatin1Char('_')) ? ch : QLatin1Char('_');
    if (stem.isEmpty()) stem = QStringLiteral("volume");
    QString path = dir + QLatin1Char('/') + stem + QStringLiteral(".npy");
    for (int i = 2; QFileInfo::exists(path); ++i) path = dir + QLatin1Char('/') + stem + QStringLiteral("_%1.npy").arg(i);
    return path;
}

bool VolumeTools::addVolume(VolumeDesc v, const QString& undoText)
{
    Scene s = m_doc->scene();
    s.volumes.push_back(std::move(v));
    m_doc->edit(s, undoText);
    Q_EMIT volumeAdded(int(s.volumes.size()) - 1);
    return true;
}

bool VolumeTools::addCloud(const volume::PyroclasticParams& params, const QString& nameIn)
{
    const QString name = uniqueName(nameIn.isEmpty() ? QStringLiteral("cloud") : nameIn);
    try {
        volume::validatePyroclastic(params);
        volume::PyroclasticParams local = params;
        local.centre = glm::vec3(0.0f);   // the grid's frame centred on the cloud; the placement carries the centre
        const DensityGrid grid = volume::makePyroclasticCloud(local);
        const QString path = gridPathFor(name);
        writeDensityFile(path.toStdString(), grid);
        VolumeDesc v = loadedVolume(name, path, "cloud", glm::dvec3(params.centre));
        log(tr("cloud %1: %2^3 nodes, radius %3 m, amplitude %4 m, seed %5 -> %6")
                .arg(name)
                .arg(params.resolution)
                .arg(double(params.radius))
                .arg(double(params.amplitude))
                .arg(params.seed)
                .arg(path));
        return addVolume(std::move(v), tr("Add cloud %1").arg(name));
    } catch (const std::exception& e) {
        fail(tr("Add cloud failed"), QString::fromStdString(e.what()));
        return false;
    }
}

void VolumeTools::cloudDialog()
{
    CloudDialog d(defaultCloud(), uniqueName(QStringLiteral("cloud")), m_window);
    if (d.exec() == QDialog::Accepted) addCloud(d.params(), d.name());
}

Job* VolumeTools::simulateSmoke(const SmokeSpec& spec)
{
    volume::SmokeSettings settings;
    settings.cells = spec.cells;
    settings.seed = spec.seed;
    try {
        checkParam(volume::kSmokeSteps, spec.steps, "smoke");
        checkParam(kSmokeSourceKelvin, spec.sourceKelvin, "smoke", "source temperature");
        volume::setSmokeDomain(settings, spec.width);   // checks the width
        const bool hot = spec.sourceKelvin > 0.0f;
        if (hot) settings.buoyancyTemperature /= spec.sourceKelvin;   // per kelvin: the same rise as unit temperature
        settings.sources.push_back({volume::defaultSmokeSource(settings, spec.width), 1.0f, hot ? spec.sourceKelvin : 1.0f, glm::vec3(0.0f)});
        volume::validateSmoke(settings);
    } catch (const std::exception& e) {
        fail(tr("Smoke failed"), QString::fromStdString(e.what()));
        return nullptr;
    }
    const QString name = uniqueName(spec.name.isEmpty() ? QStringLiteral("smoke") : spec.name);
    auto result = std::make_shared<DensityGrid>();
    auto temperature = std::make_shared<DensityGrid>();
    const bool hot = spec.sourceKelvin > 0.0f;
    const int steps = spec.steps;
    const glm::dvec3 position = spec.position;
    return m_jobs->start(
        tr("Simulate smoke"),
        [settings, steps, result, temperature, hot](Job&, Progress& progress) {
            volume::SmokeSim sim(settings);
            for (int n = 1; n <= steps; ++n) {
                sim.step(&progress);
                progress.report(double(n) / double(steps), "step " + std::to_string(n) + "/" + std::to_string(steps));
            }
            *result = sim.densityGrid();
            if (hot) *temperature = sim.temperatureGrid();
        },
        [this, name, position, result, temperature, hot, steps, spec](Job* job) {
            if (job->state() == Job::State::Cancelled) {
                log(tr("smoke %1 cancelled: nothing added").arg(name));
                return;
            }
            if (job->state() != Job::State::Succeeded) {
                fail(tr("Smoke failed"), job->error());
                return;
            }
            try {
                const QString path = gridPathFor(name);
                writeDensityFile(path.toStdString(), *result);
                QString temperaturePath;
                if (hot) {
                    temperaturePath = gridPathFor(name + QStringLiteral("_temperature"));
                    writeDensityFile(temperaturePath.toStdString(), *temperature);
                }
                VolumeDesc v = loadedVolume(name, path, "smoke", position, temperaturePath);
                log(tr("smoke %1: %2 x %3 x %4 cells, %5 steps in %6 s -> %7")
                        .arg(name)
                        .arg(spec.cells.x)
                        .arg(spec.cells.y)
                        .arg(spec.cells.z)
                        .arg(steps)
                        .arg(job->seconds(), 0, 'f', 2)
                        .arg(path));
                addVolume(std::move(v), tr("Add smoke %1").arg(name));
            } catch (const std::exception& e) {
                fail(tr("Smoke failed"), QString::fromStdString(e.what()));
            }
        });
}

void VolumeTools::smokeDialog()
{
    SmokeDialog d(defaultSmoke(), m_window);
    if (d.exec() == QDialog::Accepted) simulateSmoke(d.spec());
}

} // namespace sylva
