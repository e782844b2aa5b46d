// One launch for the host and the device (after pbrt-v4's ParallelFor): a whole-image pass is written once
// as a template over an executor, and its per-item work as SYLVA_HD functors (bodies). HostExec runs the
// bodies with oneTBB; cuda/device_exec.cuh's CudaExec launches them as kernels over device memory.
//   exec.forEach(n, body)        body(i) for every i in [0, n)
//   exec.sum<K>(n, body, out)    out[k] = sum over i of t[k], where body(i, t) fills double t[K] (zeroed
//                                first); out is the executor's memory (host here, device for CudaExec),
//                                and later bodies may read it. n = 0 writes zeros.
//   exec.forEachRow(rows, len, body)  body(r, k0, k1) for every row r in [0, rows) of len items: the calls
//                                cover items [0, len) of each row, [k0, k1) at a time (the host passes
//                                whole rows, tasks of about kChunk items; the device one item a thread),
//                                so a body computes what a row shares once per call.
//   exec.sumRows<K>(rows, len, body, out)  host only: out[k] = sum over the rows of t[k], where
//                                body(r, 0, len, t) adds row r's terms to double t[K] (zeroed per row);
//                                the rows' sums are added in row order.
//   pipelineSlabs(n, stages, fn) host only: dependent passes over a grid's slabs, temporally blocked.
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <vector>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

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

    template <class Body>
    void forEachRow(size_t rows, size_t len, const Body& body) const
    {
        const size_t grain = len >= kChunk ? 1 : kChunk / (len > 0 ? len : 1);
        tbb::parallel_for(tbb::blocked_range<size_t>(0, rows, grain), [&](const tbb::blocked_range<size_t>& r) {
            for (size_t i = r.begin(); i != r.end(); ++i) body(i, size_t(0), len);
        });
    }

    template <int K, class Body>
    void sumRows(size_t rows, size_t len, const Body& body, double* out) const
    {
        std::vector<double> partial(rows * K, 0.0);
        forEachRow(rows, len, [&](size_t r, size_t k0, size_t k1) { body(r, k0, k1, &partial[r * K]); });
        for (int k = 0; k < K; ++k) out[k] = 0.0;
        for (size_t r = 0; r < rows; ++r)
            for (int k = 0; k < K; ++k) out[k] += partial[r * K + k];
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

// Runs stage(s, i) for the stages s = 0 .. stages - 1 over the slabs i of [0, n) (a grid's planes along its
// slowest axis), with each stage's result as if it ran over all slabs after the stage before it, but with a
// few slabs' data in cache across all the stages (temporal blocking). The contract: stage s on slab i reads
// only what stage s - 1 (or earlier) left on slabs i - 1 .. i + 1, and what it writes is read by no stage
// s' < s on slabs i - 1 .. i + 1 (so a red-black Gauss-Seidel sweep, writing one colour, may follow the other
// colour's; a transfer may write another array or the slab's own cells). The slabs are cut into chunks; each
// chunk runs its stages as a wavefront (stage s on slab t - s at step t) over the slabs that need nothing from
// the chunks beside it (a trapezoid: stage s stops s slabs short of each inner edge), then each inner edge
// finishes stages 1 .. over the 2s slabs around it. Every value is computed from the same inputs as in
// stage-by-stage passes, so the bits do not depend on the chunks or the thread count (tst_parallel checks
// both against those passes). Used by the smoke simulation's V-cycle (core/volume/smoke_multigrid.cpp).
template <class Stage>
void pipelineSlabs(int n, int stages, const Stage& stage)
{
    if (n <= 0 || stages <= 0) return;
    const int cap = std::max(1, 2 * tbb::this_task_arena::max_concurrency());
    const int chunks = std::max(1, std::min(n / std::max(2 * stages, 8), cap));   // 2 stages' slabs apart: the edges never meet
    const auto bound = [&](int c) { return int(int64_t(n) * c / chunks); };
    tbb::parallel_for(0, chunks, [&](int c) {
        const int a = bound(c), b = bound(c + 1);
        for (int t = a; t < b + stages - 1; ++t)
            for (int st = 0; st < stages; ++st) {
                const int i = t - st;
                const int lo = a == 0 ? 0 : a + st, hi = b == n ? n - 1 : b - 1 - st;
                if (i >= lo && i <= hi) stage(st, i);
            }
    });
    if (chunks > 1)
        tbb::parallel_for(1, chunks, [&](int c) {
            const int b = bound(c);
            for (int st = 1; st < stages; ++st)
                for (int i = b - st; i < b + st; ++i) stage(st, i);
        });
}

} // namespace sylva
