// Host/device annotation and kernel assert: the only place that spells __device__.
#pragma once

#if defined(__CUDACC__)
#define SYLVA_HD __host__ __device__
#define SYLVA_DEVICE __device__
#define SYLVA_INLINE __forceinline__
#else
#define SYLVA_HD
#define SYLVA_DEVICE
#define SYLVA_INLINE inline __attribute__((always_inline))
#endif

// Fully unroll a short loop with a constant trip count (keeps per-node values in registers).
#if defined(__CUDA_ARCH__)
#define SYLVA_UNROLL _Pragma("unroll")
#elif defined(__CUDACC__)
#define SYLVA_UNROLL   // the host pass of a .cu file: no per-node loops run there
#elif defined(__GNUC__) && !defined(__clang__)
#define SYLVA_UNROLL _Pragma("GCC unroll 32")
#elif defined(__clang__)
#define SYLVA_UNROLL _Pragma("unroll")
#else
#define SYLVA_UNROLL
#endif

#if defined(__CUDA_ARCH__)
#define SYLVA_KERNEL_ASSERT(cond) ((void)0)
#else
#include <cassert>
#define SYLVA_KERNEL_ASSERT(cond) assert(cond)
#endif
