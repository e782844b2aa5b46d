// One launch for the host and the device (after pbrt-v4's ParallelFor): a whole-image pass is written once
// as a template over an executor, and its per-item work as SYLVA_HD functors (bodies). HostExec runs the
// bodies with oneTBB; cuda/device_exec.cuh's CudaExec launches them as kernels over device memory.
//   exec.forEach(n, body)        body(i) for every i in [0, n)
//   exec.sum<K>(n, body, out)    out[k] = sum over i of t[k], where body(i, t) fills double t[K] (zeroed
//                                first); out is the executor's memory (host here, device for CudaExec),
//                                and later bodies may read it. n = 0 writes zeros.
#pragma once

#include <cstddef>
#include <vector>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

namespace sylva {

struct HostExec {
    // Items per task. Sums run over chunks of this many items counted from 0, added in chunk order, so
    // the result does not depend on the thread count (LogAverageAccumulator uses the same rule).
    static constexpr size_t kChunk = 16384;

    template <class Body>
    void forEach(size_t n, const Body& body) const
    {
        tbb::parallel_for(tbb::blocked_range<size_t>(0, n, kChunk), [&](const tbb::blocked_range<size_t>& r) {
            for (size_t i = r.begin(); i != r.end(); ++i) body(i);
        });
    }

    template <int K, class Body>
    void sum(size_t n, const Body& body, double* out) const
    {
        const size_t chunks = (n + kChunk - 1) / kChunk;
        std::vector<double> partial(chunks * K, 0.0);
        tbb::parallel_for(size_t(0), chunks, [&](size_t c) {
            double* acc = &partial[c * K];
            const size_t end = (c + 1) * kChunk < n ? (c + 1) * kChunk : n;
            for (size_t i = c * kChunk; i != end; ++i) {
                double t[K] = {};
                body(i, t);
                for (int k = 0; k < K; ++k) acc[k] += t[k];
            }
        });
        for (int k = 0; k < K; ++k) out[k] = 0.0;
        for (size_t c = 0; c < chunks; ++c)
            for (int k = 0; k < K; ++k) out[k] += partial[c * K + k];
    }
};

} // namespace sylva
