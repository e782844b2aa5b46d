// What every job of the Python module shares: the GIL released while C++ works, a Progress whose reports reach a
// Python callback (from any thread), cancellation by the callback, a CancelToken or Ctrl+C, and the job's errors as
// Python exceptions.
#pragma once

#include <pybind11/pybind11.h>

#include <atomic>
#include <exception>
#include <memory>
#include <string>

#include "core/base/progress.h"

namespace sylva::python {

// A flag another Python thread sets to stop a running job (sylva.CancelToken).
struct CancelToken {
    std::atomic<bool> cancelled{false};
};

// One job's progress. The callback is called as callback(fraction, message) with the GIL held, at most once per
// percent and message change; a False return or an exception stops the job (the exception is raised after it).
class JobContext {
public:
    JobContext(pybind11::object callback, std::shared_ptr<CancelToken> token);

    Progress& progress() { return m_progress; }

    // Runs work with the GIL released and translates the outcome: sylva::Cancelled becomes sylva.Cancelled, or the
    // callback's own exception; sylva::Error becomes sylva.Error. Call with the GIL held.
    template <class F>
    auto run(F&& work) -> decltype(work())
    {
        try {
            pybind11::gil_scoped_release release;
            return work();
        } catch (const Cancelled&) {
            rethrowCancelled();
            throw;
        }
    }

private:
    void report(double fraction, const std::string& message);
    [[noreturn]] void rethrowCancelled();

    pybind11::object m_callback;
    std::shared_ptr<CancelToken> m_token;
    Progress m_progress;
    std::exception_ptr m_callbackError;   // set with the GIL held
    int m_lastPercent = -1;
    std::string m_lastMessage;
};

} // namespace sylva::python
