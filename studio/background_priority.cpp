// Thread nice values through setpriority(PRIO_PROCESS, tid) on Linux; a no-op elsewhere.
#include "studio/background_priority.h"

#include <tbb/task_scheduler_observer.h>

#ifdef __linux__
#include <sys/resource.h>
#include <sys/syscall.h>
#include <unistd.h>
#endif

namespace sylva {
namespace {

constexpr int kBackgroundNice = 10;

class WorkerPriority : public tbb::task_scheduler_observer {
public:
    WorkerPriority() { observe(true); }
    ~WorkerPriority() override { observe(false); }
    void on_scheduler_entry(bool isWorker) override
    {
        if (isWorker) lowerCurrentThreadPriority();
    }
};

} // namespace

void lowerCurrentThreadPriority()
{
#ifdef __linux__
    const auto tid = id_t(syscall(SYS_gettid));
    const int current = getpriority(PRIO_PROCESS, tid);
    if (current < kBackgroundNice) setpriority(PRIO_PROCESS, tid, kBackgroundNice);
#endif
}

void lowerTbbWorkerPriority()
{
    static WorkerPriority observer;
    (void)observer;
}

} // namespace sylva
