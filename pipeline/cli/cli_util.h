// Command-line helpers: exit codes, usage errors, number lists, and the progress bar on stderr.
#pragma once

#include <chrono>
#include <stdexcept>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "core/base/progress.h"

namespace sylva::cli {

enum ExitCode { kOk = 0, kFailure = 1, kUsage = 2 };

// Bad usage (unknown option, missing argument): exit code 2.
class UsageError : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

// Parses "a" (all three) or "a,b,c" into three finite numbers; throws UsageError naming the option.
glm::vec3 parseTriple(const std::string& option, const std::string& text);
// Parses a finite number / a whole number within [lo, hi]; throws UsageError naming the option.
double parseNumber(const std::string& option, const std::string& text);
long long parseInteger(const std::string& option, const std::string& text, long long lo, long long hi);
std::vector<std::string> splitList(const std::string& text);

// SIGINT (Ctrl-C) and SIGTERM cancel the running job: the first sets Progress::requestCancelAll(), so
// the job throws Cancelled at its next progress check and unwinds (AtomicFile removes its temporary
// files); main then exits with 128 + the signal (130 for SIGINT). A second signal removes the pending
// temporary files (removePendingAtomicFiles) and exits at once with the same code.
void cancelOnSignals();
// The signal that asked to cancel (SIGINT, SIGTERM), 0 when none came.
int cancelSignal();

// Draws progress on stderr: a bar when stderr is a terminal, plain "NN% message" lines every 10%
// otherwise. quiet: draw nothing.
class ProgressPrinter {
public:
    explicit ProgressPrinter(std::string label, bool quiet = false);
    ~ProgressPrinter();
    Progress& progress() { return m_progress; }
    void finish(const std::string& summary = {});

private:
    void draw(double fraction, const std::string& message);
    std::string m_label;
    bool m_quiet, m_tty, m_done = false;
    int m_lastDecile = -1;
    std::chrono::steady_clock::time_point m_start, m_lastDraw;
    Progress m_progress;
};

} // namespace sylva::cli
