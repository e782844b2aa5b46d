// Command-line helpers: number parsing with messages that name the option, and the progress bar.
#include "pipeline/cli/cli_util.h"

#include <cmath>
#include <csignal>
#include <cstdio>
#include <sstream>
#include <unistd.h>

#include "pipeline/io/atomic_file.h"

namespace sylva::cli {

namespace {

volatile std::sig_atomic_t g_cancelSignal = 0;

void onCancelSignal(int sig)
{
    if (g_cancelSignal != 0) {
        // The second: no unwinding, only what is async-signal-safe.
        removePendingAtomicFiles();
        static const char message[] = "\nsylva: interrupted again: stopped at once\n";
        (void)!::write(2, message, sizeof message - 1);
        ::_exit(128 + sig);
    }
    g_cancelSignal = sig;
    Progress::requestCancelAll();
}

} // namespace

void cancelOnSignals()
{
    struct sigaction action {};
    action.sa_handler = &onCancelSignal;
    sigemptyset(&action.sa_mask);
    action.sa_flags = SA_RESTART;   // reads and writes in progress go on; the job stops at its next check
    ::sigaction(SIGINT, &action, nullptr);
    ::sigaction(SIGTERM, &action, nullptr);
}

int cancelSignal()
{
    return int(g_cancelSignal);
}

double parseNumber(const std::string& option, const std::string& text)
{
    size_t used = 0;
    double v = 0;
    try {
        v = std::stod(text, &used);
    } catch (...) {
        used = 0;
    }
    if (used == 0 || used != text.size() || !std::isfinite(v))
        throw UsageError("option " + option + ": '" + text + "' is not a finite number");
    return v;
}

long long parseInteger(const std::string& option, const std::string& text, long long lo, long long hi)
{
    size_t used = 0;
    long long v = 0;
    try {
        v = std::stoll(text, &used);
    } catch (...) {
        used = 0;
    }
    if (used == 0 || used != text.size())
        throw UsageError("option " + option + ": '" + text + "' is not a whole number");
    if (v < lo || v > hi)
        throw UsageError("option " + option + ": " + text + " is outside [" + std::to_string(lo) + ", " +
                         std::to_string(hi) + "]");
    return v;
}

std::vector<std::string> splitList(const std::string& text)
{
    std::vector<std::string> parts;
    std::stringstream ss(text);
    std::string item;
    while (std::getline(ss, item, ',')) parts.push_back(item);
    if (!text.empty() && text.back() == ',') parts.emplace_back();
    return parts;
}

glm::vec3 parseTriple(const std::string& option, const std::string& text)
{
    const std::vector<std::string> parts = splitList(text);
    if (parts.size() == 1) {
        const float v = float(parseNumber(option, parts[0]));
        return glm::vec3(v);
    }
    if (parts.size() != 3)
        throw UsageError("option " + option + ": expected one number or three comma-separated numbers, got '" + text + "'");
    return {float(parseNumber(option, parts[0])), float(parseNumber(option, parts[1])), float(parseNumber(option, parts[2]))};
}

ProgressPrinter::ProgressPrinter(std::string label, bool quiet)
    : m_label(std::move(label)), m_quiet(quiet), m_tty(::isatty(2) != 0), m_start(std::chrono::steady_clock::now())
{
    m_progress.setCallback([this](double f, const std::string& msg) { draw(f, msg); });
}

ProgressPrinter::~ProgressPrinter()
{
    if (!m_done && m_tty && !m_quiet && m_lastDecile >= 0) std::fputc('\n', stderr);
}

void ProgressPrinter::draw(double fraction, const std::string& message)
{
    if (m_quiet) return;
    fraction = std::clamp(fraction, 0.0, 1.0);
    const auto now = std::chrono::steady_clock::now();
    if (m_tty) {
        if (fraction < 1.0 && m_lastDecile >= 0 && now - m_lastDraw < std::chrono::milliseconds(80)) return;
        m_lastDraw = now;
        m_lastDecile = 0;
        const int width = 30, filled = int(fraction * width + 0.5);
        std::string bar(size_t(filled), '#');
        bar.append(size_t(width - filled), '.');
        std::fprintf(stderr, "\r%s [%s] %3d%% %-40.40s", m_label.c_str(), bar.c_str(), int(fraction * 100 + 0.5),
                     message.c_str());
        std::fflush(stderr);
    } else {
        const int decile = int(fraction * 10.0 + 1e-9);
        if (decile <= m_lastDecile) return;
        m_lastDecile = decile;
        std::fprintf(stderr, "%s: %d%% %s\n", m_label.c_str(), decile * 10, message.c_str());
    }
}

void ProgressPrinter::finish(const std::string& summary)
{
    if (m_quiet) return;
    const double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - m_start).count();
    if (m_tty && m_lastDecile >= 0) std::fputc('\r', stderr), std::fprintf(stderr, "%-90s\r", "");
    std::fprintf(stderr, "%s: done in %.2f s%s%s\n", m_label.c_str(), secs, summary.empty() ? "" : ": ", summary.c_str());
    m_done = true;
}

} // namespace sylva::cli
