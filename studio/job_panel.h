// Running jobs, one row each: title, progress bar with the current stage, cancel button.
#pragma once

#include <QHash>
#include <QWidget>

class QVBoxLayout;
class QLabel;

namespace sylva {

class Job;
class JobManager;

class JobPanel : public QWidget {
    Q_OBJECT

public:
    explicit JobPanel(JobManager* jobs, QWidget* parent = nullptr);
    int rowCount() const { return int(m_rows.size()); }

private:
    void addJob(Job* job);
    void removeJob(Job* job);

    QVBoxLayout* m_rowsLayout;
    QLabel* m_idle;
    QHash<Job*, QWidget*> m_rows;
};

} // namespace sylva
