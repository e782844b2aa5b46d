// Spin boxes and seed fields from ParamSpecs.
#include "studio/param_widgets.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <QDoubleSpinBox>
#include <QLineEdit>
#include <QRegularExpressionValidator>
#include <QSpinBox>

#include "pipeline/scene/scene_fields.h"
#include "studio/form_widgets.h"

namespace sylva {

QString paramToolTip(const ParamSpec& spec)
{
    QString t = QString::fromStdString(paramHelp(spec));
    if (!t.isEmpty()) t[0] = t[0].toUpper();
    return t;
}

QDoubleSpinBox* paramSpin(const ParamSpec& spec, const QString& name, int decimals, double value)
{
    const double step = std::pow(10.0, -decimals);
    auto* s = new QDoubleSpinBox;
    s->setObjectName(name);
    s->setDecimals(decimals);
    s->setRange(std::max(spec.lo, -kWidgetLimit) + (spec.loOpen ? step : 0.0), std::min(spec.hi, kWidgetLimit) - (spec.hiOpen ? step : 0.0));
    s->setValue(value);
    s->setToolTip(paramToolTip(spec));
    return s;
}

QSpinBox* paramIntSpin(const ParamSpec& spec, const QString& name, int value)
{
    constexpr double intLo = std::numeric_limits<int>::min(), intHi = std::numeric_limits<int>::max();
    auto* s = new QSpinBox;
    s->setObjectName(name);
    s->setRange(int(std::max(spec.lo, intLo)), int(std::min(spec.hi, intHi)));
    s->setValue(value);
    s->setToolTip(paramToolTip(spec));
    return s;
}

QLineEdit* paramSeedEdit(const ParamSpec& spec, const QString& name, uint64_t value)
{
    auto* e = new QLineEdit;
    e->setObjectName(name);
    e->setValidator(new QRegularExpressionValidator(QRegularExpression(QStringLiteral("[0-9]{1,19}")), e));
    e->setToolTip(paramToolTip(spec));
    setParamSeed(e, value);
    return e;
}

uint64_t paramSeed(const QLineEdit* edit) { return edit->text().toULongLong(); }

void setParamSeed(QLineEdit* edit, uint64_t value) { edit->setText(QString::number(value)); }

QDoubleSpinBox* sceneSpin(const char* key, const QString& name, int decimals, double step)
{
    const json::Bounds b = sceneFieldRange(key);
    const double unit = std::pow(10.0, -decimals);
    double lo = std::max(b.lo, -kWidgetLimit) + (b.loOpen ? unit : 0.0);
    const double hi = std::min(b.hi, kWidgetLimit) - (b.hiOpen ? unit : 0.0);
    if (b.orZero) lo = std::min(lo, 0.0);
    QDoubleSpinBox* s = widgets::spin(name, lo, hi, decimals, step);
    s->setRange(lo, hi);   // again: setDecimals may have rounded it
    return s;
}

QSpinBox* sceneIntSpin(const char* key, const QString& name)
{
    constexpr double intLo = std::numeric_limits<int>::min(), intHi = std::numeric_limits<int>::max();
    const json::Bounds b = sceneFieldRange(key);
    auto* s = new QSpinBox;
    s->setObjectName(name);
    s->setRange(int(std::max(b.lo, intLo)), int(std::min(b.hi, intHi)));
    s->setKeyboardTracking(false);
    return s;
}

} // namespace sylva
