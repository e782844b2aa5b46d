// OutlinerModel: group rows with internal id 0, child rows with internal id group + 1.
#include "studio/outliner_model.h"

#include <QFileInfo>

namespace sylva {
namespace {

QString vec3Text(double x, double y, double z)
{
    return QStringLiteral("(%1, %2, %3)").arg(x, 0, 'g', 4).arg(y, 0, 'g', 4).arg(z, 0, 'g', 4);
}

} // namespace

OutlinerModel::OutlinerModel(SceneDocument* doc, QObject* parent) : QAbstractItemModel(parent), m_doc(doc)
{
    m_species = int(doc->scene().species.size());
    m_instances = int(doc->scene().instances.size());
    connect(doc, &SceneDocument::changed, this, &OutlinerModel::onChanged);
}

void OutlinerModel::onChanged(ScenePart)
{
    const Scene& s = m_doc->scene();
    const int ns = int(s.species.size()), ni = int(s.instances.size());
    if (ns != m_species || ni != m_instances) {
        beginResetModel();
        m_species = ns;
        m_instances = ni;
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
        default: return {};
        }
    }
    const int group = int(index.internalId()) - 1;
    if (group == SpeciesGroup) return {OutlinerItem::Kind::Species, index.row()};
    if (group == InstancesGroup) return {OutlinerItem::Kind::Instance, index.row()};
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
        return name ? tr("Ground") : s.ground.enabled ? tr("plane at y = %1 m").arg(s.ground.height) : tr("off");
    case K::Sun: {
        if (name) return tr("Sun");
        return tr("%1 K, intensity %2").arg(s.sun.temperature).arg(double(s.sun.intensity));
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
            return tr("%1 #%2").arg(sp).arg(it.row + 1);
        }
        return vec3Text(in.position.x, in.position.y, in.position.z);
    }
    case K::None: break;
    }
    return {};
}

} // namespace sylva
