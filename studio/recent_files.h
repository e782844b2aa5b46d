// File > Open Recent: the last files opened or saved (settings key recentFiles) and the menu listing them.
#pragma once

#include <QObject>
#include <QStringList>

class QMenu;

namespace sylva {

// The folder a file dialog of one kind ("scenes", "meshes", "maps", "grids") starts in: the folder of the
// last file (or the last folder) of that kind chosen, opened or saved (settings key lastFolder/<kind>), so
// it survives the session; empty (the dialog's own default) before any.
QString lastFolder(const QString& kind);
// Remembers `path`'s folder (path itself when it is a folder) for dialogs of `kind`.
void rememberFolder(const QString& kind, const QString& path);

class RecentFiles : public QObject {
    Q_OBJECT

public:
    static constexpr int kMaxFiles = 8;

    // Fills menu (and keeps it up to date); its actions ask for the file with openRequested.
    explicit RecentFiles(QMenu* menu, QObject* parent = nullptr);

    QStringList files() const;
    // Puts path first (once), keeping the last kMaxFiles.
    void add(const QString& path);

Q_SIGNALS:
    void openRequested(const QString& path);

private:
    void updateMenu();
    QMenu* m_menu;
};

} // namespace sylva
