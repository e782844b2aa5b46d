// VolumeInspector: slice controls, the slice picture with its legend, the value under the cursor.
#include "studio/volume_inspector.h"

#include "studio/volume_view.h"

#include <algorithm>
#include <cmath>

#include <QComboBox>
#include <QGridLayout>
#include <QHBoxLayout>
#include <QLabel>
#include <QMouseEvent>
#include <QPainter>
#include <QSlider>
#include <QTabWidget>
#include <QVBoxLayout>

namespace sylva {

// ---- SliceView ----

SliceView::SliceView(QWidget* parent) : QWidget(parent)
{
    setMouseTracking(true);
    setMinimumSize(120, 120);
    setSizePolicy(QSizePolicy::Expanding, QSizePolicy::Expanding);
}

void SliceView::setImage(const QImage& image)
{
    m_image = image;
    update();
}

QRect SliceView::imageRect() const
{
    if (m_image.isNull()) return {};
    // Whole screen pixels per node (at least 1), centred: every node is a crisp square.
    const int scale = std::max(1, std::min(width() / m_image.width(), height() / m_image.height()));
    const QSize s = m_image.size() * scale;
    return QRect(QPoint((width() - s.width()) / 2, (height() - s.height()) / 2), s);
}

QPoint SliceView::pixelAt(const QPointF& pos) const
{
    const QRect r = imageRect();
    if (r.isEmpty()) return {-1, -1};
    const double scale = double(r.width()) / double(m_image.width());
    const int col = int(std::floor((pos.x() - r.x()) / scale));
    const int row = int(std::floor((pos.y() - r.y()) / scale));
    if (col < 0 || row < 0 || col >= m_image.width() || row >= m_image.height()) return {-1, -1};
    return {col, row};
}

void SliceView::paintEvent(QPaintEvent*)
{
    QPainter p(this);
    p.fillRect(rect(), QColor(40, 40, 44));
    if (m_image.isNull()) return;
    p.setRenderHint(QPainter::SmoothPixmapTransform, false);
    p.drawImage(imageRect(), m_image);
}

void SliceView::mouseMoveEvent(QMouseEvent* event) { Q_EMIT hovered(pixelAt(event->position())); }

void SliceView::leaveEvent(QEvent*) { Q_EMIT hovered({-1, -1}); }

// ---- VolumeInspector ----

VolumeInspector::VolumeInspector(QWidget* parent) : QWidget(parent)
{
    setObjectName("volumeInspector");
    m_title = new QLabel;
    m_title->setWordWrap(true);
    m_axis = new QComboBox;
    m_axis->setObjectName("inspectorAxis");
    for (SliceAxis a : {SliceAxis::XY, SliceAxis::XZ, SliceAxis::YZ}) m_axis->addItem(QString::fromLatin1(sliceAxisName(a)), int(a));
    m_channel = new QComboBox;
    m_channel->setObjectName("inspectorChannel");
    m_depth = new QSlider(Qt::Horizontal);
    m_depth->setObjectName("inspectorDepth");
    m_depthLabel = new QLabel;
    m_depthLabel->setMinimumWidth(70);
    m_view = new SliceView;
    m_view->setObjectName("inspectorSlice");
    m_legend = new QLabel;
    m_legend->setFixedHeight(14);
    m_legend->setScaledContents(true);
    m_legend->setPixmap(QPixmap::fromImage(legendImage(256, 1)));
    m_min = new QLabel;
    m_max = new QLabel;
    m_max->setAlignment(Qt::AlignRight | Qt::AlignVCenter);
    m_value = new QLabel;
    m_value->setObjectName("inspectorValue");
    m_value->setTextInteractionFlags(Qt::TextSelectableByMouse);

    auto* controls = new QGridLayout;
    controls->addWidget(new QLabel(tr("Plane")), 0, 0);
    controls->addWidget(m_axis, 0, 1);
    controls->addWidget(new QLabel(tr("Channel")), 0, 2);
    controls->addWidget(m_channel, 0, 3);
    controls->addWidget(new QLabel(tr("Depth")), 1, 0);
    controls->addWidget(m_depth, 1, 1, 1, 2);
    controls->addWidget(m_depthLabel, 1, 3);
    auto* legendRow = new QHBoxLayout;
    legendRow->addWidget(m_min);
    legendRow->addWidget(m_legend, 1);
    legendRow->addWidget(m_max);
    auto* slices = new QWidget;
    auto* sl = new QVBoxLayout(slices);
    sl->setContentsMargins(0, 0, 0, 0);
    sl->addLayout(controls);
    sl->addWidget(m_view, 1);
    sl->addLayout(legendRow);
    sl->addWidget(m_value);

    // 3D: lighting choice and extinction over the volume view (made on first show).
    m_volumePage = new QWidget;
    auto* vl = new QVBoxLayout(m_volumePage);
    vl->setContentsMargins(0, 0, 0, 0);
    auto* vc = new QGridLayout;
    m_volumeLighting = new QComboBox;
    m_volumeLighting->setObjectName("volumeLighting");
    m_volumeLighting->addItem(tr("single scattering of the sun"));
    m_volumeLighting->addItem(tr("LB lighting"));
    m_volumeLighting->setToolTip(tr("Single scattering: the sun's light marched through the density toward each sample; "
                                    "LB lighting: each sample lit by the LB grid's luminance"));
    m_extinction = new QSlider(Qt::Horizontal);
    m_extinction->setObjectName("volumeExtinction");
    m_extinction->setRange(1, 60);
    m_extinction->setValue(12);
    m_extinction->setToolTip(tr("Extinction of density 1 per grid length"));
    vc->addWidget(new QLabel(tr("Light")), 0, 0);
    vc->addWidget(m_volumeLighting, 0, 1);
    vc->addWidget(new QLabel(tr("Opacity")), 1, 0);
    vc->addWidget(m_extinction, 1, 1);
    vl->addLayout(vc);
    vl->addStretch(1);

    m_tabs = new QTabWidget;
    m_tabs->addTab(slices, tr("Slices"));
    m_tabs->addTab(m_volumePage, tr("3D"));
    connect(m_tabs, &QTabWidget::currentChanged, this, [this](int index) {
        if (index == 1) show3D();
    });

    auto* layout = new QVBoxLayout(this);
    layout->addWidget(m_title);
    layout->addWidget(m_tabs, 1);

    connect(m_axis, &QComboBox::currentIndexChanged, this, [this] {
        updateDepthRange();
        updateSlice();
    });
    connect(m_channel, &QComboBox::currentIndexChanged, this, [this] { updateSlice(); });
    connect(m_depth, &QSlider::valueChanged, this, [this] { updateSlice(); });
    connect(m_view, &SliceView::hovered, this, &VolumeInspector::showValue);
    updateChannels();
    setMessage(tr("Select a species (or one of its instances) to inspect its lighting grids."));
}

void VolumeInspector::show3D()
{
    if (!m_volume) {
        m_volume = new VolumeView;
        auto* vl = static_cast<QVBoxLayout*>(m_volumePage->layout());
        vl->insertWidget(1, m_volume, 1);
        vl->takeAt(2);   // the stretch that held the place
        connect(m_volumeLighting, &QComboBox::currentIndexChanged, m_volume, [this](int i) {
            m_volume->setLighting(i == 1 ? VolumeView::Lighting::Lb : VolumeView::Lighting::SingleScattering);
        });
        connect(m_extinction, &QSlider::valueChanged, m_volume, [this](int v) { m_volume->setExtinction(float(v)); });
        m_volume->setExtinction(float(m_extinction->value()));
        m_volume->setLighting(m_volumeLighting->currentIndex() == 1 ? VolumeView::Lighting::Lb : VolumeView::Lighting::SingleScattering);
        m_volume->setGrids(m_grids);
    }
    m_tabs->setCurrentIndex(1);
}

QString VolumeInspector::valueText(const glm::ivec3& node, float value)
{
    return tr("node (%1, %2, %3) = %4").arg(node.x).arg(node.y).arg(node.z).arg(QString::number(double(value), 'g', 6));
}

void VolumeInspector::setGrids(const QString& species, std::shared_ptr<const SpeciesGrids> grids)
{
    m_species = species;
    m_grids = std::move(grids);
    if (m_grids) {
        const GridGeometry& g = geometry();
        m_title->setText(tr("%1: %2 x %3 x %4 nodes, %5 m apart")
                             .arg(species)
                             .arg(g.dims.x)
                             .arg(g.dims.y)
                             .arg(g.dims.z)
                             .arg(g.spacing, 0, 'g', 4));
    }
    updateChannels();
    updateDepthRange();
    updateSlice();
    if (m_volume) m_volume->setGrids(m_grids);
}

void VolumeInspector::setMessage(const QString& message)
{
    m_grids.reset();
    m_species.clear();
    m_title->setText(message);
    updateChannels();
    updateDepthRange();
    updateSlice();
    if (m_volume) m_volume->setGrids(nullptr);
}

const GridGeometry& VolumeInspector::geometry() const
{
    return m_grids->lighting.rgb.empty() ? m_grids->density.geometry : m_grids->lighting.geometry;
}

SliceAxis VolumeInspector::axis() const { return SliceAxis(m_axis->currentData().toInt()); }

VolumeChannel VolumeInspector::channel() const
{
    return m_channel->currentIndex() < 0 ? VolumeChannel::Luminance : VolumeChannel(m_channel->currentData().toInt());
}

int VolumeInspector::depth() const { return m_depth->value(); }

void VolumeInspector::setAxis(SliceAxis axis) { m_axis->setCurrentIndex(m_axis->findData(int(axis))); }

void VolumeInspector::setChannel(VolumeChannel channel)
{
    const int i = m_channel->findData(int(channel));
    if (i >= 0) m_channel->setCurrentIndex(i);
}

void VolumeInspector::setDepth(int depth) { m_depth->setValue(depth); }

void VolumeInspector::updateChannels()
{
    const VolumeChannel keep = channel();
    const QSignalBlocker block(m_channel);
    m_channel->clear();
    if (m_grids)
        for (VolumeChannel c : {VolumeChannel::Luminance, VolumeChannel::Red, VolumeChannel::Green, VolumeChannel::Blue,
                                VolumeChannel::Density, VolumeChannel::Wood})
            if (hasChannel(*m_grids, c)) m_channel->addItem(QString::fromLatin1(volumeChannelName(c)), int(c));
    const int i = m_channel->findData(int(keep));
    m_channel->setCurrentIndex(i >= 0 ? i : 0);
    m_channel->setEnabled(m_channel->count() > 0);
}

void VolumeInspector::updateDepthRange()
{
    const QSignalBlocker block(m_depth);
    if (!m_grids) {
        m_depth->setRange(0, 0);
        m_depth->setEnabled(false);
        return;
    }
    const int n = sliceDepthCount(geometry(), axis());
    const bool fresh = m_depth->maximum() != n - 1;
    m_depth->setRange(0, n - 1);
    if (fresh) m_depth->setValue(n / 2);   // a new grid or plane starts in the middle
    m_depth->setEnabled(true);
}

void VolumeInspector::updateSlice()
{
    m_value->clear();
    if (!m_grids || m_channel->count() == 0) {
        m_slice = Slice();
        m_view->setImage({});
        m_min->clear();
        m_max->clear();
        m_depthLabel->clear();
        Q_EMIT sliceChanged();
        return;
    }
    m_slice = extractSlice(*m_grids, channel(), axis(), depth());
    m_view->setImage(sliceImage(m_slice));
    m_min->setText(QString::number(double(m_slice.min), 'g', 4));
    m_max->setText(QString::number(double(m_slice.max), 'g', 4));
    static const char* kDepthAxis[3] = {"z", "y", "x"};
    m_depthLabel->setText(QStringLiteral("%1 = %2 / %3").arg(QLatin1String(kDepthAxis[int(axis())])).arg(depth()).arg(m_depth->maximum()));
    Q_EMIT sliceChanged();
}

void VolumeInspector::showValue(QPoint pixel)
{
    if (!m_grids || pixel.x() < 0 || m_slice.values.empty()) {
        m_value->clear();
        return;
    }
    const glm::ivec3 node = sliceNode(geometry(), axis(), depth(), pixel.x(), pixel.y());
    m_value->setText(valueText(node, nodeValue(*m_grids, channel(), node)));
}

} // namespace sylva
