// GrowDialog and ExportDialog: forms over GrowSpec and the export settings.
#include "studio/dialogs.h"

#include <QCheckBox>
#include <QComboBox>
#include <QDialogButtonBox>
#include <QDoubleSpinBox>
#include <QFileDialog>
#include <QFormLayout>
#include <QHBoxLayout>
#include <QLineEdit>
#include <QPushButton>
#include <QLabel>
#include <QSpinBox>
#include <QTreeWidget>
#include <QVBoxLayout>

#include "pipeline/grow/tree_grower.h"
#include "pipeline/scene/scene_fields.h"
#include "studio/param_widgets.h"

namespace sylva {

GrowDialog::GrowDialog(QWidget* parent) : QDialog(parent)
{
    setWindowTitle(tr("Grow Species"));
    auto* form = new QFormLayout(this);
    m_species = new QComboBox;
    for (const std::string& n : speciesNames()) m_species->addItem(QString::fromStdString(n));
    m_seed = sceneIntSpin("species[i].grow.seed", "grow.seed");   // the scene file's range, clamped to an int
    m_seed->setValue(1);
    m_triangles = new QSpinBox;
    m_triangles->setRange(int(kMinGrowTriangles), int(kMaxGrowTriangles));
    m_triangles->setSingleStep(10000);
    m_triangles->setValue(50000);
    m_height = sceneSpin("species[i].grow.height", "grow.height", 2, 1.0);   // 0: the species' default
    m_height->setKeyboardTracking(true);
    m_height->setSpecialValueText(tr("species default"));
    m_height->setSuffix(tr(" m"));
    form->addRow(tr("Grower species"), m_species);
    form->addRow(tr("Seed"), m_seed);
    form->addRow(tr("Triangles"), m_triangles);
    form->addRow(tr("Height"), m_height);
    auto* buttons = new QDialogButtonBox(QDialogButtonBox::Ok | QDialogButtonBox::Cancel);
    connect(buttons, &QDialogButtonBox::accepted, this, &QDialog::accept);
    connect(buttons, &QDialogButtonBox::rejected, this, &QDialog::reject);
    form->addRow(buttons);
}

GrowSpec GrowDialog::spec() const
{
    GrowSpec g;
    g.species = m_species->currentText().toStdString();
    g.seed = uint64_t(m_seed->value());
    g.triangles = uint64_t(m_triangles->value());
    const double shortest = sceneFieldRange("species[i].grow.height").lo;   // below it: 0, the species' default
    g.height = m_height->value() < shortest ? 0.0f : float(m_height->value());
    return g;
}

ExportDialog::ExportDialog(const ExportSettings& initial, QWidget* parent) : QDialog(parent)
{
    setWindowTitle(tr("Export Render"));
    auto* form = new QFormLayout(this);
    m_path = new QLineEdit(initial.path);
    auto* browse = new QPushButton(tr("Browse..."));
    connect(browse, &QPushButton::clicked, this, [this] {
        const QString p = QFileDialog::getSaveFileName(this, tr("Export Render"), m_path->text(),
                                                       tr("Images (*.png *.exr *.tif *.tiff)"));
        if (!p.isEmpty()) m_path->setText(p);
    });
    auto* pathRow = new QHBoxLayout;
    pathRow->addWidget(m_path, 1);
    pathRow->addWidget(browse);
    auto makeSpin = [](int lo, int hi, int value) {
        auto* s = new QSpinBox;
        s->setRange(lo, hi);
        s->setValue(value);
        return s;
    };
    m_width = makeSpin(1, 16384, initial.width);
    m_height = makeSpin(1, 16384, initial.height);
    m_spp = makeSpin(1, 1024, initial.spp);
    form->addRow(tr("File"), pathRow);
    form->addRow(tr("Width"), m_width);
    form->addRow(tr("Height"), m_height);
    form->addRow(tr("Samples per pixel"), m_spp);
    m_passes = new QCheckBox(tr("Render passes (multi-layer EXR: Combined, DiffDir, DiffInd, DiffCol, Env, Normal, Depth, Alpha)"));
    auto exrOnly = [this](const QString& path) {
        const bool exr = path.endsWith(QLatin1String(".exr"), Qt::CaseInsensitive);
        m_passes->setEnabled(exr);
        if (!exr) m_passes->setChecked(false);
    };
    m_passes->setChecked(initial.passes);
    exrOnly(initial.path);
    connect(m_path, &QLineEdit::textChanged, this, exrOnly);
    form->addRow(QString(), m_passes);
    auto* buttons = new QDialogButtonBox(QDialogButtonBox::Ok | QDialogButtonBox::Cancel);
    connect(buttons, &QDialogButtonBox::accepted, this, &QDialog::accept);
    connect(buttons, &QDialogButtonBox::rejected, this, &QDialog::reject);
    form->addRow(buttons);
}

ExportSettings ExportDialog::settings() const
{
    return {m_path->text(), m_width->value(), m_height->value(), m_spp->value(), m_passes->isChecked()};
}

ScatterDialog::ScatterDialog(const QStringList& speciesNames, const ScatterSpec& initial, QWidget* parent)
    : QDialog(parent), m_height(initial.height), m_clearCentre(initial.clearCentre)
{
    setWindowTitle(tr("Scatter Instances"));
    auto* form = new QFormLayout(this);
    m_species = new QComboBox;
    m_species->addItems(speciesNames);
    m_species->setCurrentIndex(std::min<int>(int(initial.species), int(speciesNames.size()) - 1));
    m_count = new QSpinBox;
    m_count->setRange(1, 100000);
    m_count->setValue(std::max(1, initial.count));
    auto metres = [](double v) {
        auto* b = new QDoubleSpinBox;
        b->setRange(-1e6, 1e6);
        b->setDecimals(2);
        b->setSuffix(QObject::tr(" m"));
        b->setValue(v);
        return b;
    };
    m_x0 = metres(initial.min.x);
    m_x1 = metres(initial.max.x);
    m_z0 = metres(initial.min.y);
    m_z1 = metres(initial.max.y);
    auto pair = [](QWidget* a, QWidget* b) {
        auto* w = new QWidget;
        auto* l = new QHBoxLayout(w);
        l->setContentsMargins(0, 0, 0, 0);
        l->addWidget(a);
        l->addWidget(b);
        return w;
    };
    m_rotate = new QCheckBox(tr("random rotation about the up axis"));
    m_rotate->setChecked(initial.randomRotation);
    auto scale = [](float v) {
        auto* b = new QDoubleSpinBox;
        b->setRange(0.01, 100.0);
        b->setDecimals(2);
        b->setSingleStep(0.05);
        b->setValue(double(v));
        return b;
    };
    m_s0 = scale(initial.scaleMin);
    m_s1 = scale(initial.scaleMax);
    m_seed = new QSpinBox;
    m_seed->setRange(0, 1 << 30);
    m_seed->setValue(int(std::min<uint64_t>(initial.seed, 1u << 30)));
    form->addRow(tr("Species"), m_species);
    form->addRow(tr("Count"), m_count);
    form->addRow(tr("X from / to"), pair(m_x0, m_x1));
    form->addRow(tr("Z from / to"), pair(m_z0, m_z1));
    form->addRow(tr("Rotation"), m_rotate);
    form->addRow(tr("Scale from / to"), pair(m_s0, m_s1));
    form->addRow(tr("Seed"), m_seed);
    m_clear = new QDoubleSpinBox;
    m_clear->setObjectName("scatterClearance");
    m_clear->setRange(0.0, 1e4);
    m_clear->setDecimals(1);
    m_clear->setSuffix(tr(" m"));
    m_clear->setValue(initial.clearRadius);
    m_clear->setToolTip(tr("No tree is placed closer than this to the camera (measured along the ground), "
                           "so the camera does not start inside a trunk or a crown. 0: no clearance"));
    form->addRow(tr("Keep clear around the camera"), m_clear);
    m_frame = new QCheckBox(tr("Frame the result"));
    m_frame->setObjectName("scatterFrame");
    m_frame->setChecked(true);
    m_frame->setToolTip(tr("Afterwards, move the camera back so the whole scene is in view (View > Frame All)"));
    form->addRow(QString(), m_frame);
    auto* buttons = new QDialogButtonBox(QDialogButtonBox::Ok | QDialogButtonBox::Cancel);
    connect(buttons, &QDialogButtonBox::accepted, this, &QDialog::accept);
    connect(buttons, &QDialogButtonBox::rejected, this, &QDialog::reject);
    form->addRow(buttons);
}

bool ScatterDialog::frameResult() const { return m_frame->isChecked(); }

ScatterSpec ScatterDialog::spec() const
{
    ScatterSpec s;
    s.species = uint32_t(std::max(0, m_species->currentIndex()));
    s.count = m_count->value();
    // Corners in either order; scale range likewise.
    s.min = {std::min(m_x0->value(), m_x1->value()), std::min(m_z0->value(), m_z1->value())};
    s.max = {std::max(m_x0->value(), m_x1->value()), std::max(m_z0->value(), m_z1->value())};
    s.height = m_height;
    s.randomRotation = m_rotate->isChecked();
    s.scaleMin = float(std::min(m_s0->value(), m_s1->value()));
    s.scaleMax = float(std::max(m_s0->value(), m_s1->value()));
    s.seed = uint64_t(m_seed->value());
    s.clearCentre = m_clearCentre;
    s.clearRadius = m_clear->value();
    return s;
}

MaterialDialog::MaterialDialog(const QString& species, const std::vector<MaterialChoice>& materials, QWidget* parent)
    : QDialog(parent), m_materials(materials)
{
    setWindowTitle(tr("Materials of %1").arg(species));
    auto* layout = new QVBoxLayout(this);
    auto* note = new QLabel(tr("Leaf materials become thin translucent foliage in the LB grid (density with "
                               "the leaf optics); wood is opaque. Changing them revoxelizes and relights the species."));
    note->setWordWrap(true);
    layout->addWidget(note);
    m_table = new QTreeWidget;
    m_table->setObjectName("materialTable");
    m_table->setRootIsDecorated(false);
    m_table->setHeaderLabels({tr("Material"), tr("Leaf"), tr("Wood")});
    for (const MaterialChoice& m : m_materials) {
        auto* item = new QTreeWidgetItem(m_table);
        item->setText(NameColumn, m.name);
        item->setToolTip(NameColumn, m.leafByRules ? tr("leaf by the importer's rules") : tr("wood by the importer's rules"));
        item->setFlags(Qt::ItemIsEnabled | Qt::ItemIsUserCheckable);
        item->setCheckState(LeafColumn, m.leaf ? Qt::Checked : Qt::Unchecked);
        item->setCheckState(WoodColumn, m.leaf ? Qt::Unchecked : Qt::Checked);
    }
    m_table->resizeColumnToContents(NameColumn);
    layout->addWidget(m_table, 1);
    auto* buttons = new QDialogButtonBox(QDialogButtonBox::Ok | QDialogButtonBox::Cancel);
    QPushButton* rules = buttons->addButton(tr("Importer's Rules"), QDialogButtonBox::ResetRole);
    m_ok = buttons->button(QDialogButtonBox::Ok);
    connect(rules, &QPushButton::clicked, this, &MaterialDialog::resetToRules);
    connect(buttons, &QDialogButtonBox::accepted, this, &QDialog::accept);
    connect(buttons, &QDialogButtonBox::rejected, this, &QDialog::reject);
    connect(m_table, &QTreeWidget::itemChanged, this, &MaterialDialog::onItemChanged);
    layout->addWidget(buttons);
    onItemChanged(nullptr, 0);
}

bool MaterialDialog::isLeaf(int row) const
{
    const QTreeWidgetItem* item = m_table->topLevelItem(row);
    return item && item->checkState(LeafColumn) == Qt::Checked;
}

void MaterialDialog::setLeaf(int row, bool leaf)
{
    if (QTreeWidgetItem* item = m_table->topLevelItem(row)) item->setCheckState(leaf ? LeafColumn : WoodColumn, Qt::Checked);
}

void MaterialDialog::resetToRules()
{
    for (int r = 0; r < int(m_materials.size()); ++r) setLeaf(r, m_materials[size_t(r)].leafByRules);
}

void MaterialDialog::onItemChanged(QTreeWidgetItem* item, int column)
{
    if (m_updating) return;
    m_updating = true;
    if (item && (column == LeafColumn || column == WoodColumn)) {
        // Leaf and Wood exclude each other: checking one unchecks the other, unchecking one checks it.
        const bool checked = item->checkState(column) == Qt::Checked;
        item->setCheckState(column == LeafColumn ? WoodColumn : LeafColumn, checked ? Qt::Unchecked : Qt::Checked);
    }
    bool anyLeaf = false;
    for (int r = 0; r < m_table->topLevelItemCount(); ++r) anyLeaf = anyLeaf || isLeaf(r);
    m_ok->setEnabled(anyLeaf);
    m_ok->setToolTip(anyLeaf ? QString() : tr("At least one material must be leaf"));
    m_updating = false;
}

std::vector<std::string> MaterialDialog::leafMaterials() const
{
    bool asRules = true;
    std::vector<std::string> out;
    for (int r = 0; r < int(m_materials.size()); ++r) {
        if (isLeaf(r) != m_materials[size_t(r)].leafByRules) asRules = false;
        if (isLeaf(r)) out.push_back(m_materials[size_t(r)].name.toStdString());
    }
    if (asRules) out.clear();
    return out;
}

} // namespace sylva
