// Small modal dialogs: grow a species, export a render, scatter instances, leaf/wood materials.
#pragma once

#include <QDialog>

#include "core/scene/scene.h"
#include "pipeline/scene/scatter.h"

class QCheckBox;
class QComboBox;
class QDoubleSpinBox;
class QLineEdit;
class QPushButton;
class QSpinBox;
class QTreeWidget;
class QTreeWidgetItem;

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
    bool passes = false;   // the render passes as one multi-layer EXR (pipeline/render/render_passes.h)
};

// Output file (PNG/EXR/TIFF), size, samples per pixel, and for .exr whether to write the render passes.
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
    QCheckBox* m_passes;
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
    QDoubleSpinBox* clearanceBox() const { return m_clear; }
    // "Frame the result": Frame All after the scatter (on at first).
    QCheckBox* frameBox() const { return m_frame; }
    bool frameResult() const;

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
    QDoubleSpinBox* m_clear;
    QCheckBox* m_frame;
    double m_height;
    glm::dvec2 m_clearCentre;
};

// One material of a species' mesh for the material dialog: its name, what the importer's rules make
// of it (leaf when it has an opacity texture or cut-out alpha, or a leaf-like name; else wood) and
// what it is now (the species' leaf_materials when set, else the rules).
struct MaterialChoice {
    QString name;
    bool leafByRules = false;
    bool leaf = false;
};

// Leaf/wood assignment of a species' materials: a row per material with Leaf and Wood check boxes
// (exactly one checked), and a button back to the importer's rules. leafMaterials() is what the
// species' leaf_materials should become: empty when the choice equals the rules (the importer
// decides), else the names checked Leaf. At least one material must be leaf (an empty list means
// "the rules"), so OK is disabled without one.
class MaterialDialog : public QDialog {
    Q_OBJECT

public:
    MaterialDialog(const QString& species, const std::vector<MaterialChoice>& materials, QWidget* parent = nullptr);
    std::vector<std::string> leafMaterials() const;
    bool isLeaf(int row) const;
    void setLeaf(int row, bool leaf);
    void resetToRules();
    QTreeWidget* table() const { return m_table; }
    QPushButton* okButton() const { return m_ok; }

    enum Column { NameColumn = 0, LeafColumn = 1, WoodColumn = 2 };

private:
    void onItemChanged(QTreeWidgetItem* item, int column);
    std::vector<MaterialChoice> m_materials;
    QTreeWidget* m_table;
    QPushButton* m_ok;
    bool m_updating = false;
};

} // namespace sylva
