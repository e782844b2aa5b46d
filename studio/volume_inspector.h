// The lighting volume inspector: slices (XY/XZ/YZ) of the selected species' density and LB lighting
// grids, a depth slider, channel select, colour map with legend, and the node under the cursor.
#pragma once

#include <memory>

#include <QImage>
#include <QWidget>

#include "studio/volume_slice.h"

class QComboBox;
class QLabel;
class QSlider;
class QTabWidget;

namespace sylva {

// One slice picture scaled to fit (whole nodes, aspect kept, no smoothing); reports the node pixel
// under the cursor.
class SliceView : public QWidget {
    Q_OBJECT

public:
    explicit SliceView(QWidget* parent = nullptr);
    void setImage(const QImage& image);
    QImage image() const { return m_image; }
    // Where the picture is drawn, widget coordinates (empty without a picture).
    QRect imageRect() const;
    // The slice pixel (column, row) at a widget position, or (-1, -1) outside the picture.
    QPoint pixelAt(const QPointF& pos) const;
    QSize sizeHint() const override { return {360, 360}; }

Q_SIGNALS:
    void hovered(QPoint pixel);   // (-1, -1) when the cursor leaves the picture

protected:
    void paintEvent(QPaintEvent* event) override;
    void mouseMoveEvent(QMouseEvent* event) override;
    void leaveEvent(QEvent* event) override;

private:
    QImage m_image;
};

class VolumeView;

class VolumeInspector : public QWidget {
    Q_OBJECT

public:
    explicit VolumeInspector(QWidget* parent = nullptr);

    // Shows a species' grids (kept: the inspector reads them on every slice change).
    void setGrids(const QString& species, std::shared_ptr<const SpeciesGrids> grids);
    // No grids, a message instead ("Select a species", "Loading...").
    void setMessage(const QString& message);
    std::shared_ptr<const SpeciesGrids> grids() const { return m_grids; }
    QString species() const { return m_species; }

    SliceAxis axis() const;
    VolumeChannel channel() const;
    int depth() const;
    void setAxis(SliceAxis axis);
    void setChannel(VolumeChannel channel);   // ignored when the grids lack it
    void setDepth(int depth);
    const Slice& slice() const { return m_slice; }

    QComboBox* axisBox() const { return m_axis; }
    QComboBox* channelBox() const { return m_channel; }
    QSlider* depthSlider() const { return m_depth; }
    SliceView* view() const { return m_view; }
    QLabel* valueLabel() const { return m_value; }
    QLabel* minLabel() const { return m_min; }
    QLabel* maxLabel() const { return m_max; }
    QLabel* titleLabel() const { return m_title; }
    // The "Slices" and "3D" pages; the 3D view (a QOpenGLWidget) is made when its page is first shown.
    QTabWidget* tabs() const { return m_tabs; }
    VolumeView* volumeView() const { return m_volume; }
    QComboBox* volumeLightingBox() const { return m_volumeLighting; }
    void show3D();

    // "node (i, j, k) = value" as the value label shows it.
    static QString valueText(const glm::ivec3& node, float value);

Q_SIGNALS:
    void sliceChanged();

private:
    void updateChannels();
    void updateDepthRange();
    void updateSlice();
    void showValue(QPoint pixel);
    const GridGeometry& geometry() const;

    QString m_species;
    std::shared_ptr<const SpeciesGrids> m_grids;
    Slice m_slice;
    QLabel* m_title;
    QComboBox* m_axis;
    QComboBox* m_channel;
    QSlider* m_depth;
    QLabel* m_depthLabel;
    SliceView* m_view;
    QLabel* m_legend;
    QLabel* m_min;
    QLabel* m_max;
    QLabel* m_value;
    QTabWidget* m_tabs;
    QWidget* m_volumePage;
    QComboBox* m_volumeLighting;
    QSlider* m_extinction;
    VolumeView* m_volume = nullptr;
};

} // namespace sylva
