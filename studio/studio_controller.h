// The narrow interface between MainWindow and its controllers: a controller does one job of the
// window (autosave, lighting, exports, ...) and reports what happened as log lines and errors; the
// window shows them (the log view, the error reporter). Everything else goes through each
// controller's own methods and signals.
#pragma once

#include <QObject>
#include <QString>

namespace sylva {

class StudioController : public QObject {
    Q_OBJECT

public:
    using QObject::QObject;

Q_SIGNALS:
    // A line for the log view.
    void logLine(const QString& line);
    // A failure the user must see (title and message for the error reporter; also logged).
    void errorRaised(const QString& title, const QString& message);

protected:
    void log(const QString& line) { Q_EMIT logLine(line); }
    void fail(const QString& title, const QString& message) { Q_EMIT errorRaised(title, message); }
};

} // namespace sylva
