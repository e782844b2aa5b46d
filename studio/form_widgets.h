// The studio's form controls, built one way in every panel (property pages, scene item pages, sky):
// a spin box for a scene value, a row of widgets, and value updates that do not fire the edit signals.
#pragma once

#include <QDoubleSpinBox>
#include <QHBoxLayout>
#include <QSignalBlocker>
#include <QSpinBox>
#include <QString>
#include <QWidget>

#include <cmath>
#include <initializer_list>

namespace sylva::widgets {

// A spin box named after its scene key, committing on Enter or focus loss (no keyboard tracking).
inline QDoubleSpinBox* spin(const QString& name, double lo, double hi, int decimals, double step)
{
    auto* s = new QDoubleSpinBox;
    s->setObjectName(name);
    s->setRange(lo, hi);
    s->setDecimals(decimals);
    s->setSingleStep(step);
    s->setKeyboardTracking(false);
    s->setAccelerated(true);
    s->setMinimumWidth(64);   // not the width of the widest value: three share a row
    return s;
}

// Shows a value without emitting valueChanged (a refresh from the scene is not an edit). What rounds to
// zero at the box's decimals shows as 0.000, not -0.000 (an orbit leaves coordinates of 1e-15 either side).
inline void setValue(QDoubleSpinBox* box, double v)
{
    const QSignalBlocker block(box);
    box->setValue(std::abs(v) < 0.5 * std::pow(10.0, -box->decimals()) ? 0.0 : v);
}
inline void setValue(QSpinBox* box, int v)
{
    const QSignalBlocker block(box);
    box->setValue(v);
}

// Widgets side by side without margins, for one form row.
inline QWidget* row(std::initializer_list<QWidget*> widgets)
{
    auto* w = new QWidget;
    auto* l = new QHBoxLayout(w);
    l->setContentsMargins(0, 0, 0, 0);
    for (QWidget* x : widgets) l->addWidget(x);
    return w;
}

} // namespace sylva::widgets
