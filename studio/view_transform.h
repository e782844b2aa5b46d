// The studio's display transforms (pipeline/render/display_view.h): the picture of a film through the scene's
// view, and View > View Transform, which sets the scene's render.view and render.display (one undo step, saved
// with the scene, used by Render Image and Export Render). The CPU viewport and the render window show the view;
// the CUDA viewport keeps its Reinhard pass on the device.
#pragma once

#include <optional>
#include <string>

#include <QImage>
#include <QMenu>

#include "core/render/render_cpu.h"
#include "core/scene/scene.h"
#include "pipeline/render/display_view.h"

namespace sylva {

class SceneDocument;

// The scene's view (render.display, render.view), or Sylva Reinhard when the config in use has no such view
// (a scene written under another $OCIO): the studio shows a picture either way; the menu says which.
DisplayTransform viewTransformOf(const Scene& scene);

// The picture of a film as the viewport shows it: compareImage (Reinhard) for Sylva Reinhard, else each mode's
// composed picture exposed with the key through the view (the right half in `compare`'s mode when given).
// `exposure` (not null): each mode exposed as that film's picture of the mode would be (the viewport's held
// exposure: one scale over its passes), the left half's scale in *scale when given.
QImage scenePicture(const Film& film, const Scene& scene, const std::optional<RenderMode>& compare = std::nullopt,
                    const Film* exposure = nullptr, float* scale = nullptr);

// View > View Transform: one checkable entry per view of each display of the config in use (a submenu per
// display when the config has several), the scene's checked. Entries are named "viewTransform:DISPLAY/VIEW".
class ViewTransformMenu : public QMenu {
    Q_OBJECT

public:
    ViewTransformMenu(SceneDocument* doc, QWidget* parent = nullptr);

private:
    void sync();   // checks the scene's view

    SceneDocument* m_doc;
    std::string m_defaultDisplay;   // the config's (empty when it cannot be read)
};

} // namespace sylva
