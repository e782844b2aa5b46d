// The benchmarks' clock and repeated timings, once.
#pragma once

#include <algorithm>
#include <chrono>
#include <vector>

namespace sylva::bench {

// Seconds on a steady clock.
inline double now() { return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count(); }

// Median and minimum of repeated timings, seconds.
struct Timing {
    double median = 0.0, min = 0.0;
};

// Runs f `reps` times (at least once) and times each run.
template <class F>
Timing timeReps(int reps, F&& f)
{
    std::vector<double> t;
    for (int r = 0; r < std::max(1, reps); ++r) {
        const double t0 = now();
        f();
        t.push_back(now() - t0);
    }
    std::sort(t.begin(), t.end());
    return {t[t.size() / 2], t.front()};
}

} // namespace sylva::bench
