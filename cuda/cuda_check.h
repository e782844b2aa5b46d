// CUDA runtime errors as BackendError (one line for the user; the caller falls back to the CPU).
#pragma once

#include <string>

#include <cuda_runtime.h>

#include "core/backend/backend.h"

namespace sylva::cuda {

inline void check(cudaError_t err, const char* what)
{
    if (err == cudaSuccess) return;
    cudaGetLastError();   // clear a non-sticky error
    if (err == cudaErrorMemoryAllocation)
        throw BackendError(std::string("CUDA: out of device memory (") + what + ")");
    throw BackendError(std::string("CUDA: ") + what + ": " + cudaGetErrorString(err));
}

// A device allocation freed on scope exit.
template <typename T>
class DeviceBuffer {
public:
    DeviceBuffer() = default;
    explicit DeviceBuffer(size_t count, const char* what = "allocation") { allocate(count, what); }
    DeviceBuffer(const DeviceBuffer&) = delete;
    DeviceBuffer& operator=(const DeviceBuffer&) = delete;
    DeviceBuffer(DeviceBuffer&& o) noexcept : m_ptr(o.m_ptr), m_count(o.m_count) { o.m_ptr = nullptr, o.m_count = 0; }
    DeviceBuffer& operator=(DeviceBuffer&& o) noexcept
    {
        std::swap(m_ptr, o.m_ptr);
        std::swap(m_count, o.m_count);
        return *this;
    }
    ~DeviceBuffer()
    {
        if (m_ptr) cudaFree(m_ptr);
    }
    void allocate(size_t count, const char* what = "allocation")
    {
        if (m_ptr) cudaFree(m_ptr);
        m_ptr = nullptr;
        m_count = count;
        if (count) check(cudaMalloc(reinterpret_cast<void**>(&m_ptr), count * sizeof(T)), what);
    }
    void upload(const T* host, size_t count, const char* what = "upload")
    {
        allocate(count, what);
        if (count) check(cudaMemcpy(m_ptr, host, count * sizeof(T), cudaMemcpyHostToDevice), what);
    }
    void download(T* host, size_t count, const char* what = "download") const
    {
        if (count) check(cudaMemcpy(host, m_ptr, count * sizeof(T), cudaMemcpyDeviceToHost), what);
    }
    T* get() const { return m_ptr; }
    size_t size() const { return m_count; }

private:
    T* m_ptr = nullptr;
    size_t m_count = 0;
};

} // namespace sylva::cuda
