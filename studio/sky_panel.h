// The sky panel: the sky model (constant, Preetham, HDR map) with its turbidity, map
// file, rotation and intensity, the virtual lights and their interleaving, the sky in the LB boundary, and the sun by dial (elevation,
// azimuth) or by date, time, time zone and place with a time slider; the look of the picture: exposure (stops
// over the render's key), leaf tint and ground colour. Every change is an undoable edit
// of the document (edits of one control less than a second apart merge into one step).
#pragma once

#include <array>
#include <functional>
#include <map>

#include <QWidget>

#include "studio/scene_document.h"

class QCheckBox;
class QComboBox;
class QDateEdit;
class QDial;
class QDoubleSpinBox;
class QLabel;
class QLineEdit;
class QPushButton;
class QSlider;
class QSpinBox;
class QStackedWidget;
class QTimeEdit;

namespace sylva {

class SkyPanel : public QWidget {
    Q_OBJECT

public:
    explicit SkyPanel(SceneDocument* doc, QWidget* parent = nullptr);

    // Asked for a map file when the model becomes `hdri` without one or on "Choose..." (default: a file
    // dialog); an empty answer changes nothing. Tests set their own.
    void setMapChooser(std::function<QString()> chooser) { m_chooseMap = std::move(chooser); }
    // Makes `path` the sky's map (and the model `hdri`): one undo step.
    void setMapPath(const QString& path);

    // The controls, named by objectName ("sky.kind", "sun.timeSlider", ...), for tests and keyboard users.
    QComboBox* kind() const { return m_kind; }
    QDoubleSpinBox* turbidity() const { return m_turbidity; }
    QLineEdit* mapPath() const { return m_path; }
    QDoubleSpinBox* rotation() const { return m_rotation; }
    QDoubleSpinBox* mapIntensity() const { return m_intensity; }
    QSpinBox* lights() const { return m_lights; }
    QSpinBox* interleave() const { return m_interleave; }
    QCheckBox* lbSky() const { return m_lbSky; }
    QCheckBox* aerialPerspective() const { return m_aerial; }
    QComboBox* sunMode() const { return m_sunMode; }
    QDoubleSpinBox* sunElevation() const { return m_elevation; }
    QDial* sunAzimuthDial() const { return m_dial; }
    QDoubleSpinBox* sunAzimuth() const { return m_azimuth; }
    QDateEdit* sunDate() const { return m_date; }
    QTimeEdit* sunTime() const { return m_time; }
    QSlider* timeSlider() const { return m_timeSlider; }
    QDoubleSpinBox* timeZone() const { return m_zone; }
    QDoubleSpinBox* latitude() const { return m_latitude; }
    QDoubleSpinBox* longitude() const { return m_longitude; }
    // Exposure in stops (EV): the render's key is 0.18 x 2^EV (render.key), so +1 doubles the exposure scale.
    QDoubleSpinBox* exposure() const { return m_exposure; }
    // Leaf tint (render.leaf_tint) and ground colour (ground.color), channel c = 0, 1, 2 (red, green, blue).
    QDoubleSpinBox* leafTint(int c) const { return m_leafTint[size_t(c)]; }
    QDoubleSpinBox* groundColor(int c) const { return m_groundColor[size_t(c)]; }
    // The last refused edit's reason (a map that cannot be read, a sun the model refuses), or empty.
    QString status() const;

private:
    void refresh();
    void apply(QObject* editor, const QString& text, const std::function<void(Scene&)>& change);
    // The sun by date and place from the controls, into s (direction computed by NOAA's algorithm).
    void applyPlace(QObject* editor, const std::function<void(sky::SunPlace&)>& change);
    void chooseMap();

    SceneDocument* m_doc;
    std::function<QString()> m_chooseMap;
    QComboBox* m_kind;
    QDoubleSpinBox* m_turbidity;
    QLineEdit* m_path;
    QPushButton* m_browse;
    QDoubleSpinBox *m_rotation, *m_intensity;
    QSpinBox *m_lights, *m_interleave;
    QCheckBox* m_lbSky;
    QCheckBox* m_aerial;
    QComboBox* m_sunMode;
    QStackedWidget* m_sunPages;
    QDoubleSpinBox *m_elevation, *m_azimuth;
    QDial* m_dial;
    QDateEdit* m_date;
    QTimeEdit* m_time;
    QSlider* m_timeSlider;
    QDoubleSpinBox *m_zone, *m_latitude, *m_longitude;
    QLabel* m_sunInfo;
    QDoubleSpinBox* m_exposure;
    std::array<QDoubleSpinBox*, 3> m_leafTint{}, m_groundColor{};
    QLabel* m_status;
    QWidget *m_preethamRows, *m_mapRows, *m_lightRows;

    EditMerger m_merger;
};

} // namespace sylva
