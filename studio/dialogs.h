// Small modal dialogs: grow a species, export a render.
#pragma once

#include <QDialog>

#include "core/scene/scene.h"

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

} // namespace sylva
