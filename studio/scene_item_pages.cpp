// SceneItemPages: one page per landscape part and one for a volume; widgets refresh under QSignalBlocker.
#include "studio/scene_item_pages.h"

#include <algorithm>

#include <QCheckBox>
#include <QComboBox>
#include <QDoubleSpinBox>
#include <QFileInfo>
#include <QFormLayout>
#include <QHBoxLayout>
#include <QLabel>
#include <QSignalBlocker>
#include <QSpinBox>

#include "core/terrain/height_field.h"

#include "studio/form_widgets.h"
#include "studio/param_widgets.h"
#include "studio/words.h"

namespace sylva {
using namespace widgets;
namespace {


QSpinBox* intSpin(const QString& name, int lo, int hi)
{
    auto* s = new QSpinBox;
    s->setObjectName(name);
    s->setRange(lo, hi);
    s->setKeyboardTracking(false);
    return s;
}


} // namespace

SceneItemPages::SceneItemPages(SceneDocument* doc, Apply apply, QWidget* parent)
    : QStackedWidget(parent), m_doc(doc), m_apply(std::move(apply))
{
    addWidget(m_terrainPage = buildTerrainPage());
    addWidget(m_tilesPage = buildTilesPage());
    addWidget(m_tilingPage = buildTilingPage());
    addWidget(m_densityPage = buildDensityPage());
    addWidget(m_volumePage = buildVolumePage());
}


QWidget* SceneItemPages::buildTerrainPage()
{
    auto* page = new QWidget;
    auto* form = new QFormLayout(page);
    m_terrainInfo = new QLabel;
    m_terrainInfo->setWordWrap(true);
    m_terrainInfo->setTextInteractionFlags(Qt::TextSelectableByMouse);
    m_snowLine = sceneSpin("terrain.snow_line", "terrain.snowLine", 1, 50.0);
    connect(m_snowLine, &QDoubleSpinBox::valueChanged, this,
            [this](double v) { m_apply(m_snowLine, tr("Change snow line"), [&](Scene& s) { s.terrain.snowLine = float(v); }); });
    m_rockSlope = sceneSpin("terrain.rock_slope", "terrain.rockSlope", 1, 1.0);
    connect(m_rockSlope, &QDoubleSpinBox::valueChanged, this,
            [this](double v) { m_apply(m_rockSlope, tr("Change rock slope"), [&](Scene& s) { s.terrain.rockSlope = float(v); }); });
    form->addRow(m_terrainInfo);
    form->addRow(tr("Snow line (m)"), m_snowLine);
    form->addRow(tr("Rock slope (deg)"), m_rockSlope);
    return page;
}

QWidget* SceneItemPages::buildTilesPage()
{
    auto* page = new QWidget;
    m_plantForm = new QFormLayout(page);
    m_tileSize = sceneSpin("terrain.tiles.size", "tiles.size", 1, 10.0);
    connect(m_tileSize, &QDoubleSpinBox::valueChanged, this,
            [this](double v) { m_apply(m_tileSize, tr("Change tile size"), [&](Scene& s) { s.terrain.tiles.size = v; }); });
    m_tileSeed = sceneIntSpin("terrain.tiles.seed", "tiles.seed");   // the file's range, clamped to an int
    connect(m_tileSeed, &QSpinBox::valueChanged, this,
            [this](int v) { m_apply(m_tileSeed, tr("Change tile seed"), [&](Scene& s) { s.terrain.tiles.seed = uint64_t(v); }); });
    m_plantForm->addRow(tr("Tile size (m)"), m_tileSize);
    m_plantForm->addRow(tr("Seed"), m_tileSeed);
    m_plantForm->addRow(new QLabel(tr("Poisson-disk spacing per plant kind (m):")));
    return page;
}

void SceneItemPages::rebuildPlantRows(const Scene& scene)
{
    const std::vector<TilePlantDesc>& plants = scene.terrain.tiles.plants;
    if (m_plantSpacing.size() != plants.size()) {
        while (m_plantForm->rowCount() > 3) m_plantForm->removeRow(3);
        m_plantSpacing.clear();
        for (size_t i = 0; i < plants.size(); ++i) {
            QDoubleSpinBox* box = sceneSpin("terrain.tiles.plants[i].spacing", QStringLiteral("tiles.spacing.%1").arg(i), 2, 0.5);
            box->setToolTip(controlToolTip(box->objectName()));
            connect(box, &QDoubleSpinBox::valueChanged, this, [this, box, i](double v) {
                m_apply(box, tr("Change plant spacing"), [&](Scene& s) { s.terrain.tiles.plants.at(i).spacing = v; });
            });
            m_plantForm->addRow(QString::fromStdString(plants[i].speciesName), box);
            m_plantSpacing.push_back(box);
        }
    }
    for (size_t i = 0; i < plants.size(); ++i) {
        setValue(m_plantSpacing[i], plants[i].spacing);
        if (auto* label = qobject_cast<QLabel*>(m_plantForm->labelForField(m_plantSpacing[i])))
            label->setText(QString::fromStdString(plants[i].speciesName));
    }
}

QWidget* SceneItemPages::buildTilingPage()
{
    auto* page = new QWidget;
    auto* form = new QFormLayout(page);
    m_tilingH = intSpin("tiling.horizontal", 1, 8);
    m_tilingV = intSpin("tiling.vertical", 1, 8);
    m_tilingSeed = sceneIntSpin("terrain.tiling.seed", "tiling.seed");
    m_tilingInfo = new QLabel;
    m_tilingInfo->setWordWrap(true);
    // A colour count edit makes the set every combination of colours (a given set would no longer match).
    connect(m_tilingH, &QSpinBox::valueChanged, this, [this](int v) {
        m_apply(m_tilingH, tr("Change tiling colours"), [&](Scene& s) {
            s.terrain.tiling.horizontal = v;
            s.terrain.tiling.setGiven = false;
            s.terrain.tiling.set.clear();
        });
    });
    connect(m_tilingV, &QSpinBox::valueChanged, this, [this](int v) {
        m_apply(m_tilingV, tr("Change tiling colours"), [&](Scene& s) {
            s.terrain.tiling.vertical = v;
            s.terrain.tiling.setGiven = false;
            s.terrain.tiling.set.clear();
        });
    });
    connect(m_tilingSeed, &QSpinBox::valueChanged, this,
            [this](int v) { m_apply(m_tilingSeed, tr("Change tiling seed"), [&](Scene& s) { s.terrain.tiling.seed = uint64_t(v); }); });
    form->addRow(m_tilingInfo);
    form->addRow(tr("South/north colours"), m_tilingH);
    form->addRow(tr("East/west colours"), m_tilingV);
    form->addRow(tr("Seed"), m_tilingSeed);
    return page;
}

QWidget* SceneItemPages::buildDensityPage()
{
    auto* page = new QWidget;
    auto* form = new QFormLayout(page);
    m_densityOn = new QCheckBox(tr("Thin plants by altitude (Dietrich, Marmitt & Slusallek, eq. 2-3)"));
    m_densityOn->setObjectName("density.enabled");
    connect(m_densityOn, &QCheckBox::toggled, this, [this](bool on) {
        m_apply(m_densityOn, on ? tr("Density rule on") : tr("Density rule off"), [&](Scene& s) { s.terrain.density.enabled = on; });
    });
    m_densityLower = spin("density.lower", -1e5, 1e5, 1, 50.0);
    m_densityUpper = spin("density.upper", -1e5, 1e5, 1, 50.0);
    m_densityAtLower = sceneSpin("terrain.density.at_lower", "density.atLower", 3, 0.05);
    m_densityAtUpper = sceneSpin("terrain.density.at_upper", "density.atUpper", 3, 0.05);
    connect(m_densityLower, &QDoubleSpinBox::valueChanged, this,
            [this](double v) { m_apply(m_densityLower, tr("Move lower tree line"), [&](Scene& s) { s.terrain.density.lower = v; }); });
    connect(m_densityUpper, &QDoubleSpinBox::valueChanged, this,
            [this](double v) { m_apply(m_densityUpper, tr("Move upper tree line"), [&](Scene& s) { s.terrain.density.upper = v; }); });
    connect(m_densityAtLower, &QDoubleSpinBox::valueChanged, this, [this](double v) {
        m_apply(m_densityAtLower, tr("Change density"), [&](Scene& s) { s.terrain.density.atLower = float(v); });
    });
    connect(m_densityAtUpper, &QDoubleSpinBox::valueChanged, this, [this](double v) {
        m_apply(m_densityAtUpper, tr("Change density"), [&](Scene& s) { s.terrain.density.atUpper = float(v); });
    });
    form->addRow(m_densityOn);
    form->addRow(tr("Lower tree line (m)"), m_densityLower);
    form->addRow(tr("Density there"), m_densityAtLower);
    form->addRow(tr("Upper tree line (m)"), m_densityUpper);
    form->addRow(tr("Density there"), m_densityAtUpper);
    return page;
}

QWidget* SceneItemPages::buildVolumePage()
{
    auto* page = new QWidget;
    auto* form = new QFormLayout(page);
    m_volumeInfo = new QLabel;
    m_volumeInfo->setWordWrap(true);
    m_volumeInfo->setTextInteractionFlags(Qt::TextSelectableByMouse);
    m_volumePreset = new QComboBox;
    m_volumePreset->setObjectName("volume.preset");
    for (const char* p : {"cloud", "smoke", "pmma"}) m_volumePreset->addItem(QString::fromLatin1(p));
    connect(m_volumePreset, &QComboBox::currentTextChanged, this, [this](const QString& name) {
        lb::LbParams optics;
        const int i = m_item.row;
        if (i < 0 || !volumePreset(name.toStdString(), &optics)) return;
        m_apply(m_volumePreset, tr("Change volume optics"), [&](Scene& s) {
            VolumeDesc& v = s.volumes.at(size_t(i));
            const lb::LbParams old = v.lighting;
            v.preset = name.toStdString();
            v.lighting = optics;
            v.lighting.steps = old.steps;
            v.lighting.tolerance = old.tolerance;
            v.lighting.storage = old.storage;
        });
    });
    m_volumeTracer = new QComboBox;
    m_volumeTracer->setObjectName("volume.tracer");
    // In the order of VolumeTracer (lb, single, combined): the index is the value.
    m_volumeTracer->addItem(tr("Scattered light (lighting grid)"));
    m_volumeTracer->addItem(tr("Sun shadow only"));
    m_volumeTracer->addItem(tr("Both"));
    connect(m_volumeTracer, &QComboBox::currentIndexChanged, this, [this](int idx) {
        const int i = m_item.row;
        if (i < 0 || idx < 0) return;
        m_apply(m_volumeTracer, tr("Change volume tracer"), [&](Scene& s) { s.volumes.at(size_t(i)).tracer = VolumeTracer(idx); });
    });
    m_volumeDensityScale = sceneSpin("volumes[i].density_scale", "volume.densityScale", 3, 0.05);   // the top set per grid
    connect(m_volumeDensityScale, &QDoubleSpinBox::valueChanged, this, [this](double v) {
        const int i = m_item.row;
        m_apply(m_volumeDensityScale, tr("Change volume density"), [&](Scene& s) { s.volumes.at(size_t(i)).densityScale = float(v); });
    });
    auto* posRow = new QWidget;
    auto* pl = new QHBoxLayout(posRow);
    pl->setContentsMargins(0, 0, 0, 0);
    const char* axis[3] = {"x", "y", "z"};
    for (int a = 0; a < 3; ++a) {
        QDoubleSpinBox* box = m_volumePos[size_t(a)] = spin(QStringLiteral("volume.position.%1").arg(axis[a]), -1e7, 1e7, 2, 0.5);
        connect(box, &QDoubleSpinBox::valueChanged, this, [this, box, a](double v) {
            const int i = m_item.row;
            m_apply(box, tr("Move volume"), [&](Scene& s) {
                VolumeDesc& vd = s.volumes.at(size_t(i));
                if (vd.instances.empty()) vd.instances.emplace_back();
                vd.instances[0].position[a] = v;
            });
        });
        pl->addWidget(box);
    }
    m_volumeScale = sceneSpin("volumes[i].instances[i].scale", "volume.scale", 3, 0.1);
    connect(m_volumeScale, &QDoubleSpinBox::valueChanged, this, [this](double v) {
        const int i = m_item.row;
        m_apply(m_volumeScale, tr("Scale volume"), [&](Scene& s) {
            VolumeDesc& vd = s.volumes.at(size_t(i));
            if (vd.instances.empty()) vd.instances.emplace_back();
            vd.instances[0].scale = float(v);
        });
    });
    form->addRow(m_volumeInfo);
    form->addRow(tr("Material"), m_volumePreset);
    form->addRow(tr("Lit by"), m_volumeTracer);
    form->addRow(tr("Density scale"), m_volumeDensityScale);
    form->addRow(tr("Position (m)"), posRow);
    form->addRow(tr("Scale"), m_volumeScale);
    return page;
}

bool SceneItemPages::showItem(const OutlinerItem& item, const Scene& s)
{
    using K = OutlinerItem::Kind;
    m_item = item;
    const TerrainDesc& t = s.terrain;
    switch (item.kind) {
    case K::Terrain: {
        if (!t.enabled()) return false;
        QString info = tr("<b>Terrain</b><br>%1").arg(QFileInfo(QString::fromStdString(t.dem)).fileName().toHtmlEscaped());
        if (t.field) {
            const HeightFieldLayout& L = t.field->layout;
            info += tr("<br>%1 x %2 samples, %3 m apart: %4 x %5 km")
                        .arg(L.nx)
                        .arg(L.nz)
                        .arg(t.spacing)
                        .arg(double(L.nx - 1) * double(L.dx) / 1000.0, 0, 'f', 2)
                        .arg(double(L.nz - 1) * double(L.dz) / 1000.0, 0, 'f', 2);
        }
        info += tr("<br>origin (%1, %2, %3) m; %4 cells a side")
                    .arg(t.origin.x, 0, 'f', 1)
                    .arg(t.origin.y, 0, 'f', 1)
                    .arg(t.origin.z, 0, 'f', 1)
                    .arg(t.cells);
        m_terrainInfo->setText(info);
        setValue(m_snowLine, double(t.snowLine));
        setValue(m_rockSlope, double(t.rockSlope));
        setCurrentWidget(m_terrainPage);
        return true;
    }
    case K::Tiles:
        if (!t.enabled()) return false;
        setValue(m_tileSize, t.tiles.size);
        setValue(m_tileSeed, int(std::min<uint64_t>(t.tiles.seed, uint64_t(m_tileSeed->maximum()))));
        rebuildPlantRows(s);
        setCurrentWidget(m_tilesPage);
        return true;
    case K::Tiling: {
        if (!t.enabled()) return false;
        const TilingDesc& tl = t.tiling;
        const int tiles = tl.setGiven ? int(tl.set.size()) : tl.horizontal * tl.horizontal * tl.vertical * tl.vertical;
        m_tilingInfo->setText(tl.setGiven ? tr("A given set of %1 Wang tiles").arg(tiles)
                                          : tr("Every combination of edge colours: %1 Wang tiles").arg(tiles));
        setValue(m_tilingH, tl.horizontal);
        setValue(m_tilingV, tl.vertical);
        setValue(m_tilingSeed, int(std::min<uint64_t>(tl.seed, uint64_t(m_tilingSeed->maximum()))));
        setCurrentWidget(m_tilingPage);
        return true;
    }
    case K::Density: {
        if (!t.enabled()) return false;
        const DensityDesc& d = t.density;
        {
            const QSignalBlocker block(m_densityOn);
            m_densityOn->setChecked(d.enabled);
        }
        setValue(m_densityLower, d.lower);
        setValue(m_densityUpper, d.upper);
        setValue(m_densityAtLower, double(d.atLower));
        setValue(m_densityAtUpper, double(d.atUpper));
        setCurrentWidget(m_densityPage);
        return true;
    }
    case K::Volume: {
        if (item.row < 0 || size_t(item.row) >= s.volumes.size()) return false;
        const VolumeDesc& v = s.volumes[size_t(item.row)];
        QString info = tr("<b>%1</b><br>%2").arg(QString::fromStdString(v.name).toHtmlEscaped(),
                                                 QString::fromStdString(v.grid).toHtmlEscaped());
        float peak = 0.0f;
        if (v.data) {
            const glm::ivec3 d = v.data->density.geometry.dims;
            for (float x : v.data->density.density) peak = std::max(peak, x);
            info += tr("<br>%1 x %2 x %3 nodes, %4 m apart, largest density %5")
                        .arg(d.x)
                        .arg(d.y)
                        .arg(d.z)
                        .arg(double(v.data->density.geometry.spacing), 0, 'g', 4)
                        .arg(double(peak), 0, 'g', 3);
            if (!v.data->temperature.empty()) info += tr("<br>with a temperature grid (emission)");
        }
        m_volumeInfo->setText(info);
        {
            const QSignalBlocker b1(m_volumePreset), b2(m_volumeTracer);
            m_volumePreset->setCurrentText(QString::fromStdString(v.preset));
            m_volumeTracer->setCurrentIndex(int(v.tracer));
        }
        // density x scale stays in [0, 1] (the LB's range).
        m_volumeDensityScale->setMaximum(peak > 0.0f ? std::max(0.001, 1.0 / double(peak)) : 1.0);
        setValue(m_volumeDensityScale, double(v.densityScale));
        const VolumePlacement p = v.instances.empty() ? VolumePlacement{} : v.instances[0];
        for (int a = 0; a < 3; ++a) setValue(m_volumePos[size_t(a)], p.position[a]);
        setValue(m_volumeScale, double(p.scale));
        setCurrentWidget(m_volumePage);
        return true;
    }
    default: return false;
    }
}

} // namespace sylva
