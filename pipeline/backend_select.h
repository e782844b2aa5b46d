// Picks the compute backend for a run (auto, cpu, cuda) and falls back to the CPU on device trouble.
#pragma once

#include <functional>
#include <memory>
#include <mutex>
#include <string>

#include "core/backend/backend.h"
#include "core/backend/device_display.h"

namespace sylva {

// A backend that runs on `primary` (CUDA) and, when it throws BackendError (driver error, out of
// device memory), reports the message through `onFallback` once and reruns the job on the CPU;
// every later job goes straight to the CPU. Never a crash, never a half-done result. Thread-safe:
// jobs on several threads may share it (the studio's lighting, inspect and export jobs).
class FallbackBackend final : public Backend {
public:
    FallbackBackend(std::unique_ptr<Backend> primary, std::function<void(const std::string&)> onFallback);
    std::string name() const override;
    LightingGrid solveLighting(const DensityGrid& density, const lb::LbParams& params, Progress* progress,
                               lb::SolveStats* stats) override;
    Film render(const RenderScene& scene, Progress* progress) override;

private:
    std::shared_ptr<Backend> primary() const;
    // Drops `failed` (once, if it is still the primary) and reports message.
    void dropPrimary(const std::shared_ptr<Backend>& failed, const std::string& message);

    mutable std::mutex m_mutex;   // guards m_primary (a running job keeps its own reference)
    std::shared_ptr<Backend> m_primary;
    CpuBackend m_cpu;
    std::function<void(const std::string&)> m_onFallback;
};

// request: "auto" (CUDA when a device is present, else CPU), "cpu", or "cuda" (CPU with a note when
// there is no device). Notes (one line each, e.g. "CUDA requested but no CUDA device: ...; using the
// CPU") go to onNote; the returned backend is never null. Throws Error on another request.
std::unique_ptr<Backend> selectBackend(const std::string& request, const std::function<void(const std::string&)>& onNote);

// The studio viewport's GPU display (CUDA-GL interop on the first usable device); null with *why set
// (one line) when this build has no CUDA backend or the machine no device. The viewport then probes
// whether its GL context can share buffers with the device (setPixelBuffer).
std::unique_ptr<DeviceDisplay> makeDeviceDisplay(std::string* why);

// Uploads a render scene for a DeviceDisplay, from any thread. Throws BackendError when there is no
// device or its memory is short.
std::unique_ptr<DeviceFrame> uploadDeviceFrame(const RenderScene& scene);

} // namespace sylva
