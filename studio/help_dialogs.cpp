// The manual and the shortcut sheet (help_dialogs.h).
#include "studio/help_dialogs.h"

#include <functional>

#include <QAction>
#include <QCoreApplication>
#include <QDialogButtonBox>
#include <QDir>
#include <QFileInfo>
#include <QHeaderView>
#include <QLabel>
#include <QListWidget>
#include <QMainWindow>
#include <QMenu>
#include <QMenuBar>
#include <QRegularExpression>
#include <QSet>
#include <QSplitter>
#include <QTableWidget>
#include <QTextBrowser>
#include <QUrl>
#include <QVBoxLayout>

namespace sylva {
namespace {

bool holdsDocs(const QString& folder)
{
    return !folder.isEmpty() && QFileInfo::exists(QDir(folder).filePath(QStringLiteral("docs/STUDIO.md")));
}

QString plainText(const QAction* a)
{
    QString t = a->text();
    t.remove(QRegularExpression(QStringLiteral("&(?!&)")));
    return t;
}

} // namespace

QString ManualDialog::docsRoot()
{
    const QString installed = QDir(QCoreApplication::applicationDirPath()).absoluteFilePath(QStringLiteral("../share/doc/sylva"));
    if (holdsDocs(installed)) return QDir::cleanPath(installed);
    const QString source = QStringLiteral(SYLVA_SOURCE_DIR);
    if (holdsDocs(source)) return QDir::cleanPath(source);
    return QString();
}

QStringList ManualDialog::documents()
{
    return {QStringLiteral("docs/STUDIO.md"), QStringLiteral("docs/SCENE.md"), QStringLiteral("README.md")};
}

ManualDialog::ManualDialog(QWidget* parent) : QDialog(parent)
{
    setObjectName("manualDialog");
    setWindowTitle(tr("Sylva Studio Manual"));
    m_list = new QListWidget;
    m_list->setObjectName("manualDocuments");
    const QStringList titles = {tr("The studio"), tr("Scene files"), tr("About Sylva")};
    const QStringList docs = documents();
    for (int i = 0; i < docs.size(); ++i) {
        auto* item = new QListWidgetItem(titles.value(i, docs[i]), m_list);
        item->setData(Qt::UserRole, docs[i]);
        item->setToolTip(docs[i]);
    }
    m_list->setMaximumWidth(180);
    m_browser = new QTextBrowser;
    m_browser->setObjectName("manualText");
    m_browser->setOpenExternalLinks(true);   // web links in the system's browser; links between the documents here
    auto* split = new QSplitter;
    split->addWidget(m_list);
    split->addWidget(m_browser);
    split->setStretchFactor(1, 1);
    auto* buttons = new QDialogButtonBox(QDialogButtonBox::Close);
    connect(buttons, &QDialogButtonBox::rejected, this, &QDialog::reject);
    auto* layout = new QVBoxLayout(this);
    layout->addWidget(split, 1);
    layout->addWidget(buttons);
    resize(1000, 720);
    connect(m_list, &QListWidget::currentRowChanged, this, [this](int row) {
        if (row >= 0) showDocument(m_list->item(row)->data(Qt::UserRole).toString());
    });
    if (docsRoot().isEmpty()) m_browser->setPlainText(tr("The manual's files (README.md and docs/) were not found beside the program."));
    else m_list->setCurrentRow(0);
}

bool ManualDialog::showDocument(const QString& relativePath)
{
    const QString root = docsRoot();
    const QString path = root.isEmpty() ? QString() : QDir(root).filePath(relativePath);
    if (path.isEmpty() || !QFileInfo::exists(path)) {
        m_browser->setPlainText(tr("%1 was not found.").arg(relativePath));
        return false;
    }
    m_browser->setSource(QUrl::fromLocalFile(path), QTextDocument::MarkdownResource);
    return true;
}

QVector<ShortcutRow> ShortcutSheet::rows(QWidget* window)
{
    QVector<ShortcutRow> out;
    QSet<QAction*> seen;
    auto add = [&](QAction* a, const QString& name) {
        if (!a || a->isSeparator() || a->shortcuts().isEmpty() || seen.contains(a)) return;
        seen.insert(a);
        QStringList keys;
        for (const QKeySequence& k : a->shortcuts()) keys << k.toString(QKeySequence::NativeText);
        out.push_back({name, keys.join(QStringLiteral(", ")), a});
    };
    // The menus first, in their order, each action named by its path.
    std::function<void(QMenu*, const QString&)> walk = [&](QMenu* menu, const QString& path) {
        for (QAction* a : menu->actions()) {
            if (a->menu()) walk(a->menu(), path + plainText(a) + QStringLiteral(" > "));
            else add(a, path + plainText(a));
        }
    };
    if (auto* main = qobject_cast<QMainWindow*>(window))
        for (QAction* a : main->menuBar()->actions())
            if (a->menu()) walk(a->menu(), plainText(a) + QStringLiteral(" > "));
    for (QAction* a : window->findChildren<QAction*>()) add(a, plainText(a));
    return out;
}

ShortcutSheet::ShortcutSheet(QWidget* window, QWidget* parent) : QDialog(parent)
{
    setObjectName("shortcutSheet");
    setWindowTitle(tr("Keyboard Shortcuts"));
    const QVector<ShortcutRow> list = rows(window);
    m_table = new QTableWidget(int(list.size()), 2);
    m_table->setObjectName("shortcutTable");
    m_table->setHorizontalHeaderLabels({tr("Action"), tr("Shortcut")});
    m_table->verticalHeader()->hide();
    m_table->setEditTriggers(QAbstractItemView::NoEditTriggers);
    m_table->setSelectionBehavior(QAbstractItemView::SelectRows);
    for (int r = 0; r < list.size(); ++r) {
        m_table->setItem(r, 0, new QTableWidgetItem(list[r].action));
        m_table->setItem(r, 1, new QTableWidgetItem(list[r].keys));
        if (!list[r].source->toolTip().isEmpty()) m_table->item(r, 0)->setToolTip(list[r].source->toolTip());
    }
    m_table->horizontalHeader()->setSectionResizeMode(0, QHeaderView::Stretch);
    m_table->horizontalHeader()->setSectionResizeMode(1, QHeaderView::ResizeToContents);
    auto* note = new QLabel(tr("In the viewport: drag to orbit, Shift + drag or the middle button to pan, the wheel to zoom; F switches "
                              "fly navigation on and off (then W/S, A/D, Q/E move; Shift: faster). A click selects a tree; "
                              "Ctrl + drag on a tree slides it over the ground, Ctrl + wheel turns the selected tree, "
                              "Ctrl + Shift + wheel scales it."));
    note->setWordWrap(true);
    auto* buttons = new QDialogButtonBox(QDialogButtonBox::Close);
    connect(buttons, &QDialogButtonBox::rejected, this, &QDialog::reject);
    auto* layout = new QVBoxLayout(this);
    layout->addWidget(m_table, 1);
    layout->addWidget(note);
    layout->addWidget(buttons);
    resize(520, 560);
}

} // namespace sylva
