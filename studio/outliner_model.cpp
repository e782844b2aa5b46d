// OutlinerModel: group rows with internal id 0, child rows with internal id group + 1.
#include "studio/outliner_model.h"

#include <algorithm>
#include <cmath>

#include <QFileInfo>

#include "core/terrain/height_field.h"

namespace sylva {
namespace {

QString vec3Text(double x, double y, double z)
{
    return QStringLiteral("(%1, %2, %3)").arg(decimalText(x), decimalText(y), decimalText(z));
}

// Rows under Terrain: Tiles, Tiling, Density for a landscape (a terrain with cells), none otherwise.
int terrainRows(const Scene& s) { return s.terrain.enabled() && s.terrain.cells > 0 ? 3 : 0; }

} // namespace

QString decimalText(double v)
{
    if (!std::isfinite(v)) return QString::number(v);
    // Four significant digits, but never fewer than the units and never more than millimetres: 12690,
    // 123.5, 2.5, 0.013; what rounds to zero is 0 (not 1.2e-15, not -0).
    const double a = std::abs(v);
    const int decimals = a > 0.0 ? std::clamp(3 - int(std::floor(std::log10(a))), 0, 3) : 0;
    QString text = QString::number(v, 'f', decimals);
    if (text.contains(QLatin1Char('.'))) {
        while (text.endsWith(QLatin1Char('0'))) text.chop(1);
        if (text.endsWith(QLatin1Char('.'))) text.chop(1);
    }
    if (text == QLatin1String("-0")) text = QStringLiteral("0");
    return text;
}

OutlinerModel::OutlinerModel(SceneDocument* doc, QObject* parent) : QAbstractItemModel(parent), m_doc(doc)
{
    m_species = int(doc->scene().species.size());
    m_instances = int(doc->scene().instances.size());
    m_terrainRows = terrainRows(doc->scene());
    m_volumes = int(doc->scene().volumes.size());
    connect(doc, &SceneDocument::changed, this, &OutlinerModel::onChanged);
}

void OutlinerModel::onChanged(ScenePart)
{
    const Scene& s = m_doc->scene();
    const int ns = int(s.species.size()), ni = int(s.instances.size()), nt = terrainRows(s), nv = int(s.volumes.size());
    if (ns != m_species || ni != m_instances || nt != m_terrainRows || nv != m_volumes) {
        beginResetModel();
        m_species = ns;
        m_instances = ni;
        m_terrainRows = nt;
        m_volumes = nv;
        endResetModel();
        return;
    }
    // Same shape: every row may show new text.
    for (int g = 0; g < GroupCount; ++g) {
        const QModelIndex gi = index(g, 0);
        Q_EMIT dataChanged(gi, index(g, 1));
        const int n = rowCount(gi);
        if (n > 0) Q_EMIT dataChanged(index(0, 0, gi), index(n - 1, 1, gi));
    }
}

QModelIndex OutlinerModel::index(int row, int column, const QModelIndex& parent) const
{
    if (!hasIndex(row, column, parent)) return {};
    if (!parent.isValid()) return createIndex(row, column, quintptr(0));
    return createIndex(row, column, quintptr(parent.row() + 1));
}

QModelIndex OutlinerModel::parent(const QModelIndex& child) const
{
    if (!child.isValid() || child.internalId() == 0) return {};
    return createIndex(int(child.internalId()) - 1, 0, quintptr(0));
}

int OutlinerModel::rowCount(const QModelIndex& parent) const
{
    if (!parent.isValid()) return GroupCount;
    if (parent.column() != 0 || parent.internalId() != 0) return 0;
    if (parent.row() == SpeciesGroup) return m_species;
    if (parent.row() == InstancesGroup) return m_instances;
    if (parent.row() == TerrainGroup) return m_terrainRows;
    if (parent.row() == VolumesGroup) return m_volumes;
    return 0;
}

int OutlinerModel::columnCount(const QModelIndex&) const { return 2; }

Qt::ItemFlags OutlinerModel::flags(const QModelIndex& index) const
{
    if (!index.isValid()) return Qt::NoItemFlags;
    return Qt::ItemIsEnabled | Qt::ItemIsSelectable;
}

QVariant OutlinerModel::headerData(int section, Qt::Orientation orientation, int role) const
{
    if (orientation != Qt::Horizontal || role != Qt::DisplayRole) return {};
    return section == 0 ? tr("Name") : tr("Details");
}

OutlinerItem OutlinerModel::itemAt(const QModelIndex& index) const
{
    if (!index.isValid()) return {};
    if (index.internalId() == 0) {
        switch (index.row()) {
        case SpeciesGroup: return {OutlinerItem::Kind::SpeciesGroup, -1};
        case InstancesGroup: return {OutlinerItem::Kind::InstancesGroup, -1};
        case GroundGroup: return {OutlinerItem::Kind::Ground, -1};
        case SunGroup: return {OutlinerItem::Kind::Sun, -1};
        case CameraGroup: return {OutlinerItem::Kind::Camera, -1};
        case TerrainGroup: return {OutlinerItem::Kind::Terrain, -1};
        case VolumesGroup: return {OutlinerItem::Kind::VolumesGroup, -1};
        default: return {};
        }
    }
    const int group = int(index.internalId()) - 1;
    if (group == SpeciesGroup) return {OutlinerItem::Kind::Species, index.row()};
    if (group == InstancesGroup) return {OutlinerItem::Kind::Instance, index.row()};
    if (group == TerrainGroup) {
        constexpr OutlinerItem::Kind kRows[3] = {OutlinerItem::Kind::Tiles, OutlinerItem::Kind::Tiling, OutlinerItem::Kind::Density};
        return index.row() < 3 ? OutlinerItem{kRows[index.row()], -1} : OutlinerItem{};
    }
    if (group == VolumesGroup) return {OutlinerItem::Kind::Volume, index.row()};
    return {};
}

QModelIndex OutlinerModel::indexOf(const OutlinerItem& item, int column) const
{
    using K = OutlinerItem::Kind;
    switch (item.kind) {
    case K::SpeciesGroup: return index(SpeciesGroup, column);
    case K::InstancesGroup: return index(InstancesGroup, column);
    case K::Ground: return index(GroundGroup, column);
    case K::Sun: return index(SunGroup, column);
    case K::Camera: return index(CameraGroup, column);
    case K::Species: return index(item.row, column, index(SpeciesGroup, 0));
    case K::Instance: return index(item.row, column, index(InstancesGroup, 0));
    case K::Terrain: return index(TerrainGroup, column);
    case K::Tiles: return index(0, column, index(TerrainGroup, 0));
    case K::Tiling: return index(1, column, index(TerrainGroup, 0));
    case K::Density: return index(2, column, index(TerrainGroup, 0));
    case K::VolumesGroup: return index(VolumesGroup, column);
    case K::Volume: return index(item.row, column, index(VolumesGroup, 0));
    case K::None: break;
    }
    return {};
}

QVariant OutlinerModel::data(const QModelIndex& index, int role) const
{
    if (!index.isValid() || (role != Qt::DisplayRole && role != Qt::ToolTipRole)) return {};
    const Scene& s = m_doc->scene();
    const OutlinerItem it = itemAt(index);
    const bool name = index.column() == 0;
    using K = OutlinerItem::Kind;
    switch (it.kind) {
    case K::SpeciesGroup: return name ? tr("Species") : tr("%n species", nullptr, m_species);
    case K::InstancesGroup: return name ? tr("Instances") : tr("%n instance(s)", nullptr, m_instances);
    case K::Ground:
        return name ? tr("Ground") : s.ground.enabled ? tr("plane at y = %1 m").arg(decimalText(s.ground.height)) : tr("off");
    case K::Sun: {
        if (name) return tr("Sun");
        return tr("%1 K, intensity %2").arg(decimalText(s.sun.temperature), decimalText(double(s.sun.intensity)));
    }
    case K::Camera:
        if (name) return tr("Camera");
        return tr("at %1").arg(vec3Text(s.camera.position.x, s.camera.position.y, s.camera.position.z));
    case K::Species: {
        if (it.row >= int(s.species.size())) return {};
        const SpeciesDesc& sp = s.species[size_t(it.row)];
        if (name) return QString::fromStdString(sp.name);
        const QString source = sp.grow ? tr("grown %1, seed %2").arg(QString::fromStdString(sp.grow->species)).arg(sp.grow->seed)
                                       : QFileInfo(QString::fromStdString(sp.meshPath)).fileName();
        return tr("%1; %2, grid %3").arg(source, QString::fromStdString(sp.preset)).arg(sp.grid);
    }
    case K::Instance: {
        if (it.row >= int(s.instances.size())) return {};
        const InstanceDesc& in = s.instances[size_t(it.row)];
        if (name) {
            const QString sp = in.species < s.species.size() ? QString::fromStdString(s.species[in.species].name) : tr("?");
            // Instances have no name in the scene file: the number is the place in its instances list (from 1),
            // so the ones after a deleted instance move up a number, as they do in the file.
            if (role == Qt::ToolTipRole)
                return tr("%1, instance %2 of the scene's %3 (numbered by their place in the scene file's list)")
                    .arg(sp)
                    .arg(it.row + 1)
                    .arg(s.instances.size());
            return tr("%1 #%2").arg(sp).arg(it.row + 1);
        }
        return vec3Text(in.position.x, in.position.y, in.position.z);
    }
    case K::Terrain: {
        if (name) return tr("Terrain");
        const TerrainDesc& t = s.terrain;
        if (!t.enabled()) return tr("none");
        QString text = QFileInfo(QString::fromStdString(t.dem)).fileName();
        if (t.field)
            text += tr(", %1 x %2 samples, %3 m apart")
                        .arg(t.field->layout.nx)
                        .arg(t.field->layout.nz)
                        .arg(decimalText(t.spacing));
        if (t.cells > 0) text += tr(", %1 cells a side").arg(t.cells);
        return text;
    }
    case K::Tiles: {
        if (name) return tr("Tiles");
        const TileSetDesc& ts = s.terrain.tiles;
        return tr("%1 m square, %n plant kind(s), seed %2", nullptr, int(ts.plants.size())).arg(decimalText(ts.size)).arg(ts.seed);
    }
    case K::Tiling: {
        if (name) return tr("Tiling");
        const TilingDesc& tl = s.terrain.tiling;
        const int tiles = tl.setGiven ? int(tl.set.size()) : tl.horizontal * tl.horizontal * tl.vertical * tl.vertical;
        return tr("Wang, %1 x %2 edge colours, %3 tiles, seed %4").arg(tl.horizontal).arg(tl.vertical).arg(tiles).arg(tl.seed);
    }
    case K::Density: {
        if (name) return tr("Density");
        const DensityDesc& d = s.terrain.density;
        if (!d.enabled) return tr("off: every plant grows");
        return tr("%1 at %2 m to %3 at %4 m")
            .arg(decimalText(double(d.atLower)), decimalText(d.lower), decimalText(double(d.atUpper)), decimalText(d.upper));
    }
    case K::VolumesGroup: return name ? tr("Volumes") : tr("%n volume(s)", nullptr, m_volumes);
    case K::Volume: {
        if (it.row >= int(s.volumes.size())) return {};
        const VolumeDesc& v = s.volumes[size_t(it.row)];
        if (name) return QString::fromStdString(v.name);
        QString text = tr("%1, %2").arg(QFileInfo(QString::fromStdString(v.grid)).fileName(), QString::fromStdString(v.preset));
        if (v.data) {
            const glm::ivec3 d = v.data->density.geometry.dims;
            text += tr(", %1 x %2 x %3 nodes").arg(d.x).arg(d.y).arg(d.z);
        }
        return text;
    }
    case K::None: break;
    }
    return {};
}

} // namespace sylva
