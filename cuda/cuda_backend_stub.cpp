// Builds without nvcc: there is no CUDA backend, every request falls back to the CPU.
#include "cuda/cuda_backend.h"

namespace sylva::cuda {

std::unique_ptr<Backend> makeCudaBackend(std::string* why)
{
    if (why) *why = "this build has no CUDA backend (nvcc was not found at configure time)";
    return nullptr;
}

} // namespace sylva::cuda
