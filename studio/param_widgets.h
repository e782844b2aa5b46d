// Form widgets made from a ParamSpec (core/base/param_spec.h): the range, the tooltip (the help line with
// range and default) and the object name come from the one declaration the CLI and the core read too.
// Widgets over a scene file's field take their range from the scene's field table the same way.
#pragma once

#include <cstdint>

#include <QString>

#include "core/base/param_spec.h"

class QDoubleSpinBox;
class QLineEdit;
class QSpinBox;

namespace sylva {

// A spin box can hold no infinity: an unbounded side stops at +-this.
inline constexpr double kWidgetLimit = 1e7;

// "Radius R of the undisplaced sphere, metres, > 0 (default 1)".
QString paramToolTip(const ParamSpec& spec);
// A real parameter (an open bound moves in by one step of the last decimal); `name` is the object name.
QDoubleSpinBox* paramSpin(const ParamSpec& spec, const QString& name, int decimals, double value);
// An integer parameter whose range fits an int.
QSpinBox* paramIntSpin(const ParamSpec& spec, const QString& name, int value);
// A seed (a range past an int's): a line edit of whole numbers; the core's validation checks the range.
QLineEdit* paramSeedEdit(const ParamSpec& spec, const QString& name, uint64_t value);
uint64_t paramSeed(const QLineEdit* edit);
void setParamSeed(QLineEdit* edit, uint64_t value);

// Spin boxes over a scene file's numbers (pipeline/scene/scene_fields.h, sceneFieldRange): the range is the
// one the file checks, looked up by the field's full key ("sun.temperature"); an open bound moves in by
// one step of the last decimal, an unbounded side stops at +-kWidgetLimit (a bound "0 or ..." admits 0).
// Built as widgets::spin (named `name`, committing on Enter or focus loss).
QDoubleSpinBox* sceneSpin(const char* key, const QString& name, int decimals, double step);
// An integer field's range, clamped to an int's.
QSpinBox* sceneIntSpin(const char* key, const QString& name);

} // namespace sylva
