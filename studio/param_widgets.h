// Form widgets made from a ParamSpec (core/base/param_spec.h): the range, the tooltip (the help line with
// range and default) and the object name come from the one declaration the CLI and the core read too.
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

} // namespace sylva
