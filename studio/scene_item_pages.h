// The property pages of the landscape (terrain, tiles, tiling, density) and of a volume: editors whose
// changes become undoable scene edits through the property panel's apply (one undo step per gesture).
#pragma once

#include <array>
#include <functional>
#include <vector>

#include <QStackedWidget>

#include "studio/outliner_model.h"
#include "studio/scene_document.h"

class QCheckBox;
class QComboBox;
class QDoubleSpinBox;
class QFormLayout;
class QLabel;
class QSpinBox;

namespace sylva {

class SceneItemPages : public QStackedWidget {
    Q_OBJECT

public:
    // apply: the property panel's edit (editor for merging, undo text, change to a copy of the scene).
    using Apply = std::function<void(QObject* editor, const QString& text, const std::function<void(Scene&)>& change)>;
    SceneItemPages(SceneDocument* doc, Apply apply, QWidget* parent = nullptr);

    // Shows the page of `item` (Terrain, Tiles, Tiling, Density, Volume) with the scene's values; false
    // when the item is none of them or no longer exists (a volume row past the end, no terrain).
    bool showItem(const OutlinerItem& item, const Scene& scene);

    // Editors, named for tests and scripts: "terrain.snowLine", "tiles.size", "tiles.seed",
    // "tiles.spacing.N", "tiling.horizontal", "tiling.vertical", "tiling.seed", "density.enabled",
    // "density.lower", "density.upper", "density.atLower", "density.atUpper", "volume.preset",
    // "volume.densityScale", "volume.tracer", "volume.position.x|y|z", "volume.scale".
    QDoubleSpinBox* densityLower() const { return m_densityLower; }
    QDoubleSpinBox* tileSize() const { return m_tileSize; }

private:
    QWidget* buildTerrainPage();
    QWidget* buildTilesPage();
    QWidget* buildTilingPage();
    QWidget* buildDensityPage();
    QWidget* buildVolumePage();
    void rebuildPlantRows(const Scene& scene);

    SceneDocument* m_doc;
    Apply m_apply;
    OutlinerItem m_item;
    QWidget *m_terrainPage, *m_tilesPage, *m_tilingPage, *m_densityPage, *m_volumePage;

    QLabel* m_terrainInfo;
    QDoubleSpinBox *m_snowLine, *m_rockSlope;

    QDoubleSpinBox* m_tileSize;
    QSpinBox* m_tileSeed;
    QFormLayout* m_plantForm;
    std::vector<QDoubleSpinBox*> m_plantSpacing;

    QSpinBox *m_tilingH, *m_tilingV, *m_tilingSeed;
    QLabel* m_tilingInfo;

    QCheckBox* m_densityOn;
    QDoubleSpinBox *m_densityLower, *m_densityUpper, *m_densityAtLower, *m_densityAtUpper;

    QLabel* m_volumeInfo;
    QComboBox *m_volumePreset, *m_volumeTracer;
    QDoubleSpinBox* m_volumeDensityScale;
    std::array<QDoubleSpinBox*, 3> m_volumePos{};
    QDoubleSpinBox* m_volumeScale;
};

} // namespace sylva
