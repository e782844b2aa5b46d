// GrowDialog and ExportDialog: forms over GrowSpec and the export settings.
#include "studio/dialogs.h"

#include <QComboBox>
#include <QDialogButtonBox>
#include <QDoubleSpinBox>
#include <QFileDialog>
#include <QFormLayout>
#include <QHBoxLayout>
#include <QLineEdit>
#include <QPushButton>
#include <QSpinBox>

#include "pipeline/grow/tree_grower.h"

namespace sylva {

GrowDialog::GrowDialog(QWidget* parent) : QDialog(parent)
{
    setWindowTitle(tr("Grow Species"));
    auto* form = new QFormLayout(this);
    m_species = new QComboBox;
    for (const std::string& n : speciesNames()) m_species->addItem(QString::fromStdString(n));
    m_seed = new QSpinBox;
    m_seed->setRange(0, 1 << 30);
    m_seed->setValue(1);
    m_triangles = new QSpinBox;
    m_triangles->setRange(int(kMinGrowTriangles), int(kMaxGrowTriangles));
    m_triangles->setSingleStep(10000);
    m_triangles->setValue(50000);
    m_height = new QDoubleSpinBox;
    m_height->setRange(0.0, 150.0);
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
    g.height = m_height->value() < 0.1 ? 0.0f : float(m_height->value());
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
    auto* buttons = new QDialogButtonBox(QDialogButtonBox::Ok | QDialogButtonBox::Cancel);
    connect(buttons, &QDialogButtonBox::accepted, this, &QDialog::accept);
    connect(buttons, &QDialogButtonBox::rejected, this, &QDialog::reject);
    form->addRow(buttons);
}

ExportSettings ExportDialog::settings() const
{
    return {m_path->text(), m_width->value(), m_height->value(), m_spp->value()};
}

} // namespace sylva
