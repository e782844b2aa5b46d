// Progress, cancellation and exceptions of the Python module's jobs.
#include "python/job_context.h"

#include <algorithm>
#include <cmath>

namespace py = pybind11;

namespace sylva::python {

JobContext::JobContext(py::object callback, std::shared_ptr<CancelToken> token)
    : m_callback(std::move(callback)), m_token(std::move(token))
{
    if (m_callback.is_none()) m_callback = py::object();
    m_progress.setCallback([this](double fraction, const std::string& message) { report(fraction, message); });
}

void JobContext::report(double fraction, const std::string& message)
{
    // Serialized by the Progress. The token is read without the GIL; Python is entered once a percent or message.
    if (m_token && m_token->cancelled.load(std::memory_order_relaxed)) m_progress.cancel();
    if (m_progress.isCancelled()) return;
    const int percent = int(std::floor(std::clamp(fraction, 0.0, 1.0) * 100.0));
    if (percent == m_lastPercent && message == m_lastMessage) return;
    m_lastPercent = percent;
    m_lastMessage = message;
    py::gil_scoped_acquire gil;
    try {
        if (PyErr_CheckSignals() != 0) throw py::error_already_set();   // Ctrl+C on the main thread
        if (m_callback) {
            const py::object answer = m_callback(fraction, message);
            if (answer.is(py::bool_(false))) m_progress.cancel();
        }
    } catch (py::error_already_set&) {
        m_callbackError = std::current_exception();
        m_progress.cancel();
    }
}

void JobContext::rethrowCancelled()
{
    if (m_callbackError) std::rethrow_exception(m_callbackError);
    throw Cancelled();
}

} // namespace sylva::python
