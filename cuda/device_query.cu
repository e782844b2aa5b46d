// CUDA device query: the first CUDA code path, proving the toolchain is wired.
#include "cuda/device_query.h"

#include <cuda_runtime.h>

namespace sylva::cuda {

namespace {
__global__ void addOne(int* value) { *value += 1; }
} // namespace

DeviceQuery queryDevices()
{
    DeviceQuery q;
    q.built = true;
    int count = 0;
    cudaError_t err = cudaGetDeviceCount(&count);
    if (err != cudaSuccess) {
        q.message = std::string("no CUDA device: ") + cudaGetErrorString(err);
        cudaGetLastError(); // clear the sticky error
        return q;
    }
    if (count == 0) {
        q.message = "no CUDA device found";
        return q;
    }
    for (int d = 0; d < count; ++d) {
        cudaDeviceProp prop{};
        if (cudaGetDeviceProperties(&prop, d) != cudaSuccess) continue;
        DeviceInfo info;
        info.index = d;
        info.name = prop.name;
        info.computeMajor = prop.major;
        info.computeMinor = prop.minor;
        info.totalMemoryBytes = prop.totalGlobalMem;
        info.multiprocessors = prop.multiProcessorCount;
        // A device that cannot run a trivial kernel is not usable.
        int* dValue = nullptr;
        int value = 41;
        bool ok = cudaSetDevice(d) == cudaSuccess && cudaMalloc(&dValue, sizeof(int)) == cudaSuccess &&
                  cudaMemcpy(dValue, &value, sizeof(int), cudaMemcpyHostToDevice) == cudaSuccess;
        if (ok) {
            addOne<<<1, 1>>>(dValue);
            ok = cudaMemcpy(&value, dValue, sizeof(int), cudaMemcpyDeviceToHost) == cudaSuccess && value == 42;
        }
        if (dValue) cudaFree(dValue);
        cudaGetLastError();
        if (ok) q.devices.push_back(info);
        else if (q.message.empty()) q.message = "CUDA device " + info.name + " failed a test kernel";
    }
    if (q.devices.empty() && q.message.empty()) q.message = "no usable CUDA device";
    return q;
}

} // namespace sylva::cuda
