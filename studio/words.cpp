// The studio's words for artists (words.h).
#include "studio/words.h"

#include <cmath>

#include <QCoreApplication>
#include <QHash>
#include <QPainter>
#include <QRegularExpression>
#include <QWidget>

namespace sylva {
namespace {

QString tr(const char* text) { return QCoreApplication::translate("sylva::Words", text); }

const QHash<QString, QString>& tips()
{
    static const QHash<QString, QString> table = {
        // Toolbar
        {"renderMode", tr("Which light the picture shows: All (sunlight and the light bounced between the leaves), "
                          "Direct only (sunlight and shadows), Flat ambient (sunlight plus an even fill light of the same "
                          "overall brightness), Bounce only (the light scattered through the crowns alone)")},
        {"integrator", tr("How light is computed: the lighting model (fast: direct light with shadows plus the light "
                          "bounced inside the crowns, solved once per species) or the path tracer (every bounce traced, "
                          "the reference the model is measured against; slower and grainy at first, no clouds or smoke yet)")},
        {"compareToggle", tr("Split the viewport: the left half shows the light chosen on the left, the right half the "
                             "light chosen here, from one render")},
        {"compareMode", tr("The light shown in the right half of the split viewport")},
        {"viewportSamples", tr("How many samples per pixel the viewport adds up while the view stays still: more is "
                               "smoother and takes longer (the counter and the bar at the bottom of the viewport show how "
                               "far it is). The lowest setting stops where the finished render would")},
        // Instance
        {"instance.species", tr("The species this tree is an instance of")},
        {"instance.position", tr("Where the tree stands, metres: x (east), y (up), z (south)")},
        {"instance.rotation", tr("How the tree is turned, degrees about the x, y (up) and z axes")},
        {"instance.scale", tr("Size of this tree relative to its species' model (1: as modelled)")},
        // Species
        {"species.name", tr("The species' name (unique in the scene)")},
        {"species.preset", tr("Light transport preset: how leaves and wood of this species let light through and "
                              "scatter it (leaf, needle, ...); changing it lights the species again")},
        {"species.grid", tr("Lighting detail: grid points along the species' longest side. More is finer and "
                            "slower to compute")},
        // Sun
        {"sun.elevation", tr("Height of the sun above the horizon, degrees (90: overhead, 0: on the horizon)")},
        {"sun.azimuth", tr("Compass direction of the sun, degrees: 0 south, 90 east, 180 north, 270 west")},
        {"sun.azimuthDial", tr("Drag to turn the sun around the compass (N, E, S, W)")},
        {"sun.temperature", tr("Colour of sunlight as a temperature, kelvin: lower is warmer (sunset about 3000 K), "
                               "higher cooler (midday about 5800 K)")},
        {"sun.intensity", tr("Brightness of the sun (1: normal daylight)")},
        {"sun.mode", tr("Place the sun by its angles, or by the date, time and place on Earth")},
        {"sun.date", tr("The day of the year the sun is placed for")},
        {"sun.time", tr("Local clock time the sun is placed for")},
        {"sun.timeSlider", tr("Local clock time: drag to move the sun through the day")},
        {"sun.timezone", tr("Hours of local time ahead of UTC (east +: 1 for CET, 2 for CEST)")},
        {"sun.latitude", tr("Latitude of the place, degrees north (south negative)")},
        {"sun.longitude", tr("Longitude of the place, degrees east (west negative)")},
        // Camera
        {"camera.position", tr("Where the camera stands, metres: x (east), y (up), z (south)")},
        {"camera.target", tr("The point the camera looks at, metres")},
        {"camera.fov", tr("How much the camera sees from top to bottom, degrees: smaller zooms in (a telephoto), "
                          "larger shows more (a wide angle)")},
        // Ground
        {"ground.enabled", tr("A flat ground under the trees (it catches their shadows)")},
        {"ground.height", tr("Height of the ground, metres")},
        // Sky
        {"sky.kind", tr("What the sky is: a colour backdrop (seen behind the trees, lights nothing), a clear-sky "
                        "model that follows the sun, a photographed sky (HDR map), or an even sky light of one "
                        "colour that lights the plants from every direction")},
        {"sky.turbidity", tr("Haze of the atmosphere: 2 a very clear sky, 10 a hazy one")},
        {"sky.aerial_perspective", tr("The air between the camera and the land: distant hills fade toward the sky's colour at "
                                      "the horizon, more with a higher turbidity (seen over kilometres; the quality presets turn "
                                      "it on for terrains)")},
        {"sky.path", tr("The HDR picture of the sky (.exr or .hdr)")},
        {"sky.choose", tr("Choose the HDR picture of the sky")},
        {"sky.rotation", tr("Turns the sky picture about the up axis, degrees")},
        {"sky.intensity", tr("Brightness of the sky picture (1: as recorded)")},
        {"sky.lights", tr("Sky samples: how many directions the sky's light comes from in each render. More is "
                          "smoother and slower")},
        {"sky.interleave", tr("Sky sample groups: the sky samples are split into this many groups that take turns "
                              "over neighbouring pixels and passes, so each pass is faster; the picture evens out "
                              "as passes add up")},
        // Look
        {"render.exposure", tr("Brightness of the picture in stops: +1 lets in twice the light, -1 half (0: the "
                               "automatic exposure). The rendered image uses it too")},
        {"render.leafTint", tr("Colours the leaves of every tree: red, green and blue multiply the leaves' own colour "
                               "(1 1 1: as modelled; lower green and blue for autumn yellows)")},
        {"ground.color", tr("Colour of the ground: how much red, green and blue light it reflects (0 to 1)")},
        {"lighting.boundary", tr("Let skylight, not only sunlight, scatter through the crowns (the species are lit again)")},
        // Terrain and landscape
        {"terrain.snowLine", tr("Height above which the ground is snow, metres (0: no snow)")},
        {"terrain.rockSlope", tr("Slopes steeper than this are bare rock, degrees")},
        {"tiles.size", tr("The side of a square tile of plants, metres (the terrain's cells stretch it over themselves)")},
        {"tiles.seed", tr("A number that shuffles where the plants stand in the tiles")},
        {"tiles.spacing", tr("Least distance between two plants of this kind, metres: larger is sparser")},
        {"tiling.horizontal", tr("Edge colours of the tiles south to north: more colours, more varied tiling")},
        {"tiling.vertical", tr("Edge colours of the tiles east to west: more colours, more varied tiling")},
        {"tiling.seed", tr("A number that shuffles which tile lies where")},
        {"density.enabled", tr("Thin the plants out with altitude between the two tree lines")},
        {"density.lower", tr("Height of the lower tree line, metres")},
        {"density.upper", tr("Height of the upper tree line, metres")},
        {"density.atLower", tr("Share of the plants kept at the lower tree line (1: all)")},
        {"density.atUpper", tr("Share of the plants kept at the upper tree line (0: none)")},
        // Volumes
        {"volume.preset", tr("What the volume is made of: cloud, smoke or clear acrylic (pmma)")},
        {"volume.tracer", tr("How the volume is lit: by its lighting grid (scattered light), by a shadow toward the "
                             "sun, or both")},
        {"volume.densityScale", tr("Thickness of the volume: its density multiplied by this")},
        {"volume.position", tr("Where the volume lies, metres")},
        {"volume.scale", tr("Size of the volume")},
    };
    return table;
}

} // namespace

QString renderModeLabel(RenderMode mode)
{
    switch (mode) {
    case RenderMode::Full: return tr("All");
    case RenderMode::Local: return tr("Direct only");
    case RenderMode::Ambient: return tr("Flat ambient");
    case RenderMode::Lb: return tr("Bounce only");
    }
    return QString();
}

QString renderModeToolTip(RenderMode mode)
{
    switch (mode) {
    case RenderMode::Full: return tr("Sunlight with shadows plus the light bounced between the leaves");
    case RenderMode::Local: return tr("Sunlight with shadows alone");
    case RenderMode::Ambient: return tr("Sunlight with shadows plus an even fill light of the same overall brightness");
    case RenderMode::Lb: return tr("The light bounced and scattered through the crowns alone");
    }
    return QString();
}

QString controlToolTip(const QString& objectName)
{
    const QHash<QString, QString>& t = tips();
    if (const auto it = t.find(objectName); it != t.end()) return *it;
    // camera.position.x, tiles.spacing.3: the field's words.
    static const QRegularExpression suffix(QStringLiteral("\\.([xyz]|\\d+)$"));
    QString field = objectName;
    field.remove(suffix);
    if (const auto it = t.find(field); it != t.end()) return *it;
    return QString();
}

int applyToolTips(QWidget* root)
{
    int set = 0;
    for (QWidget* w : root->findChildren<QWidget*>()) {
        const QString tip = controlToolTip(w->objectName());
        if (tip.isEmpty()) continue;
        w->setToolTip(tip);
        ++set;
    }
    return set;
}

CompassDial::CompassDial(QWidget* parent) : QDial(parent)
{
    setRange(0, 359);
    setWrapping(true);
    setInvertedAppearance(true);   // counter-clockwise: east (+X) to the right of south, north at the top
    setNotchesVisible(true);
    setNotchTarget(15.0);
    setFixedSize(72, 72);
}

QPointF CompassDial::labelCentre(double azimuthDeg) const
{
    // Value 0 at the bottom, growing counter-clockwise on the screen (inverted appearance).
    const double a = (-90.0 + azimuthDeg) * 3.14159265358979323846 / 180.0;
    const double r = 0.5 * std::min(width(), height()) - 9.0;
    return {0.5 * width() + r * std::cos(a), 0.5 * height() - r * std::sin(a)};
}

void CompassDial::paintEvent(QPaintEvent* event)
{
    QDial::paintEvent(event);
    QPainter p(this);
    QFont f = p.font();
    f.setPixelSize(9);
    f.setBold(true);
    p.setFont(f);
    p.setPen(palette().color(QPalette::WindowText));
    const struct {
        const char* name;
        double azimuth;
    } points[] = {{"S", 0.0}, {"E", 90.0}, {"N", 180.0}, {"W", 270.0}};   // the scene's azimuths (+Z south, +X east)
    for (const auto& pt : points) {
        const QPointF c = labelCentre(pt.azimuth);
        p.drawText(QRectF(c.x() - 6.0, c.y() - 6.0, 12.0, 12.0), Qt::AlignCenter, QString::fromLatin1(pt.name));
    }
}

} // namespace sylva
