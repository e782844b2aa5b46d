// The CUDA backend: the LB solve and the frame on an NVIDIA GPU, the same per-node and per-pixel code as the CPU.
#pragma once

#include <memory>
#include <string>

#include "core/backend/backend.h"

namespace sylva::cuda {

// Creates the CUDA backend on the first usable device; returns null and sets *why (one line) when
// this build has no CUDA or no device can run a kernel.
std::unique_ptr<Backend> makeCudaBackend(std::string* why);

} // namespace sylva::cuda
