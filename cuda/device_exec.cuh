// The device executor of core/base/parallel.h: the same bodies as HostExec, launched as kernels over device
// memory (256 threads per block; one atomic add per block and term for sums).
#pragma once

#include <cstddef>

#include "cuda/cuda_check.h"

namespace sylva::cuda {

namespace exec_detail {

constexpr int kThreads = 256;

// Block-wide sum of one double per thread, added to *out by one atomic per block (blockDim.x == kThreads).
__device__ inline void blockSum(double v, double* out)
{
    __shared__ double warpSums[kThreads / 32];
    __syncthreads();   // warpSums may still be read for the previous term
    for (int o = 16; o > 0; o >>= 1) v += __shfl_down_sync(0xffffffffu, v, o);
    const int lane = int(threadIdx.x) & 31, warp = int(threadIdx.x) >> 5;
    if (lane == 0) warpSums[warp] = v;
    __syncthreads();
    if (warp == 0) {
        v = lane < kThreads / 32 ? warpSums[lane] : 0.0;
        for (int o = kThreads / 64; o > 0; o >>= 1) v += __shfl_down_sync(0xffffffffu, v, o);
        if (lane == 0) atomicAdd(out, v);
    }
}

template <class Body>
__global__ void forEachKernel(size_t n, Body body)
{
    const size_t i = size_t(blockIdx.x) * blockDim.x + threadIdx.x;
    if (i < n) body(i);
}

template <class Body>
__global__ void forEachRowKernel(size_t n, size_t len, Body body)
{
    const size_t i = size_t(blockIdx.x) * blockDim.x + threadIdx.x;
    if (i < n) body(i / len, i % len, i % len + 1);
}

template <int K, class Body>
__global__ void sumKernel(size_t n, Body body, double* out)
{
    const size_t i = size_t(blockIdx.x) * blockDim.x + threadIdx.x;
    double t[K] = {};
    if (i < n) body(i, t);
    for (int k = 0; k < K; ++k) blockSum(t[k], &out[k]);
}

} // namespace exec_detail

// Blocks of `threads` threads that cover n items (kernels outside the executor use it too).
inline unsigned blocksFor(size_t n, int threads = exec_detail::kThreads)
{
    return unsigned((n + size_t(threads) - 1) / size_t(threads));
}

struct CudaExec {
    template <class Body>
    void forEach(size_t n, const Body& body) const
    {
        if (n == 0) return;
        exec_detail::forEachKernel<<<blocksFor(n), exec_detail::kThreads>>>(n, body);
        check(cudaGetLastError(), "kernel launch");
    }

    template <class Body>
    void forEachRow(size_t rows, size_t len, const Body& body) const
    {
        const size_t n = rows * len;
        if (n == 0) return;
        exec_detail::forEachRowKernel<<<blocksFor(n), exec_detail::kThreads>>>(n, len, body);
        check(cudaGetLastError(), "kernel launch");
    }

    template <int K, class Body>
    void sum(size_t n, const Body& body, double* out) const
    {
        check(cudaMemsetAsync(out, 0, K * sizeof(double)), "sum reset");
        if (n == 0) return;
        exec_detail::sumKernel<K><<<blocksFor(n), exec_detail::kThreads>>>(n, body, out);
        check(cudaGetLastError(), "sum kernel launch");
    }
};

} // namespace sylva::cuda
