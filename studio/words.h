// The studio's words for artists: the names the controls show for the renderer's settings (the values
// underneath stay the scene file's) and the tooltips of the panels' controls, kept in one place.
#pragma once

#include <QDial>
#include <QString>

#include "core/scene/scene.h"

class QWidget;

namespace sylva {

// What a render mode shows in the toolbar: All, Direct only, Flat ambient, Bounce only.
QString renderModeLabel(RenderMode mode);
// What it does, in a sentence.
QString renderModeToolTip(RenderMode mode);

// Sets the tooltip of every control under root whose object name (the scene key it edits, e.g.
// "sun.elevation", "camera.position.x") the studio has words for. Returns how many it set.
int applyToolTips(QWidget* root);
// The tooltip for a control's object name (an axis suffix .x/.y/.z or an index .N read as the field); empty if none.
QString controlToolTip(const QString& objectName);

// The sun's azimuth dial, a map seen from above with north up: 0 .. 359 degrees of the scene's azimuth
// (0 south, +Z, at the bottom; 90 east, +X, at the right; growing counter-clockwise on the screen), with the
// compass points N, E, S and W drawn at their azimuths.
class CompassDial : public QDial {
public:
    explicit CompassDial(QWidget* parent = nullptr);
    // Where azimuth `azimuthDeg` lies on the dial's rim (where its compass letter is drawn), widget pixels.
    QPointF labelCentre(double azimuthDeg) const;

protected:
    void paintEvent(QPaintEvent* event) override;
};

} // namespace sylva
