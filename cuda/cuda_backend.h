// The CUDA backend: the LB solve and the frame on an NVIDIA GPU, the same per-node and per-pixel code as the CPU.
#pragma once

#include <memory>
#include <string>

#include "core/backend/backend.h"
#include "core/backend/device_display.h"

namespace sylva::cuda {

// Creates the CUDA backend on the first usable device; returns null and sets *why (one line) when
// this build has no CUDA or no device can run a kernel.
std::unique_ptr<Backend> makeCudaBackend(std::string* why);

// The viewport's display on the first usable device (CUDA-GL interop); null with *why set (one line)
// when this build has no CUDA or no device.
std::unique_ptr<DeviceDisplay> makeCudaDisplay(std::string* why);

// Uploads `scene` to the first usable device, from any thread. Throws BackendError (no device, out of
// device memory).
std::unique_ptr<DeviceFrame> uploadCudaFrame(const RenderScene& scene);

} // namespace sylva::cuda
