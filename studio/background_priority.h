// Background work runs below the GUI thread: the UI stays responsive while jobs use every core.
#pragma once

namespace sylva {

// Lowers the calling thread's scheduling priority (Linux: nice +10 for this thread). Job threads and
// the viewport's render thread call it once when they start.
void lowerCurrentThreadPriority();

// From now on, oneTBB's worker threads lower their priority when they join (a global
// task_scheduler_observer). Call once, early, in the GUI process; idempotent.
void lowerTbbWorkerPriority();

} // namespace sylva
