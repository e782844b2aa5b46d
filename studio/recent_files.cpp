// RecentFiles: the list in QSettings and the Open Recent menu.
#include "studio/recent_files.h"

#include <QAction>
#include <QFileInfo>
#include <QMenu>
#include <QSettings>

namespace sylva {

QString lastFolder(const QString& kind)
{
    const QString folder = QSettings().value(QStringLiteral("lastFolder/") + kind).toString();
    return !folder.isEmpty() && QFileInfo(folder).isDir() ? folder : QString();
}

void rememberFolder(const QString& kind, const QString& path)
{
    if (path.isEmpty()) return;
    const QFileInfo info(path);
    QSettings().setValue(QStringLiteral("lastFolder/") + kind, info.isDir() ? info.absoluteFilePath() : info.absolutePath());
}

RecentFiles::RecentFiles(QMenu* menu, QObject* parent) : QObject(parent), m_menu(menu) { updateMenu(); }

QStringList RecentFiles::files() const { return QSettings().value("recentFiles").toStringList(); }

void RecentFiles::add(const QString& path)
{
    QStringList list = files();
    list.removeAll(path);
    list.prepend(path);
    while (list.size() > kMaxFiles) list.removeLast();
    QSettings().setValue("recentFiles", list);
    updateMenu();
}

void RecentFiles::updateMenu()
{
    if (!m_menu) return;
    m_menu->clear();
    const QStringList list = files();
    for (int i = 0; i < list.size(); ++i) {
        const QString f = list[i];
        QAction* a = m_menu->addAction(QStringLiteral("&%1 %2").arg(i + 1).arg(QFileInfo(f).fileName()));
        a->setToolTip(f);
        connect(a, &QAction::triggered, this, [this, f] { Q_EMIT openRequested(f); });
    }
    m_menu->setEnabled(!list.isEmpty());
}

} // namespace sylva
