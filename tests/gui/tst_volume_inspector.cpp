// The lighting volume inspector against the grids read directly: the displayed slice's pixels are
// the colour-mapped grid values over the slice's range, the legend shows that range, and the text
// under the cursor names the node and its value, for every plane and channel.
#include <QApplication>
#include <QComboBox>
#include <QLabel>
#include <QMouseEvent>
#include <QSlider>
#include <QTemporaryDir>
#include <QTest>

#include "core/lb/lb_params.h"
#include "pipeline/cache/grid_cache.h"
#include "studio/volume_inspector.h"
#include "tests/common/scenes.h"

using namespace sylva;

namespace {

// A grown shrub (leaves and wood) at a 14-node grid: small, fast, every channel non-trivial.
Scene shrubScene()
{
    Scene s;
    s.species.push_back(test::shrubSpecies(14));
    s.instances.push_back(InstanceDesc{});
    return s;
}

// The test's own reading of the grids: node (i,j,k) of a channel, straight from the arrays.
float direct(const SpeciesGrids& g, VolumeChannel c, int i, int j, int k)
{
    const GridGeometry& geo = g.lighting.geometry;
    const size_t n = (size_t(i) * size_t(geo.dims.y) + size_t(j)) * size_t(geo.dims.z) + size_t(k);
    switch (c) {
    case VolumeChannel::Red: return g.lighting.rgb[n * 3 + 0];
    case VolumeChannel::Green: return g.lighting.rgb[n * 3 + 1];
    case VolumeChannel::Blue: return g.lighting.rgb[n * 3 + 2];
    case VolumeChannel::Luminance:
        return 0.2126f * g.lighting.rgb[n * 3] + 0.7152f * g.lighting.rgb[n * 3 + 1] + 0.0722f * g.lighting.rgb[n * 3 + 2];
    case VolumeChannel::Density: return g.density.density[n];
    case VolumeChannel::Wood: return g.density.woodFraction[n];
    }
    return 0.0f;
}

// Node of slice pixel (col, row): first axis right, second axis up, the third is the depth.
glm::ivec3 node(SliceAxis a, const glm::ivec3& dims, int depth, int col, int row)
{
    switch (a) {
    case SliceAxis::XY: return {col, dims.y - 1 - row, depth};
    case SliceAxis::XZ: return {col, depth, dims.z - 1 - row};
    case SliceAxis::YZ: return {depth, col, dims.z - 1 - row};
    }
    return {};
}

} // namespace

class TstVolumeInspector : public QObject {
    Q_OBJECT

    QTemporaryDir m_dir;
    std::shared_ptr<const SpeciesGrids> m_grids;

private Q_SLOTS:
    void initTestCase()
    {
        GridCache cache(m_dir.filePath("cache").toStdString());
        m_grids = std::make_shared<const SpeciesGrids>(loadSpeciesGrids(shrubScene(), 0, &cache));
        QCOMPARE(m_grids->lighting.geometry, m_grids->density.geometry);
        const auto& w = m_grids->density.woodFraction;
        QVERIFY2(*std::max_element(w.begin(), w.end()) > 0.0f, "the shrub should have wood");
    }

    void colourMapEnds()
    {
        QCOMPARE(colourMap(0.0f), qRgb(0, 0, 4));
        QCOMPARE(colourMap(1.0f), qRgb(252, 255, 164));
        QCOMPARE(colourMap(-3.0f), qRgb(0, 0, 4));
        QCOMPARE(colourMap(7.0f), qRgb(252, 255, 164));
        // Lightness rises along the ramp.
        for (int i = 1; i <= 64; ++i) QVERIFY(qGray(colourMap(float(i) / 64.0f)) >= qGray(colourMap(float(i - 1) / 64.0f)));
    }

    void slicesShowTheGrid_data()
    {
        QTest::addColumn<int>("axis");
        QTest::addColumn<int>("channel");
        for (SliceAxis a : {SliceAxis::XY, SliceAxis::XZ, SliceAxis::YZ})
            for (VolumeChannel c : {VolumeChannel::Luminance, VolumeChannel::Red, VolumeChannel::Blue, VolumeChannel::Density,
                                    VolumeChannel::Wood})
                QTest::addRow("%s %s", sliceAxisName(a), volumeChannelName(c)) << int(a) << int(c);
    }

    void slicesShowTheGrid()
    {
        QFETCH(int, axis);
        QFETCH(int, channel);
        const SliceAxis a = SliceAxis(axis);
        const VolumeChannel c = VolumeChannel(channel);
        const glm::ivec3 dims = m_grids->lighting.geometry.dims;
        const int depths = a == SliceAxis::XY ? dims.z : a == SliceAxis::XZ ? dims.y : dims.x;
        const int cols = a == SliceAxis::YZ ? dims.y : dims.x;
        const int rows = a == SliceAxis::XY ? dims.y : dims.z;

        VolumeInspector insp;
        insp.resize(520, 640);
        insp.setGrids("shrub", m_grids);
        insp.show();
        QVERIFY(QTest::qWaitForWindowExposed(&insp));
        insp.setAxis(a);
        insp.setChannel(c);
        QCOMPARE(insp.channelBox()->currentText(), QString::fromLatin1(volumeChannelName(c)));
        QCOMPARE(insp.depthSlider()->maximum(), depths - 1);
        // Scrub to a slice through the plant (its densest one along this axis) with the slider.
        int best = 0;
        double bestSum = -1.0;
        for (int d = 0; d < depths; ++d) {
            double sum = 0.0;
            for (int r = 0; r < rows; ++r)
                for (int col = 0; col < cols; ++col) {
                    const glm::ivec3 n = node(a, dims, d, col, r);
                    sum += direct(*m_grids, VolumeChannel::Density, n.x, n.y, n.z);
                }
            if (sum > bestSum) bestSum = sum, best = d;
        }
        insp.depthSlider()->setValue(best);
        QCOMPARE(insp.depth(), best);

        // The slice's range, read directly; the legend shows it.
        float lo = 1e30f, hi = -1e30f;
        QPoint loAt, hiAt;
        for (int r = 0; r < rows; ++r)
            for (int col = 0; col < cols; ++col) {
                const glm::ivec3 n = node(a, dims, best, col, r);
                const float v = direct(*m_grids, c, n.x, n.y, n.z);
                if (v < lo) lo = v, loAt = {col, r};
                if (v > hi) hi = v, hiAt = {col, r};
            }
        QVERIFY2(hi > lo, "the chosen slice should not be flat");
        QCOMPARE(insp.minLabel()->text(), QString::number(double(lo), 'g', 4));
        QCOMPARE(insp.maxLabel()->text(), QString::number(double(hi), 'g', 4));

        // What is on screen: each node a square of whole pixels.
        SliceView* view = insp.view();
        const QImage shot = view->grab().toImage();
        const QRect r = view->imageRect();
        QCOMPARE(r.width() * rows, r.height() * cols);   // square nodes
        const double px = double(r.width()) / cols;
        QVERIFY(px >= 2.0);
        auto centre = [&](QPoint p) { return QPointF(r.x() + (p.x() + 0.5) * px, r.y() + (p.y() + 0.5) * px); };
        auto shown = [&](QPoint p) { return shot.pixel(centre(p).toPoint()) & 0xffffffu; };
        // The ends of the range are the ends of the map.
        QCOMPARE(shown(loAt), colourMap(0.0f) & 0xffffffu);
        QCOMPARE(shown(hiAt), colourMap(1.0f) & 0xffffffu);
        int checked = 0;
        for (int row = 0; row < rows; row += 3)
            for (int col = 0; col < cols; col += 2) {
                const glm::ivec3 n = node(a, dims, best, col, row);
                const float v = direct(*m_grids, c, n.x, n.y, n.z);
                const QRgb want = colourMap((v - lo) / (hi - lo)) & 0xffffffu;
                QVERIFY2(shown({col, row}) == want,
                         qPrintable(QString("pixel (%1, %2), node (%3, %4, %5)").arg(col).arg(row).arg(n.x).arg(n.y).arg(n.z)));
                ++checked;
            }
        QVERIFY(checked > 20);

        // The value under the cursor: a mouse move over a node names it and its value.
        for (QPoint p : {hiAt, loAt, QPoint(cols / 2, rows / 3)}) {
            const QPointF at = centre(p);
            QMouseEvent move(QEvent::MouseMove, at, view->mapToGlobal(at), Qt::NoButton, Qt::NoButton, Qt::NoModifier);
            QApplication::sendEvent(view, &move);
            const glm::ivec3 n = node(a, dims, best, p.x(), p.y());
            const QString want = QString("node (%1, %2, %3) = %4")
                                     .arg(n.x)
                                     .arg(n.y)
                                     .arg(n.z)
                                     .arg(QString::number(double(direct(*m_grids, c, n.x, n.y, n.z)), 'g', 6));
            QCOMPARE(insp.valueLabel()->text(), want);
        }
        // Off the picture: no value.
        QMouseEvent off(QEvent::MouseMove, QPointF(1, 1), view->mapToGlobal(QPointF(1, 1)), Qt::NoButton, Qt::NoButton, Qt::NoModifier);
        QApplication::sendEvent(view, &off);
        QVERIFY(insp.valueLabel()->text().isEmpty());
    }

    // Without grids: a message, no picture, no channels; grids without lighting offer density only.
    void messagesAndMissingChannels()
    {
        VolumeInspector insp;
        insp.setMessage("Loading...");
        QVERIFY(insp.view()->image().isNull());
        QCOMPARE(insp.channelBox()->count(), 0);
        auto densityOnly = std::make_shared<SpeciesGrids>();
        densityOnly->density = m_grids->density;
        insp.setGrids("d", densityOnly);
        QCOMPARE(insp.channelBox()->count(), 2);
        QCOMPARE(insp.channel(), VolumeChannel::Density);
        QVERIFY(!insp.view()->image().isNull());
    }
};

QTEST_MAIN(TstVolumeInspector)
#include "tst_volume_inspector.moc"
