// JobPanel: a QProgressBar per job fed by Job::progressChanged; the cancel button calls Job::cancel.
#include "studio/job_panel.h"

#include <QHBoxLayout>
#include <QLabel>
#include <QProgressBar>
#include <QToolButton>
#include <QVBoxLayout>

#include "studio/job_manager.h"

namespace sylva {

JobPanel::JobPanel(JobManager* jobs, QWidget* parent) : QWidget(parent)
{
    auto* outer = new QVBoxLayout(this);
    outer->setContentsMargins(4, 4, 4, 4);
    m_idle = new QLabel(tr("No jobs running."));
    outer->addWidget(m_idle);
    m_rowsLayout = new QVBoxLayout;
    outer->addLayout(m_rowsLayout);
    outer->addStretch(1);
    connect(jobs, &JobManager::jobStarted, this, &JobPanel::addJob);
    connect(jobs, &JobManager::jobFinished, this, &JobPanel::removeJob);
}

void JobPanel::addJob(Job* job)
{
    auto* row = new QWidget;
    auto* l = new QHBoxLayout(row);
    l->setContentsMargins(0, 0, 0, 0);
    auto* title = new QLabel(job->title());
    auto* bar = new QProgressBar;
    bar->setRange(0, 1000);
    bar->setValue(0);
    bar->setFormat(tr("starting"));
    bar->setTextVisible(true);
    bar->setMinimumWidth(160);
    auto* cancel = new QToolButton;
    cancel->setText(tr("Cancel"));
    cancel->setObjectName("cancel");
    l->addWidget(title);
    l->addWidget(bar, 1);
    l->addWidget(cancel);
    connect(cancel, &QToolButton::clicked, job, [job, cancel] {
        job->cancel();
        cancel->setEnabled(false);
    });
    connect(job, &Job::progressChanged, bar, [bar](double fraction, const QString& message) {
        bar->setValue(int(fraction * 1000.0));
        bar->setFormat(QStringLiteral("%p% ") + message);
    });
    m_rowsLayout->addWidget(row);
    m_rows.insert(job, row);
    m_idle->setVisible(m_rows.isEmpty());
}

void JobPanel::removeJob(Job* job)
{
    if (QWidget* row = m_rows.take(job)) row->deleteLater();
    m_idle->setVisible(m_rows.isEmpty());
}

} // namespace sylva
