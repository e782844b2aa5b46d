// Progress and cancel for long jobs: a GUI-free object the CLI draws as a bar and the studio bridges to signals.
#pragma once

#include <atomic>
#include <functional>
#include <mutex>
#include <string>

#include "core/base/error.h"

namespace sylva {

class Progress {
public:
    // fraction in [0,1]; called from any thread, serialized by the Progress object.
    using Callback = std::function<void(double fraction, const std::string& message)>;

    Progress() = default;
    explicit Progress(Callback callback) : m_callback(std::move(callback)) {}

    void setCallback(Callback callback) { m_callback = std::move(callback); }

    // Reports progress; throws Cancelled when cancel() was called.
    void report(double fraction, const std::string& message = {})
    {
        if (m_callback) {
            std::lock_guard lock(m_mutex);
            m_callback(fraction, message);
        }
        throwIfCancelled();
    }

    void cancel() { m_cancelled.store(true, std::memory_order_relaxed); }
    bool isCancelled() const { return m_cancelled.load(std::memory_order_relaxed) || cancelAllRequested(); }

    // A process-wide cancel: every Progress reports cancelled from then on, the sub-progress objects
    // of a job included. The CLI's SIGINT/SIGTERM handler calls it (a lock-free atomic store, so it is
    // async-signal-safe); nothing resets it.
    static void requestCancelAll() noexcept { s_cancelAll.store(true, std::memory_order_relaxed); }
    static bool cancelAllRequested() noexcept { return s_cancelAll.load(std::memory_order_relaxed); }
    void throwIfCancelled() const
    {
        if (isCancelled()) throw Cancelled();
    }

private:
    Callback m_callback;
    std::mutex m_mutex;
    std::atomic<bool> m_cancelled{false};
    inline static std::atomic<bool> s_cancelAll{false};
    static_assert(std::atomic<bool>::is_always_lock_free, "requestCancelAll must be async-signal-safe");
};

// Maps [0,1] of a sub-job onto [begin,end] of a parent's progress.
class SubProgress {
public:
    SubProgress(Progress* parent, double begin, double end) : m_parent(parent), m_begin(begin), m_end(end) {}
    void report(double fraction, const std::string& message = {})
    {
        if (m_parent) m_parent->report(m_begin + (m_end - m_begin) * fraction, message);
    }

private:
    Progress* m_parent;
    double m_begin, m_end;
};

} // namespace sylva
