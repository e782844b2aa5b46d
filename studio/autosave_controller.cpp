// AutosaveController: the recovery file (scene + autosave.json naming its origin), its timer and the
// recovery offer at start-up.
#include "studio/autosave_controller.h"

#include <QFile>
#include <QFileInfo>
#include <QJsonDocument>
#include <QJsonObject>
#include <QLocale>
#include <QMessageBox>
#include <QSettings>
#include <QStandardPaths>
#include <QWidget>

#include "pipeline/io/atomic_file.h"
#include "pipeline/scene/scene_file.h"
#include "studio/scene_document.h"

namespace sylva {
namespace {

QString recoveryInfoPath()
{
    return QFileInfo(AutosaveController::recoveryFilePath()).absolutePath() + QStringLiteral("/autosave.json");
}

} // namespace

AutosaveController::AutosaveController(SceneDocument* doc, QWidget* window, QObject* parent)
    : StudioController(parent), m_doc(doc)
{
    m_askRecover = [window](const QString& origin, const QDateTime& when) {
        return QMessageBox::question(window, tr("Recover unsaved changes?"),
                                     tr("Sylva Studio did not close cleanly. Recover the unsaved changes to %1 autosaved at %2?")
                                         .arg(origin.isEmpty() ? tr("an untitled scene") : origin,
                                              QLocale().toString(when, QLocale::ShortFormat)),
                                     QMessageBox::Yes | QMessageBox::No, QMessageBox::Yes) == QMessageBox::Yes;
    };
    connect(m_doc, &SceneDocument::modifiedChanged, this, [this](bool modified) {
        if (!modified) removeRecoveryFile();
    });
    connect(&m_timer, &QTimer::timeout, this, [this] { autosaveNow(); });
    setInterval(QSettings().value("autosave/intervalSeconds", 60).toInt() * 1000);
    m_recoveryPending = QFileInfo::exists(recoveryFilePath());
    QTimer::singleShot(0, this, [this] { offerRecovery(); });
}

AutosaveController::~AutosaveController() { m_timer.stop(); }

QString AutosaveController::recoveryFilePath()
{
    return QStandardPaths::writableLocation(QStandardPaths::AppDataLocation) + QStringLiteral("/recovery/autosave.sylva.json");
}

void AutosaveController::setInterval(int milliseconds)
{
    if (milliseconds <= 0) {
        m_timer.stop();
        return;
    }
    m_timer.start(milliseconds);
}

bool AutosaveController::autosaveNow()
{
    if (m_recoveryPending) return false;
    const Scene& s = m_doc->scene();
    if (!m_doc->isModified()) {
        removeRecoveryFile();
        return false;
    }
    if (m_doc->revision() == m_autosavedRevision && QFileInfo::exists(recoveryFilePath())) return false;
    try {
        writeSceneFile(s, recoveryFilePath().toStdString());
        QJsonObject o;
        o["file"] = m_doc->filePath();
        o["saved"] = QDateTime::currentDateTimeUtc().toString(Qt::ISODate);
        const QByteArray text = QJsonDocument(o).toJson();
        AtomicFile info(recoveryInfoPath().toStdString(), AtomicFile::Sync::Yes, "recovery file");
        info.write(text.constData(), size_t(text.size()));
        info.commit();
    } catch (const std::exception& e) {
        log(tr("autosave failed: %1").arg(QString::fromStdString(e.what())));
        return false;
    }
    m_autosavedRevision = m_doc->revision();
    Q_EMIT autosaved(recoveryFilePath());
    return true;
}

void AutosaveController::removeRecoveryFile()
{
    if (m_recoveryPending) return;
    QFile::remove(recoveryFilePath());
    QFile::remove(recoveryInfoPath());
    m_autosavedRevision = 0;
}

bool AutosaveController::offerRecovery()
{
    m_recoveryPending = false;
    const QString path = recoveryFilePath();
    if (!QFileInfo::exists(path)) return false;
    QString origin;
    QDateTime when = QFileInfo(path).lastModified();
    QFile info(recoveryInfoPath());
    if (info.open(QIODevice::ReadOnly)) {
        const QJsonObject o = QJsonDocument::fromJson(info.readAll()).object();
        origin = o["file"].toString();
        const QDateTime t = QDateTime::fromString(o["saved"].toString(), Qt::ISODate);
        if (t.isValid()) when = t.toLocalTime();
    }
    const bool recover = m_askRecover ? m_askRecover(origin, when) : false;
    bool recovered = false;
    if (recover) {
        try {
            const Scene scene = readSceneFile(path.toStdString());
            // On top of the saved file (undo shows what was saved), else of an empty untitled scene.
            bool based = false;
            if (!origin.isEmpty() && QFileInfo::exists(origin)) {
                try {
                    m_doc->open(origin);
                    based = true;
                } catch (const std::exception& e) {
                    log(tr("recovery: %1 cannot be read (%2); recovering as untitled").arg(origin, QString::fromStdString(e.what())));
                }
            }
            if (!based) m_doc->reset(Scene{}, QString());
            m_doc->edit(scene, tr("Recover unsaved changes"));
            log(tr("recovered unsaved changes%1").arg(origin.isEmpty() ? QString() : tr(" to %1").arg(origin)));
            recovered = true;
        } catch (const std::exception& e) {
            fail(tr("Recovery failed"), QString::fromStdString(e.what()));
        }
    }
    removeRecoveryFile();
    return recovered;
}

} // namespace sylva
