// Help > Manual (the user documents, Markdown shown offline) and Help > Keyboard Shortcuts (a sheet made
// from the window's actions and their shortcuts).
#pragma once

#include <QDialog>
#include <QString>
#include <QStringList>
#include <QVector>

class QAction;
class QListWidget;
class QTableWidget;
class QTextBrowser;

namespace sylva {

class ManualDialog : public QDialog {
    Q_OBJECT

public:
    explicit ManualDialog(QWidget* parent = nullptr);

    // The folder that holds README.md and docs/ (STUDIO.md, SCENE.md, ...): the installed documents beside
    // the program (../share/doc/sylva from its folder) when they are there, else the source tree the
    // program was built from. Empty when neither has them.
    static QString docsRoot();
    // The manual's documents, relative to docsRoot(): README.md, docs/STUDIO.md, docs/SCENE.md.
    static QStringList documents();

    // Shows one of documents() (its links to other documents are followed in the browser); false when it is missing.
    bool showDocument(const QString& relativePath);
    QTextBrowser* browser() const { return m_browser; }
    QListWidget* list() const { return m_list; }

private:
    QListWidget* m_list;
    QTextBrowser* m_browser;
};

// One row of the shortcut sheet: where the action is (its menu path, e.g. "File > Open..."), its shortcut(s).
struct ShortcutRow {
    QString action;
    QString keys;
    QAction* source = nullptr;
};

class ShortcutSheet : public QDialog {
    Q_OBJECT

public:
    // window: the window whose actions (every QAction under it with a shortcut) the sheet lists.
    explicit ShortcutSheet(QWidget* window, QWidget* parent = nullptr);

    // The rows for window's actions: each action with at least one shortcut once, named by its menu path
    // (its text alone when it is in no menu), in menu order, then the others.
    static QVector<ShortcutRow> rows(QWidget* window);
    QTableWidget* table() const { return m_table; }

private:
    QTableWidget* m_table;
};

} // namespace sylva
