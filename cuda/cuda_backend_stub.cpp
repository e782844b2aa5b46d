// Builds without nvcc: there is no CUDA backend, every request falls back to the CPU.
#include "cuda/cuda_backend.h"

namespace sylva::cuda {

namespace {
const char* const kNoCuda = "this build has no CUDA backend (configured without CUDA: nvcc missing or older than 12, or SYLVA_ENABLE_CUDA=OFF)";
}

std::unique_ptr<Backend> makeCudaBackend(std::string* why)
{
    if (why) *why = kNoCuda;
    return nullptr;
}

std::unique_ptr<DeviceDisplay> makeCudaDisplay(std::string* why)
{
    if (why) *why = kNoCuda;
    return nullptr;
}

std::unique_ptr<DeviceFrame> uploadCudaFrame(const RenderScene&) { throw BackendError(kNoCuda); }

} // namespace sylva::cuda
