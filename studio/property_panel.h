// Properties of the outliner's current item: numeric edits that become undoable scene edits.
#pragma once

#include <array>
#include <functional>
#include <map>

#include <QWidget>

#include "studio/outliner_model.h"
#include "studio/scene_document.h"

class QCheckBox;
class QComboBox;
class QDial;
class QDoubleSpinBox;
class QLabel;
class QLineEdit;
class QSpinBox;
class QStackedWidget;

namespace sylva {

class SceneItemPages;

class PropertyPanel : public QWidget {
    Q_OBJECT

public:
    explicit PropertyPanel(SceneDocument* doc, QWidget* parent = nullptr);

    void showItem(const OutlinerItem& item);
    OutlinerItem item() const { return m_item; }

    // The editors, for tests and keyboard users (named: objectName is "instance.position.x" etc.).
    QDoubleSpinBox* instancePosition(int axis) const { return m_instPos[size_t(axis)]; }
    QDoubleSpinBox* instanceRotation(int axis) const { return m_instRot[size_t(axis)]; }
    QDoubleSpinBox* instanceScale() const { return m_instScale; }
    QDial* sunAzimuthDial() const { return m_sunDial; }
    QDoubleSpinBox* sunElevation() const { return m_sunElevation; }
    QDoubleSpinBox* sunTemperature() const { return m_sunTemperature; }
    QSpinBox* speciesGrid() const { return m_speciesGrid; }
    QLineEdit* speciesName() const { return m_speciesName; }
    QComboBox* speciesPreset() const { return m_speciesPreset; }
    // The landscape's and the volumes' pages (studio/scene_item_pages.h).
    SceneItemPages* itemPages() const { return m_itemPages; }

private:
    QWidget* buildEmptyPage();
    QWidget* buildInstancePage();
    QWidget* buildSpeciesPage();
    QWidget* buildSunPage();
    QWidget* buildCameraPage();
    QWidget* buildGroundPage();
    void refresh();
    // Applies `change` to a copy of the scene and pushes it; edits of one editor in a row merge.
    void apply(QObject* editor, const QString& text, const std::function<void(Scene&)>& change);

    SceneDocument* m_doc;
    OutlinerItem m_item;
    QStackedWidget* m_stack;
    QWidget *m_emptyPage, *m_instancePage, *m_speciesPage, *m_sunPage, *m_cameraPage, *m_groundPage;
    SceneItemPages* m_itemPages;

    QComboBox* m_instSpecies;
    std::array<QDoubleSpinBox*, 3> m_instPos{}, m_instRot{};
    QDoubleSpinBox* m_instScale;

    QLabel* m_speciesTitle;
    QLabel* m_speciesSource;
    QLineEdit* m_speciesName;
    QComboBox* m_speciesPreset;
    QSpinBox* m_speciesGrid;

    QDoubleSpinBox* m_sunElevation;
    QDial* m_sunDial;
    QDoubleSpinBox* m_sunAzimuth;
    QDoubleSpinBox* m_sunTemperature;
    QDoubleSpinBox* m_sunIntensity;

    std::array<QDoubleSpinBox*, 3> m_camPos{}, m_camTarget{};
    QDoubleSpinBox* m_camFov;

    QCheckBox* m_groundEnabled;
    QDoubleSpinBox* m_groundHeight;

    EditMerger m_merger;
};

} // namespace sylva
