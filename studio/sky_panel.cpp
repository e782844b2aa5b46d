// SkyPanel: the sky block and the sun of the scene as controls; each change one SceneDocument edit.
#include "studio/sky_panel.h"

#include <algorithm>
#include <cmath>

#include <QCheckBox>
#include <QComboBox>
#include <QDateEdit>
#include <QDateTime>
#include <QDial>
#include <QDoubleSpinBox>
#include <QFileDialog>
#include <QFileInfo>
#include <QFormLayout>
#include <QGroupBox>
#include <QHBoxLayout>
#include <QLabel>
#include <QLineEdit>
#include <QPushButton>
#include <QSignalBlocker>
#include <QSlider>
#include <QSpinBox>
#include <QStackedWidget>
#include <QTimeEdit>
#include <QVBoxLayout>

#include "core/base/error.h"
#include "core/sky/sun_position.h"
#include "studio/camera_nav.h"
#include "studio/recent_files.h"

#include "studio/form_widgets.h"
#include "studio/param_widgets.h"
#include "studio/words.h"

namespace sylva {
using namespace widgets;
namespace {


QFormLayout* form(QWidget* w)
{
    auto* f = new QFormLayout(w);
    f->setContentsMargins(0, 0, 0, 0);
    return f;
}

sky::SunPlace placeOf(const Scene& s) { return s.sun.place ? *s.sun.place : sky::SunPlace{}; }

// The key of exposure 0 EV: Reinhard's middle grey, the render's default key.
constexpr double kMiddleGrey = 0.18;

} // namespace

SkyPanel::SkyPanel(SceneDocument* doc, QWidget* parent) : QWidget(parent), m_doc(doc)
{
    m_chooseMap = [this] {
        const QString path = QFileDialog::getOpenFileName(this, tr("HDR Environment Map"), lastFolder(QStringLiteral("maps")),
                                                          tr("HDR maps (*.exr *.hdr);;All files (*)"));
        rememberFolder(QStringLiteral("maps"), path);
        return path;
    };
    auto* layout = new QVBoxLayout(this);
    layout->setContentsMargins(4, 4, 4, 4);

    // The sky.
    auto* skyBox = new QGroupBox(tr("Sky"));
    auto* skyForm = new QFormLayout(skyBox);
    m_kind = new QComboBox;
    m_kind->setObjectName("sky.kind");
    m_kind->addItem(tr("Colour backdrop (lights nothing)"), int(sky::SkyKind::Constant));
    m_kind->addItem(tr("Clear sky (follows the sun)"), int(sky::SkyKind::Preetham));
    m_kind->addItem(tr("Photographed sky (HDR map)"), int(sky::SkyKind::Map));
    m_kind->addItem(tr("Even sky light (lights the plants)"), int(sky::SkyKind::Uniform));
    m_kind->setItemData(0, tr("A plain colour behind the trees: it is seen, but lights nothing (the sun lights the scene)"), Qt::ToolTipRole);
    m_kind->setItemData(1, tr("A clear daytime sky computed from the sun's position and the haze: it lights the plants "
                              "and changes with the sun"), Qt::ToolTipRole);
    m_kind->setItemData(2, tr("A photographed sky (an HDR panorama): seen behind the trees, and its light lights the plants"),
                        Qt::ToolTipRole);
    m_kind->setItemData(3, tr("A sky of one colour that shines evenly from every direction: unlike the colour backdrop, it "
                              "lights the plants (an overcast day)"), Qt::ToolTipRole);
    skyForm->addRow(tr("Sky"), m_kind);
    connect(m_kind, &QComboBox::currentIndexChanged, this, [this](int idx) {
        const auto kind = sky::SkyKind(m_kind->itemData(idx).toInt());
        if (kind == sky::SkyKind::Map && m_doc->scene().skyModel.path.empty()) {
            chooseMap();   // a map sky needs its file first
            refresh();
            return;
        }
        apply(m_kind, tr("Change sky model"), [&](Scene& s) { s.skyModel.kind = kind; });
    });

    m_preethamRows = new QWidget;
    m_turbidity = sceneSpin("sky.turbidity", "sky.turbidity", 2, 0.25);
    connect(m_turbidity, &QDoubleSpinBox::valueChanged, this, [this](double v) {
        apply(m_turbidity, tr("Change turbidity"), [&](Scene& s) { s.skyModel.turbidity = v; });
    });
    form(m_preethamRows)->addRow(tr("Turbidity"), m_turbidity);
    skyForm->addRow(m_preethamRows);

    m_mapRows = new QWidget;
    QFormLayout* mapForm = form(m_mapRows);
    m_path = new QLineEdit;
    m_path->setObjectName("sky.path");
    m_path->setReadOnly(true);
    m_browse = new QPushButton(tr("Choose..."));
    m_browse->setObjectName("sky.choose");
    connect(m_browse, &QPushButton::clicked, this, [this] { chooseMap(); });
    mapForm->addRow(tr("Map file"), row({m_path, m_browse}));
    m_rotation = spin("sky.rotation", -360.0, 360.0, 1, 5.0);
    m_rotation->setWrapping(true);
    connect(m_rotation, &QDoubleSpinBox::valueChanged, this, [this](double v) {
        apply(m_rotation, tr("Rotate sky map"), [&](Scene& s) { s.skyModel.rotationDeg = float(v); });
    });
    mapForm->addRow(tr("Rotation (deg)"), m_rotation);
    m_intensity = sceneSpin("sky.intensity", "sky.intensity", 3, 0.1);
    connect(m_intensity, &QDoubleSpinBox::valueChanged, this, [this](double v) {
        apply(m_intensity, tr("Change sky map intensity"), [&](Scene& s) { s.skyModel.intensity = float(v); });
    });
    mapForm->addRow(tr("Intensity"), m_intensity);
    skyForm->addRow(m_mapRows);

    m_lightRows = new QWidget;
    QFormLayout* lightForm = form(m_lightRows);
    m_lights = sceneIntSpin("sky.lights", "sky.lights");
    connect(m_lights, &QSpinBox::valueChanged, this, [this](int v) {
        apply(m_lights, tr("Change sky lights"), [&](Scene& s) {
            s.skyModel.lights = v;
            // The groups split the lights: no more groups than lights (what the scene file requires).
            s.skyModel.interleave = std::min(s.skyModel.interleave, v);
        });
    });
    lightForm->addRow(tr("Sky samples"), m_lights);
    m_interleave = sceneIntSpin("sky.interleave", "sky.interleave");
    connect(m_interleave, &QSpinBox::valueChanged, this, [this](int v) {
        apply(m_interleave, tr("Change sky interleave"), [&](Scene& s) { s.skyModel.interleave = std::min(v, s.skyModel.lights); });
    });
    lightForm->addRow(tr("Sky sample groups"), m_interleave);
    skyForm->addRow(m_lightRows);
    m_lbSky = new QCheckBox(tr("Skylight inside the crowns"));
    m_lbSky->setObjectName("lighting.boundary");
    connect(m_lbSky, &QCheckBox::toggled, this, [this](bool on) {
        apply(m_lbSky, tr("Change LB boundary"), [&](Scene& s) { s.lighting.boundary = on ? LbBoundary::SunSky : LbBoundary::Sun; });
    });
    skyForm->addRow(m_lbSky);
    m_aerial = new QCheckBox(tr("Haze in the distance"));
    m_aerial->setObjectName("sky.aerial_perspective");
    connect(m_aerial, &QCheckBox::toggled, this, [this](bool on) {
        apply(m_aerial, on ? tr("Turn on distance haze") : tr("Turn off distance haze"),
              [&](Scene& s) { s.skyModel.aerialPerspective = on; });
    });
    skyForm->addRow(m_aerial);
    layout->addWidget(skyBox);

    // The sun.
    auto* sunBox = new QGroupBox(tr("Sun"));
    auto* sunLayout = new QVBoxLayout(sunBox);
    m_sunMode = new QComboBox;
    m_sunMode->setObjectName("sun.mode");
    m_sunMode->addItem(tr("Elevation and azimuth"));
    m_sunMode->addItem(tr("Date, time and place"));
    sunLayout->addWidget(m_sunMode);
    m_sunPages = new QStackedWidget;
    sunLayout->addWidget(m_sunPages);
    connect(m_sunMode, &QComboBox::currentIndexChanged, this, [this](int idx) {
        if (idx == 0) {
            apply(m_sunMode, tr("Sun by direction"), [](Scene& s) { s.sun.place.reset(); });
        } else {
            const sky::SunPlace p = placeOf(m_doc->scene());
            applyPlace(m_sunMode, [p](sky::SunPlace& q) { q = p; });
        }
    });

    auto* dialPage = new QWidget;
    QFormLayout* dialForm = form(dialPage);
    m_elevation = sceneSpin("sun.elevation", "sun.elevation", 1, 1.0);
    m_azimuth = spin("sun.azimuth", 0.0, 360.0, 1, 1.0);
    m_azimuth->setWrapping(true);
    m_dial = new CompassDial;
    m_dial->setObjectName("sun.azimuthDial");
    auto setAngles = [this](QObject* editor, double elevation, double azimuth) {
        apply(editor, tr("Move sun"), [&](Scene& s) {
            s.sun.place.reset();
            s.sun.direction = sunDirection(elevation, azimuth);
        });
    };
    connect(m_elevation, &QDoubleSpinBox::valueChanged, this,
            [this, setAngles](double v) { setAngles(m_elevation, v, m_azimuth->value()); });
    connect(m_azimuth, &QDoubleSpinBox::valueChanged, this,
            [this, setAngles](double v) { setAngles(m_azimuth, m_elevation->value(), v); });
    // As the properties' dial: the value is the azimuth (0 south at the bottom, 90 east at the right: a map, north up).
    connect(m_dial, &QDial::valueChanged, this, [this, setAngles](int v) { setAngles(m_dial, m_elevation->value(), double(v)); });
    dialForm->addRow(tr("Elevation (deg)"), m_elevation);
    dialForm->addRow(tr("Azimuth (deg)"), row({m_dial, m_azimuth}));
    m_sunPages->addWidget(dialPage);

    auto* placePage = new QWidget;
    QFormLayout* placeForm = form(placePage);
    m_date = new QDateEdit;
    m_date->setObjectName("sun.date");
    m_date->setDisplayFormat("yyyy-MM-dd");
    m_date->setDateRange(QDate(1583, 1, 1), QDate(3000, 12, 31));
    m_date->setCalendarPopup(true);
    m_date->setKeyboardTracking(false);
    connect(m_date, &QDateEdit::dateChanged, this, [this](const QDate& d) {
        applyPlace(m_date, [d](sky::SunPlace& p) {
            p.year = d.year();
            p.month = d.month();
            p.day = d.day();
        });
    });
    m_time = new QTimeEdit;
    m_time->setObjectName("sun.time");
    m_time->setDisplayFormat("HH:mm");
    m_time->setKeyboardTracking(false);
    connect(m_time, &QTimeEdit::timeChanged, this, [this](const QTime& t) {
        applyPlace(m_time, [t](sky::SunPlace& p) { p.hour = t.hour() + t.minute() / 60.0; });
    });
    m_timeSlider = new QSlider(Qt::Horizontal);
    m_timeSlider->setObjectName("sun.timeSlider");
    m_timeSlider->setRange(0, 24 * 60 - 1);   // minutes of the local day
    m_timeSlider->setSingleStep(5);
    m_timeSlider->setPageStep(60);
    connect(m_timeSlider, &QSlider::valueChanged, this, [this](int minutes) {
        applyPlace(m_timeSlider, [minutes](sky::SunPlace& p) { p.hour = minutes / 60.0; });
    });
    m_zone = sceneSpin("sun.timezone", "sun.timezone", 2, 0.5);
    connect(m_zone, &QDoubleSpinBox::valueChanged, this,
            [this](double v) { applyPlace(m_zone, [v](sky::SunPlace& p) { p.timeZoneHours = v; }); });
    m_latitude = sceneSpin("sun.latitude", "sun.latitude", 4, 0.5);
    connect(m_latitude, &QDoubleSpinBox::valueChanged, this,
            [this](double v) { applyPlace(m_latitude, [v](sky::SunPlace& p) { p.latitudeDeg = v; }); });
    m_longitude = sceneSpin("sun.longitude", "sun.longitude", 4, 0.5);
    connect(m_longitude, &QDoubleSpinBox::valueChanged, this,
            [this](double v) { applyPlace(m_longitude, [v](sky::SunPlace& p) { p.longitudeDeg = v; }); });
    placeForm->addRow(tr("Date"), m_date);
    placeForm->addRow(tr("Time"), row({m_time, m_timeSlider}));
    placeForm->addRow(tr("Time zone (h)"), m_zone);
    placeForm->addRow(tr("Latitude (deg N)"), m_latitude);
    placeForm->addRow(tr("Longitude (deg E)"), m_longitude);
    m_sunPages->addWidget(placePage);
    m_sunInfo = new QLabel;
    m_sunInfo->setObjectName("sun.info");
    m_sunInfo->setWordWrap(true);
    sunLayout->addWidget(m_sunInfo);
    layout->addWidget(sunBox);

    // The look: exposure, leaf tint, ground colour.
    auto* lookBox = new QGroupBox(tr("Look"));
    auto* lookForm = new QFormLayout(lookBox);
    m_exposure = spin("render.exposure", -10.0, 10.0, 2, 0.25);
    connect(m_exposure, &QDoubleSpinBox::valueChanged, this, [this](double ev) {
        apply(m_exposure, tr("Change exposure"), [&](Scene& s) { s.render.exposureKey = float(kMiddleGrey * std::exp2(ev)); });
    });
    lookForm->addRow(tr("Exposure (EV)"), m_exposure);
    for (int c = 0; c < 3; ++c) {
        m_leafTint[size_t(c)] = spin(QStringLiteral("render.leafTint.%1").arg(c), 0.0, 2.0, 2, 0.05);
        connect(m_leafTint[size_t(c)], &QDoubleSpinBox::valueChanged, this, [this, c](double v) {
            apply(m_leafTint[size_t(c)], tr("Change leaf tint"), [&](Scene& s) { s.render.leafTint[c] = float(v); });
        });
        m_groundColor[size_t(c)] = spin(QStringLiteral("ground.color.%1").arg(c), 0.0, 1.0, 3, 0.05);
        connect(m_groundColor[size_t(c)], &QDoubleSpinBox::valueChanged, this, [this, c](double v) {
            apply(m_groundColor[size_t(c)], tr("Change ground colour"), [&](Scene& s) { s.ground.color[c] = float(v); });
        });
    }
    lookForm->addRow(tr("Leaf tint (R G B)"), row({m_leafTint[0], m_leafTint[1], m_leafTint[2]}));
    lookForm->addRow(tr("Ground colour (R G B)"), row({m_groundColor[0], m_groundColor[1], m_groundColor[2]}));
    layout->addWidget(lookBox);

    m_status = new QLabel;
    m_status->setObjectName("sky.status");
    m_status->setWordWrap(true);
    m_status->setStyleSheet("color: #b00020");
    layout->addWidget(m_status);
    layout->addStretch(1);
    applyToolTips(this);   // the artists' words for every control (studio/words.cpp)

    connect(doc, &SceneDocument::changed, this, [this] {
        m_status->clear();
        refresh();
    });
    connect(doc, &SceneDocument::editRefused, this, [this](const QString& text, const QString& reason) {
        m_status->setText(tr("%1 refused: %2").arg(text, reason));
        refresh();
    });
    refresh();
}

QString SkyPanel::status() const { return m_status->text(); }


void SkyPanel::apply(QObject* editor, const QString& text, const std::function<void(Scene&)>& change)
{
    Scene s = m_doc->scene();
    change(s);
    m_doc->edit(s, text, m_merger.keyFor(editor));
}

void SkyPanel::applyPlace(QObject* editor, const std::function<void(sky::SunPlace&)>& change)
{
    sky::SunPlace p = placeOf(m_doc->scene());
    change(p);
    glm::vec3 direction;
    try {
        direction = sky::placeSunDirection(p);
    } catch (const Error& e) {
        m_status->setText(tr("Sun refused: %1").arg(QString::fromStdString(e.what())));
        refresh();
        return;
    }
    apply(editor, tr("Move sun (date and place)"), [&](Scene& s) {
        s.sun.place = p;
        s.sun.direction = direction;
    });
}

void SkyPanel::chooseMap()
{
    const QString path = m_chooseMap ? m_chooseMap() : QString();
    if (!path.isEmpty()) setMapPath(path);
}

void SkyPanel::setMapPath(const QString& path)
{
    const std::string abs = QFileInfo(path).absoluteFilePath().toStdString();
    apply(m_path, tr("Choose sky map"), [&](Scene& s) {
        s.skyModel.kind = sky::SkyKind::Map;
        s.skyModel.path = abs;
    });
}

void SkyPanel::refresh()
{
    const Scene& s = m_doc->scene();
    const SkyDesc& d = s.skyModel;
    {
        const QSignalBlocker b1(m_kind), b2(m_lights), b3(m_interleave), b4(m_sunMode), b5(m_dial), b6(m_date), b7(m_time),
            b8(m_timeSlider), b9(m_lbSky), b10(m_aerial);
        m_lbSky->setChecked(s.lighting.boundary == LbBoundary::SunSky);
        m_aerial->setChecked(d.aerialPerspective);
        m_kind->setCurrentIndex(m_kind->findData(int(d.kind)));
        m_lights->setValue(d.lights);
        m_interleave->setMaximum(std::max(1, d.lights));   // at most one group a light
        m_interleave->setValue(d.interleave);
        m_sunMode->setCurrentIndex(s.sun.place ? 1 : 0);
        double el = 0.0, az = 0.0;
        sunAngles(s.sun.direction, &el, &az);
        setValue(m_elevation, el);
        setValue(m_azimuth, az);
        m_dial->setValue(int(std::lround(az)) % 360);
        const sky::SunPlace p = placeOf(s);
        m_date->setDate(QDate(p.year, p.month, p.day));
        const int minutes = int(std::lround(p.hour * 60.0));
        m_time->setTime(QTime(std::min(23, minutes / 60), minutes >= 24 * 60 ? 59 : minutes % 60));
        m_timeSlider->setValue(std::min(24 * 60 - 1, minutes));
        setValue(m_zone, p.timeZoneHours);
        setValue(m_latitude, p.latitudeDeg);
        setValue(m_longitude, p.longitudeDeg);
        m_sunInfo->setText(tr("Elevation %1 deg, azimuth %2 deg").arg(el, 0, 'f', 2).arg(az, 0, 'f', 2) +
                           (d.kind == sky::SkyKind::Map && d.sunFromMap ? tr(" (the picture's sun is the map's own)") : QString()));
    }
    setValue(m_turbidity, d.turbidity);
    setValue(m_rotation, double(d.rotationDeg));
    setValue(m_intensity, double(d.intensity));
    m_path->setText(QString::fromStdString(d.path));
    m_preethamRows->setVisible(d.kind == sky::SkyKind::Preetham || d.aerialPerspective);   // the haze's turbidity
    m_mapRows->setVisible(d.kind == sky::SkyKind::Map);
    m_lightRows->setVisible(d.analytic());
    m_sunPages->setCurrentIndex(s.sun.place ? 1 : 0);
    setValue(m_exposure, std::log2(double(s.render.exposureKey) / kMiddleGrey));
    for (int c = 0; c < 3; ++c) {
        setValue(m_leafTint[size_t(c)], double(s.render.leafTint[c]));
        setValue(m_groundColor[size_t(c)], double(s.ground.color[c]));
    }
}

} // namespace sylva
