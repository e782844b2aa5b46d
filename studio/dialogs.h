// Small modal dialogs: grow a species, export a render, scatter instances.
#pragma once

#include <QDialog>

#include "core/scene/scene.h"
#include "pipeline/scene/scatter.h"

class QCheckBox;
class QComboBox;
class QDoubleSpinBox;
class QLineEdit;
class QSpinBox;

namespace sylva {

// Grower species, seed, triangle count, height.
class GrowDialog : public QDialog {
    Q_OBJECT

public:
    explicit GrowDialog(QWidget* parent = nullptr);
    GrowSpec spec() const;

private:
    QComboBox* m_species;
    QSpinBox* m_seed;
    QSpinBox* m_triangles;
    QDoubleSpinBox* m_height;
};

struct ExportSettings {
    QString path;
    int width = 896, height = 448, spp = 4;
};

// Output file (PNG/EXR/TIFF), size and samples per pixel.
class ExportDialog : public QDialog {
    Q_OBJECT

public:
    ExportDialog(const ExportSettings& initial, QWidget* parent = nullptr);
    ExportSettings settings() const;

private:
    QLineEdit* m_path;
    QSpinBox* m_width;
    QSpinBox* m_height;
    QSpinBox* m_spp;
};

// Scatter tool: species, count, rectangle (x and z ranges), random rotation about up, scale range, seed.
class ScatterDialog : public QDialog {
    Q_OBJECT

public:
    // speciesNames: the scene's species in order; initial: the form's starting values.
    ScatterDialog(const QStringList& speciesNames, const ScatterSpec& initial, QWidget* parent = nullptr);
    ScatterSpec spec() const;

    QComboBox* speciesBox() const { return m_species; }
    QSpinBox* countBox() const { return m_count; }
    QSpinBox* seedBox() const { return m_seed; }

private:
    QComboBox* m_species;
    QSpinBox* m_count;
    QDoubleSpinBox* m_x0;
    QDoubleSpinBox* m_x1;
    QDoubleSpinBox* m_z0;
    QDoubleSpinBox* m_z1;
    QCheckBox* m_rotate;
    QDoubleSpinBox* m_s0;
    QDoubleSpinBox* m_s1;
    QSpinBox* m_seed;
    double m_height;
};

} // namespace sylva
