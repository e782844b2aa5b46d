// What the files of `sylva render --mpi` share (mpi_session.cpp defines the functions): the clock, the message
// tags and the pace of the messages, MPI's error codes as exceptions, the end of a failed job, the bound on
// MPI's blocking calls. Internal to pipeline/mpi: it includes the MPI header.
//
// Threads: every MPI call is made by the process's main thread (MPI_THREAD_FUNNELED). The long work
// (loading the scene, rank 0's render, a worker's tile) runs in a second thread while the main thread
// sends and receives heartbeats, so a rank busy for minutes is still heard from twice a second.
#pragma once

#include <mpi.h>

#include <chrono>
#include <condition_variable>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <mutex>
#include <string>
#include <thread>

#include <tbb/global_control.h>

namespace sylva::mpi {

using Clock = std::chrono::steady_clock;

// Message tags. Workers send kHeartbeat, kRequest (the tile they finished, if any, and a request for
// the next), kFailed (an error text), kLit (its species' lighting is done) and kReady (it holds the
// memory for the scene's arrays); rank 0 sends kTile, kDone, kHeartbeat (to waiting ranks) and kShare (light
// your share of the species: rank 0's render missed in the cache).
enum Tag : int { kFailed = 11, kHeartbeat = 12, kRequest = 13, kTile = 14, kDone = 15, kLit = 16, kReady = 17, kShare = 18 };

constexpr double kHeartbeatSeconds = 0.5;

// Tiles a worker asks for ahead: it traces one while the result of the last one travels and the
// answer to its next request comes back, so its render thread never waits on a round trip (one
// ahead left a worker idle about half of a frame: 2.5-4 ms a tile measured, against 3-4 ms of
// tracing, on the 2-core VM whose cores both trace).
constexpr int kAhead = 2;

// The pause between two looks for messages of rank 0's main thread and of a worker's while it traces
// (a worker's finished tile wakes it at once). With kAhead tiles asked for, an answer may take this
// long; looking every 200 us instead made the frame no faster (medians of 4 interleaved runs: 0.75 s
// against 0.66 s), its wake-ups taking time from the two tracing threads on the 2-core VM.
constexpr auto kPollPause = std::chrono::milliseconds(1);

inline double since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

// Throws Error naming `what` and MPI's text when rc is not MPI_SUCCESS.
void check(int rc, const char* what);

// "rank N" (built without string concatenation, which GCC 12 warns about falsely).
std::string rankName(int r);

// This machine's host name ("?" when unknown).
std::string hostName();

// Reports an error on this rank's stderr and ends the whole job (every rank, exit 1).
[[noreturn]] void abortJob(const std::string& message);

// "sylva render: error: ...; no picture was written" for a Deadline's message.
std::string jobError(const std::string& what);

// The integer in environment variable `name`, or fallback when it is unset or empty.
int envInt(const char* name, int fallback);

// Ends this process (exit 1, `message` on stderr) unless disarmed within `seconds`: bounds MPI's blocking
// calls (the start, collectives over the ranks of a host), which a rank that died or hung before reaching
// them would hold forever. mpirun then stops the other ranks.
class Deadline {
public:
    Deadline(double seconds, std::string message)
        : m_thread([this, seconds, message = std::move(message)] {
              std::unique_lock<std::mutex> lock(m_mutex);
              if (m_cv.wait_for(lock, std::chrono::duration<double>(seconds), [&] { return m_disarmed; })) return;
              std::fprintf(stderr, "%s\n", message.c_str());
              std::fflush(stderr);
              std::_Exit(1);
          })
    {
    }
    Deadline(const Deadline&) = delete;
    Deadline& operator=(const Deadline&) = delete;
    ~Deadline() { disarm(); }

    void disarm()
    {
        if (!m_thread.joinable()) return;
        {
            std::lock_guard<std::mutex> lock(m_mutex);
            m_disarmed = true;
        }
        m_cv.notify_all();
        m_thread.join();
    }

private:
    std::mutex m_mutex;
    std::condition_variable m_cv;
    bool m_disarmed = false;
    std::thread m_thread;   // last: it starts once the members above exist
};

// A limit of oneTBB's threads to `threads` while it lives (none for 0).
inline std::unique_ptr<tbb::global_control> threadLimit(int threads)
{
    if (threads <= 0) return nullptr;
    return std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism, size_t(threads));
}

} // namespace sylva::mpi
