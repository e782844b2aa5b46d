// Edit > Scatter Instances: many instances of a species over a rectangle of the ground
// (scatterInstances, pipeline/scene/scatter.h) as one undo step, and its form.
#pragma once

#include <functional>

#include "core/mesh/triangle_mesh.h"
#include "pipeline/scene/scatter.h"
#include "studio/studio_controller.h"

class QWidget;

namespace sylva {

class SceneDocument;

class ScatterTool : public StudioController {
    Q_OBJECT

public:
    // selectedSpecies: the species the selection points at (-1: none), the form's first choice.
    // window: the parent of the form.
    ScatterTool(SceneDocument* doc, std::function<int()> selectedSpecies, QWidget* window, QObject* parent = nullptr);

    // Adds spec.count instances of a species scattered over a rectangle as one undo step (the first
    // instances of a scene also frame the camera on the rectangle); false (and an error) for a bad
    // spec or species. None lies within spec.clearRadius of spec.clearCentre; those that found no room
    // outside it are left out and the log says how many. frame: frameRequested afterwards (the window
    // frames the whole scene, a second undo step).
    bool scatter(const ScatterSpec& spec, bool frame = false);
    // The least clearance kept around the camera's eye by default, metres.
    static constexpr double kDefaultClearance = 3.0;
    // The form's starting values: the selected species, 100 instances over the instances' footprint
    // (20 m around the origin when there are none) on the ground, a clearance about the camera's eye of
    // kDefaultClearance or, when the species' model is loaded and its crown is wider, the crown's reach
    // at the largest scale (crownReach x scaleMax), so no crown starts at the lens.
    ScatterSpec defaultScatter() const;
    // How far a species' model reaches from its trunk sideways, metres: the largest horizontal distance of
    // its box's corners from the species origin (0 for an invalid box).
    static double crownReach(const Bounds3& speciesBox);
    // Where the tool reads a species' model box (species frame; invalid: not loaded). Default: none known.
    void setSpeciesBox(std::function<Bounds3(int species)> box) { m_speciesBox = std::move(box); }
    // The form (ScatterDialog), then scatter; an error when the scene has no species.
    void scatterDialog();

Q_SIGNALS:
    // A scatter asked to frame its result (View > Frame All).
    void frameRequested();

private:
    SceneDocument* m_doc;
    std::function<int()> m_selectedSpecies;
    std::function<Bounds3(int species)> m_speciesBox;
    QWidget* m_window;
};

} // namespace sylva
