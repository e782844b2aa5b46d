// Autosave and crash recovery of the window's document: a timer writes a modified scene to a recovery
// file; at start-up a recovery file left by a window that did not close cleanly is offered back.
#pragma once

#include <functional>

#include <QDateTime>
#include <QString>
#include <QTimer>

#include "studio/studio_controller.h"

class QWidget;

namespace sylva {

class SceneDocument;

class AutosaveController : public StudioController {
    Q_OBJECT

public:
    // window: the parent of the default recovery question. Reads the interval from the settings and
    // offers a recovery file, if there is one, once the event loop runs.
    AutosaveController(SceneDocument* doc, QWidget* window, QObject* parent = nullptr);
    ~AutosaveController() override;

    // The question asked when a recovery file is found (origin: the scene's file, empty when untitled;
    // when: the autosave's time). Default: a modal question box. Answer true to recover.
    using RecoveryPrompt = std::function<bool(const QString& origin, const QDateTime& when)>;
    void setRecoveryPrompt(RecoveryPrompt prompt) { m_askRecover = std::move(prompt); }

    // Every interval (default 60 s, settings key autosave/intervalSeconds; 0 = off) a modified scene
    // goes to recoveryFilePath(); a clean save, a clean document or a close deletes it.
    void setInterval(int milliseconds);
    int interval() const { return m_timer.isActive() ? m_timer.interval() : 0; }
    // Writes the recovery file now when the scene is modified and changed since the last autosave;
    // true when it wrote one.
    bool autosaveNow();
    // Where autosave writes: QStandardPaths::AppDataLocation/recovery/autosave.sylva.json, with
    // autosave.json beside it naming the scene's own file.
    static QString recoveryFilePath();
    // Offers the recovery file, if there is one: recovering replaces the document with the file's scene
    // on top of the saved one (one undo step, modified); either way the recovery file is deleted. True
    // when a scene was recovered.
    bool offerRecovery();
    // Deletes the recovery file (a clean close, a clean document); not while one waits to be offered.
    void removeRecoveryFile();

Q_SIGNALS:
    void autosaved(const QString& path);

private:
    SceneDocument* m_doc;
    RecoveryPrompt m_askRecover;
    QTimer m_timer;
    quint64 m_autosavedRevision = 0;
    bool m_recoveryPending = false;   // a recovery file waits to be offered: neither overwrite nor delete it
};

} // namespace sylva
