// Job and JobManager: QtConcurrent::run + QFutureWatcher, Progress coalesced into queued signals.
#include "studio/job_manager.h"

#include <QDateTime>
#include <QMetaObject>
#include <QTimer>
#include <QtConcurrent/QtConcurrentRun>

#include "core/base/error.h"
#include "studio/background_priority.h"

namespace sylva {

Job::Job(int id, const QString& title, QObject* parent) : QObject(parent), m_id(id), m_title(title)
{
    m_progress.setCallback([this](double fraction, const std::string& message) {
        {
            std::lock_guard lock(m_pendingMutex);
            m_pendingFraction = fraction;
            if (!message.empty()) m_pendingMessage = message;
        }
        // Coalesce: the GUI thread sees the latest value, never a backlog of thousands of reports.
        if (!m_updateQueued.exchange(true)) QMetaObject::invokeMethod(this, &Job::flushProgress, Qt::QueuedConnection);
    });
    connect(&m_watcher, &QFutureWatcher<void>::finished, this, &Job::onWorkDone);
}

Job::~Job()
{
    cancel();
    m_watcher.waitForFinished();
}

void Job::log(const QString& line)
{
    QMetaObject::invokeMethod(this, [this, line] { Q_EMIT logLine(line); }, Qt::QueuedConnection);
}

void Job::cancel() { m_progress.cancel(); }

void Job::waitForFinished() { m_watcher.waitForFinished(); }

void Job::start(Work work)
{
    m_startMs = QDateTime::currentMSecsSinceEpoch();
    m_watcher.setFuture(QtConcurrent::run([this, work = std::move(work)] {
        lowerCurrentThreadPriority();
        try {
            work(*this, m_progress);
        } catch (const Cancelled&) {
            m_workCancelled = true;
        } catch (const std::exception& e) {
            if (m_progress.isCancelled()) m_workCancelled = true;
            else m_workError = QString::fromStdString(e.what());
        }
    }));
}

void Job::flushProgress()
{
    if (m_state != State::Running) return;
    const qint64 now = QDateTime::currentMSecsSinceEpoch();
    if (now - m_lastProgressMs < kProgressIntervalMs) {
        QTimer::singleShot(int(kProgressIntervalMs - (now - m_lastProgressMs)), this, &Job::flushProgress);
        return;
    }
    m_lastProgressMs = now;
    m_updateQueued.store(false);
    {
        std::lock_guard lock(m_pendingMutex);
        m_fraction = m_pendingFraction;
        m_message = QString::fromStdString(m_pendingMessage);
    }
    Q_EMIT progressChanged(m_fraction, m_message);
}

void Job::onWorkDone()
{
    m_seconds = double(QDateTime::currentMSecsSinceEpoch() - m_startMs) / 1000.0;
    if (m_workCancelled) {
        m_state = State::Cancelled;
    } else if (!m_workError.isEmpty()) {
        m_state = State::Failed;
        m_error = m_workError;
    } else {
        m_state = State::Succeeded;
        m_fraction = 1.0;
    }
    Q_EMIT progressChanged(m_fraction, m_message);
    Q_EMIT finished(this);
}

JobManager::JobManager(QObject* parent) : QObject(parent) {}

JobManager::~JobManager()
{
    cancelAll();
    waitForAll();
}

Job* JobManager::start(const QString& title, Job::Work work, std::function<void(Job*)> done)
{
    auto* job = new Job(m_nextId++, title, this);
    m_jobs.append(job);
    connect(job, &Job::logLine, this, &JobManager::logLine);
    // The job's own finished comes first (it updates its state); then done, then the manager's signal.
    connect(job, &Job::finished, this, [this, done = std::move(done)](Job* j) {
        // Log lines are queued before the work returns, so they precede this.
        if (done) done(j);
        m_jobs.removeOne(j);
        Q_EMIT jobFinished(j);
        j->deleteLater();
    });
    Q_EMIT jobStarted(job);
    job->start(std::move(work));
    return job;
}

QList<Job*> JobManager::running() const
{
    QList<Job*> out;
    for (Job* j : m_jobs)
        if (j->isRunning()) out.append(j);
    return out;
}

void JobManager::cancelAll()
{
    for (Job* j : m_jobs) j->cancel();
}

void JobManager::waitForAll()
{
    for (Job* j : m_jobs) j->waitForFinished();
}

} // namespace sylva
