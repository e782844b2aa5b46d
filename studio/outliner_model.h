// The scene outliner: a two-level tree model over the document (groups: Species, Instances, Ground,
// Sun, Camera, Terrain, Volumes; rows under Species, Instances, Terrain and Volumes), columns Name and Details.
#pragma once

#include <QAbstractItemModel>

#include "studio/scene_document.h"

namespace sylva {

// What an outliner row stands for.
struct OutlinerItem {
    enum class Kind { None, SpeciesGroup, InstancesGroup, Ground, Sun, Camera, Species, Instance,
                      Terrain, Tiles, Tiling, Density, VolumesGroup, Volume };
    Kind kind = Kind::None;
    int row = -1;   // index into Scene::species / Scene::instances / Scene::volumes for Species / Instance / Volume
    bool operator==(const OutlinerItem&) const = default;
};

// A number as the studio shows it: fixed notation with four significant digits, at most three decimals and
// none past them: decimalText(12690.4) is "12690", 1.225e-15 gives "0", 2.5 gives "2.5", 0.0132 "0.013".
QString decimalText(double v);

class OutlinerModel : public QAbstractItemModel {
    Q_OBJECT

public:
    // Terrain: rows Tiles, Tiling, Density under it when the scene has a landscape (terrain cells); Volumes:
    // one row per volume.
    enum Group { SpeciesGroup, InstancesGroup, GroundGroup, SunGroup, CameraGroup, TerrainGroup, VolumesGroup, GroupCount };

    explicit OutlinerModel(SceneDocument* doc, QObject* parent = nullptr);

    QModelIndex index(int row, int column, const QModelIndex& parent = {}) const override;
    QModelIndex parent(const QModelIndex& child) const override;
    int rowCount(const QModelIndex& parent = {}) const override;
    int columnCount(const QModelIndex& parent = {}) const override;
    QVariant data(const QModelIndex& index, int role = Qt::DisplayRole) const override;
    QVariant headerData(int section, Qt::Orientation orientation, int role = Qt::DisplayRole) const override;
    Qt::ItemFlags flags(const QModelIndex& index) const override;

    OutlinerItem itemAt(const QModelIndex& index) const;
    QModelIndex indexOf(const OutlinerItem& item, int column = 0) const;

private:
    void onChanged(ScenePart parts);

    SceneDocument* m_doc;
    int m_species = 0, m_instances = 0;   // row counts the views know about
    int m_terrainRows = 0, m_volumes = 0;
};

} // namespace sylva
