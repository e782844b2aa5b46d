// Background jobs: a function run on Qt's thread pool with a Progress bridged to signals, cancel, and a log.
#pragma once

#include <atomic>
#include <functional>
#include <memory>
#include <mutex>

#include <QFutureWatcher>
#include <QList>
#include <QObject>
#include <QString>

#include "core/base/progress.h"

namespace sylva {

// One running or finished job. Lives in the GUI thread; its work runs on a pool thread
// (QtConcurrent::run) and talks to it only through Progress and log(), both thread-safe.
class Job : public QObject {
    Q_OBJECT

public:
    enum class State { Running, Succeeded, Cancelled, Failed };

    // Runs on the pool thread. Throws Error (failure) or Cancelled.
    using Work = std::function<void(Job& job, Progress& progress)>;

    Job(int id, const QString& title, QObject* parent = nullptr);
    ~Job() override;

    int id() const { return m_id; }
    QString title() const { return m_title; }
    State state() const { return m_state; }
    bool isRunning() const { return m_state == State::Running; }
    double fraction() const { return m_fraction; }
    QString message() const { return m_message; }
    QString error() const { return m_error; }
    double seconds() const { return m_seconds; }

    // Thread-safe: a log line for the log view.
    void log(const QString& line);
    // Thread-safe: asks the work to stop at its next progress report.
    void cancel();
    bool cancelRequested() const { return m_progress.isCancelled(); }
    // Blocks until the work has returned (GUI thread; for shutdown and tests).
    void waitForFinished();

    void start(Work work);

Q_SIGNALS:
    void progressChanged(double fraction, const QString& message);
    void logLine(const QString& line);
    void finished(sylva::Job* job);   // state() says how; error() why it failed

private:
    void flushProgress();
    void onWorkDone();

    const int m_id;
    const QString m_title;
    State m_state = State::Running;
    double m_fraction = 0.0;
    QString m_message;
    QString m_error;
    double m_seconds = 0.0;
    qint64 m_startMs = 0;

    Progress m_progress;
    // Latest report from the worker, coalesced: at most one queued update in flight.
    std::mutex m_pendingMutex;
    double m_pendingFraction = 0.0;
    std::string m_pendingMessage;
    std::atomic<bool> m_updateQueued{false};
    // progressChanged at most every kProgressIntervalMs: every repaint costs the GUI thread a frame.
    static constexpr int kProgressIntervalMs = 100;
    qint64 m_lastProgressMs = 0;
    // Set by the worker when it ends.
    QString m_workError;
    bool m_workCancelled = false;
    QFutureWatcher<void> m_watcher;
};

// Starts jobs and keeps the running ones; the job panel lists them.
class JobManager : public QObject {
    Q_OBJECT

public:
    explicit JobManager(QObject* parent = nullptr);
    ~JobManager() override;

    // done(job) runs in the GUI thread after the work returned (any state), before finished is emitted.
    Job* start(const QString& title, Job::Work work, std::function<void(Job*)> done = {});
    QList<Job*> running() const;
    bool isBusy() const { return !running().isEmpty(); }
    void cancelAll();
    void waitForAll();

Q_SIGNALS:
    void jobStarted(sylva::Job* job);
    void jobFinished(sylva::Job* job);
    void logLine(const QString& line);

private:
    QList<Job*> m_jobs;
    int m_nextId = 1;
};

} // namespace sylva
