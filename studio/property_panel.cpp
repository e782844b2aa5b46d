// PropertyPanel: one page per item kind; widgets refresh under QSignalBlocker when the scene changes.
#include "studio/property_panel.h"

#include <cmath>

#include <QCheckBox>
#include <QComboBox>
#include <QDateTime>
#include <QDial>
#include <QDoubleSpinBox>
#include <QFileInfo>
#include <QFormLayout>
#include <QHBoxLayout>
#include <QLabel>
#include <QLineEdit>
#include <QSignalBlocker>
#include <QSpinBox>
#include <QStackedWidget>
#include <QVBoxLayout>

#include "core/lb/lb_params.h"
#include "studio/camera_nav.h"
#include "studio/scene_item_pages.h"

#include "studio/form_widgets.h"
#include "studio/param_widgets.h"
#include "studio/words.h"

namespace sylva {
using namespace widgets;
namespace {

const char* kAxis[3] = {"x", "y", "z"};


} // namespace

PropertyPanel::PropertyPanel(SceneDocument* doc, QWidget* parent) : QWidget(parent), m_doc(doc)
{
    m_stack = new QStackedWidget(this);
    auto* layout = new QVBoxLayout(this);
    layout->setContentsMargins(4, 4, 4, 4);
    layout->addWidget(m_stack);
    m_stack->addWidget(m_emptyPage = buildEmptyPage());
    m_stack->addWidget(m_instancePage = buildInstancePage());
    m_stack->addWidget(m_speciesPage = buildSpeciesPage());
    m_stack->addWidget(m_sunPage = buildSunPage());
    m_stack->addWidget(m_cameraPage = buildCameraPage());
    m_stack->addWidget(m_groundPage = buildGroundPage());
    m_stack->addWidget(m_itemPages = new SceneItemPages(
                           doc, [this](QObject* editor, const QString& text, const std::function<void(Scene&)>& change) {
                               apply(editor, text, change);
                           }));
    applyToolTips(this);   // the artists' words for every control (studio/words.cpp)
    connect(doc, &SceneDocument::changed, this, [this] { refresh(); });
    showItem({});
}


void PropertyPanel::apply(QObject* editor, const QString& text, const std::function<void(Scene&)>& change)
{
    Scene s = m_doc->scene();
    change(s);
    m_doc->edit(s, text, m_merger.keyFor(editor));
}

QWidget* PropertyPanel::buildEmptyPage()
{
    auto* l = new QLabel(tr("Select an item in the outliner."));
    l->setAlignment(Qt::AlignTop | Qt::AlignLeft);
    l->setWordWrap(true);
    return l;
}

QWidget* PropertyPanel::buildInstancePage()
{
    auto* page = new QWidget;
    auto* form = new QFormLayout(page);
    m_instSpecies = new QComboBox;
    m_instSpecies->setObjectName("instance.species");
    form->addRow(tr("Species"), m_instSpecies);
    connect(m_instSpecies, &QComboBox::currentIndexChanged, this, [this](int idx) {
        if (idx < 0) return;
        const int i = m_item.row;
        apply(m_instSpecies, tr("Change instance species"), [&](Scene& s) { s.instances.at(size_t(i)).species = uint32_t(idx); });
    });
    for (int a = 0; a < 3; ++a) {
        m_instPos[size_t(a)] = spin(QStringLiteral("instance.position.%1").arg(kAxis[a]), -1e7, 1e7, 3, 0.1);
        m_instRot[size_t(a)] = spin(QStringLiteral("instance.rotation.%1").arg(kAxis[a]), -360.0, 360.0, 2, 5.0);
        m_instRot[size_t(a)]->setWrapping(true);
        connect(m_instPos[size_t(a)], &QDoubleSpinBox::valueChanged, this, [this, a](double v) {
            const int i = m_item.row;
            apply(m_instPos[size_t(a)], tr("Move instance"), [&](Scene& s) { s.instances.at(size_t(i)).position[a] = v; });
        });
        connect(m_instRot[size_t(a)], &QDoubleSpinBox::valueChanged, this, [this, a](double v) {
            const int i = m_item.row;
            apply(m_instRot[size_t(a)], tr("Rotate instance"),
                  [&](Scene& s) { s.instances.at(size_t(i)).rotationDeg[a] = float(v); });
        });
    }
    form->addRow(tr("Position (m)"), row({m_instPos[0], m_instPos[1], m_instPos[2]}));
    form->addRow(tr("Rotation (deg)"), row({m_instRot[0], m_instRot[1], m_instRot[2]}));
    m_instScale = sceneSpin("instances[i].scale", "instance.scale", 3, 0.05);
    connect(m_instScale, &QDoubleSpinBox::valueChanged, this, [this](double v) {
        const int i = m_item.row;
        apply(m_instScale, tr("Scale instance"), [&](Scene& s) { s.instances.at(size_t(i)).scale = float(v); });
    });
    form->addRow(tr("Scale"), m_instScale);
    return page;
}

QWidget* PropertyPanel::buildSpeciesPage()
{
    auto* page = new QWidget;
    auto* form = new QFormLayout(page);
    m_speciesTitle = new QLabel;
    m_speciesSource = new QLabel;
    m_speciesSource->setWordWrap(true);
    m_speciesSource->setTextInteractionFlags(Qt::TextSelectableByMouse);
    m_speciesName = new QLineEdit;
    m_speciesName->setObjectName("species.name");
    connect(m_speciesName, &QLineEdit::editingFinished, this, [this] {
        const std::string name = m_speciesName->text().trimmed().toStdString();
        const int i = m_item.row;
        const Scene& cur = m_doc->scene();
        if (i < 0 || size_t(i) >= cur.species.size()) return;
        bool taken = name.empty();
        for (size_t k = 0; k < cur.species.size(); ++k) taken = taken || (int(k) != i && cur.species[k].name == name);
        if (taken) {
            m_speciesName->setText(QString::fromStdString(cur.species[size_t(i)].name));   // names are unique and non-empty
            return;
        }
        apply(m_speciesName, tr("Rename species"), [&](Scene& s) { s.species.at(size_t(i)).name = name; });
    });
    m_speciesPreset = new QComboBox;
    m_speciesPreset->setObjectName("species.preset");
    for (const lb::Preset& p : lb::presets()) m_speciesPreset->addItem(QString::fromStdString(p.name));
    connect(m_speciesPreset, &QComboBox::currentTextChanged, this, [this](const QString& name) {
        const lb::Preset* preset = lb::findPreset(name.toStdString());
        const int i = m_item.row;
        if (!preset || i < 0) return;
        apply(m_speciesPreset, tr("Change light transport preset"), [&](Scene& s) {
            SpeciesDesc& sp = s.species.at(size_t(i));
            // A preset sets the optics; solve settings the user chose stay.
            const lb::LbParams old = sp.lighting;
            sp.preset = preset->name;
            sp.lighting = lb::paramsFromPreset(*preset);
            sp.lighting.steps = old.steps;
            sp.lighting.tolerance = old.tolerance;
            sp.lighting.storage = old.storage;
        });
    });
    m_speciesGrid = paramIntSpin(kSpeciesGrid, "species.grid", int(kSpeciesGrid.def[0]));   // the scene file's range
    m_speciesGrid->setKeyboardTracking(false);
    connect(m_speciesGrid, &QSpinBox::valueChanged, this, [this](int v) {
        const int i = m_item.row;
        apply(m_speciesGrid, tr("Change lighting grid"), [&](Scene& s) { s.species.at(size_t(i)).grid = v; });
    });
    form->addRow(m_speciesTitle);
    form->addRow(tr("Name"), m_speciesName);
    form->addRow(tr("Source"), m_speciesSource);
    form->addRow(tr("Light transport preset"), m_speciesPreset);
    form->addRow(tr("Lighting detail"), m_speciesGrid);
    return page;
}

QWidget* PropertyPanel::buildSunPage()
{
    auto* page = new QWidget;
    auto* form = new QFormLayout(page);
    m_sunElevation = sceneSpin("sun.elevation", "sun.elevation", 1, 1.0);
    m_sunAzimuth = spin("sun.azimuth", 0.0, 360.0, 1, 1.0);
    m_sunAzimuth->setWrapping(true);
    m_sunDial = new CompassDial;
    m_sunDial->setObjectName("sun.azimuthDial");
    m_sunTemperature = sceneSpin("sun.temperature", "sun.temperature", 0, 100.0);
    m_sunIntensity = sceneSpin("sun.intensity", "sun.intensity", 3, 0.1);
    auto setAngles = [this](QObject* editor, double elevation, double azimuth) {
        apply(editor, tr("Move sun"), [&](Scene& s) {
            s.sun.place.reset();   // by direction now (the sky panel sets the sun by date and place)
            s.sun.direction = sunDirection(elevation, azimuth);
        });
    };
    connect(m_sunElevation, &QDoubleSpinBox::valueChanged, this,
            [this, setAngles](double v) { setAngles(m_sunElevation, v, m_sunAzimuth->value()); });
    connect(m_sunAzimuth, &QDoubleSpinBox::valueChanged, this,
            [this, setAngles](double v) { setAngles(m_sunAzimuth, m_sunElevation->value(), v); });
    // The compass dial's value is the azimuth (0 south at the bottom, 90 east at the right: a map, north up).
    connect(m_sunDial, &QDial::valueChanged, this,
            [this, setAngles](int v) { setAngles(m_sunDial, m_sunElevation->value(), double(v)); });
    connect(m_sunTemperature, &QDoubleSpinBox::valueChanged, this, [this](double v) {
        apply(m_sunTemperature, tr("Change sun temperature"), [&](Scene& s) { s.sun.temperature = v; });
    });
    connect(m_sunIntensity, &QDoubleSpinBox::valueChanged, this, [this](double v) {
        apply(m_sunIntensity, tr("Change sun intensity"), [&](Scene& s) { s.sun.intensity = float(v); });
    });
    form->addRow(tr("Elevation (deg)"), m_sunElevation);
    form->addRow(tr("Azimuth (deg)"), row({m_sunDial, m_sunAzimuth}));
    form->addRow(tr("Temperature (K)"), m_sunTemperature);
    form->addRow(tr("Intensity"), m_sunIntensity);
    return page;
}

QWidget* PropertyPanel::buildCameraPage()
{
    auto* page = new QWidget;
    auto* form = new QFormLayout(page);
    for (int a = 0; a < 3; ++a) {
        m_camPos[size_t(a)] = spin(QStringLiteral("camera.position.%1").arg(kAxis[a]), -1e7, 1e7, 3, 0.5);
        m_camTarget[size_t(a)] = spin(QStringLiteral("camera.target.%1").arg(kAxis[a]), -1e7, 1e7, 3, 0.5);
        // A camera the scene file refuses (the eye on its target, the view straight along up) is not applied: the
        // box shows the scene's value again.
        auto moveCamera = [this, a](QDoubleSpinBox* box, const QString& text, bool target, double v) {
            const CameraDesc& now = m_doc->scene().camera;
            CameraDesc c = now;
            (target ? c.target : c.position)[a] = v;
            if (!cameraUsable(c)) {
                setValue(box, (target ? now.target : now.position)[a]);
                return;
            }
            apply(box, text, [&](Scene& s) { s.camera = c; });
        };
        connect(m_camPos[size_t(a)], &QDoubleSpinBox::valueChanged, this,
                [this, a, moveCamera](double v) { moveCamera(m_camPos[size_t(a)], tr("Move camera"), false, v); });
        connect(m_camTarget[size_t(a)], &QDoubleSpinBox::valueChanged, this,
                [this, a, moveCamera](double v) { moveCamera(m_camTarget[size_t(a)], tr("Aim camera"), true, v); });
    }
    m_camFov = sceneSpin("camera.fov", "camera.fov", 1, 1.0);
    connect(m_camFov, &QDoubleSpinBox::valueChanged, this, [this](double v) {
        apply(m_camFov, tr("Change field of view"), [&](Scene& s) { s.camera.fovY = float(v); });
    });
    form->addRow(tr("Position (m)"), row({m_camPos[0], m_camPos[1], m_camPos[2]}));
    form->addRow(tr("Target (m)"), row({m_camTarget[0], m_camTarget[1], m_camTarget[2]}));
    form->addRow(tr("Field of view (deg)"), m_camFov);
    return page;
}

QWidget* PropertyPanel::buildGroundPage()
{
    auto* page = new QWidget;
    auto* form = new QFormLayout(page);
    m_groundEnabled = new QCheckBox(tr("Ground plane"));
    m_groundEnabled->setObjectName("ground.enabled");
    connect(m_groundEnabled, &QCheckBox::toggled, this, [this](bool on) {
        apply(m_groundEnabled, on ? tr("Show ground") : tr("Hide ground"), [&](Scene& s) { s.ground.enabled = on; });
    });
    m_groundHeight = spin("ground.height", -1e5, 1e5, 3, 0.1);
    connect(m_groundHeight, &QDoubleSpinBox::valueChanged, this, [this](double v) {
        apply(m_groundHeight, tr("Move ground"), [&](Scene& s) { s.ground.height = v; });
    });
    form->addRow(m_groundEnabled);
    form->addRow(tr("Height (m)"), m_groundHeight);
    return page;
}

void PropertyPanel::showItem(const OutlinerItem& item)
{
    if (!(item == m_item)) m_merger.clear();   // a new item starts new undo steps
    m_item = item;
    refresh();
}

void PropertyPanel::refresh()
{
    const Scene& s = m_doc->scene();
    using K = OutlinerItem::Kind;
    if ((m_item.kind == K::Instance && (m_item.row < 0 || size_t(m_item.row) >= s.instances.size())) ||
        (m_item.kind == K::Species && (m_item.row < 0 || size_t(m_item.row) >= s.species.size())))
        m_item = {};
    switch (m_item.kind) {
    case K::Instance: {
        const InstanceDesc& in = s.instances[size_t(m_item.row)];
        {
            const QSignalBlocker block(m_instSpecies);
            m_instSpecies->clear();
            for (const SpeciesDesc& sp : s.species) m_instSpecies->addItem(QString::fromStdString(sp.name));
            m_instSpecies->setCurrentIndex(int(in.species));
        }
        for (int a = 0; a < 3; ++a) {
            setValue(m_instPos[size_t(a)], in.position[a]);
            setValue(m_instRot[size_t(a)], double(in.rotationDeg[a]));
        }
        setValue(m_instScale, double(in.scale));
        m_stack->setCurrentWidget(m_instancePage);
        break;
    }
    case K::Species: {
        const SpeciesDesc& sp = s.species[size_t(m_item.row)];
        m_speciesTitle->setText(QStringLiteral("<b>%1</b>").arg(QString::fromStdString(sp.name).toHtmlEscaped()));
        if (!m_speciesName->hasFocus()) m_speciesName->setText(QString::fromStdString(sp.name));
        m_speciesSource->setText(sp.grow ? tr("grown: %1, seed %2, %3 triangles")
                                               .arg(QString::fromStdString(sp.grow->species))
                                               .arg(sp.grow->seed)
                                               .arg(sp.grow->triangles)
                                         : QString::fromStdString(sp.meshPath));
        {
            const QSignalBlocker b1(m_speciesPreset), b2(m_speciesGrid);
            m_speciesPreset->setCurrentText(QString::fromStdString(sp.preset));
            m_speciesGrid->setValue(sp.grid);
        }
        m_stack->setCurrentWidget(m_speciesPage);
        break;
    }
    case K::Sun: {
        double el = 0.0, az = 0.0;
        sunAngles(s.sun.direction, &el, &az);
        setValue(m_sunElevation, el);
        setValue(m_sunAzimuth, az);
        {
            const QSignalBlocker block(m_sunDial);
            m_sunDial->setValue(int(std::lround(az)) % 360);
        }
        setValue(m_sunTemperature, s.sun.temperature);
        setValue(m_sunIntensity, double(s.sun.intensity));
        m_stack->setCurrentWidget(m_sunPage);
        break;
    }
    case K::Camera:
        for (int a = 0; a < 3; ++a) {
            setValue(m_camPos[size_t(a)], s.camera.position[a]);
            setValue(m_camTarget[size_t(a)], s.camera.target[a]);
        }
        setValue(m_camFov, double(s.camera.fovY));
        m_stack->setCurrentWidget(m_cameraPage);
        break;
    case K::Ground: {
        const QSignalBlocker block(m_groundEnabled);
        m_groundEnabled->setChecked(s.ground.enabled);
        setValue(m_groundHeight, s.ground.height);
        m_stack->setCurrentWidget(m_groundPage);
        break;
    }
    case K::Terrain:
    case K::Tiles:
    case K::Tiling:
    case K::Density:
    case K::Volume:
        m_stack->setCurrentWidget(m_itemPages->showItem(m_item, s) ? static_cast<QWidget*>(m_itemPages) : m_emptyPage);
        break;
    default: m_stack->setCurrentWidget(m_emptyPage); break;
    }
}

} // namespace sylva
