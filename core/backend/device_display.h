// The studio viewport's GPU path behind the backend: a render scene resident in device memory and a
// display that traces it straight into a GL pixel buffer. The studio holds these interfaces only; the
// CUDA backend implements them (cuda/cuda_backend.cu) and pipeline/backend_select.h makes them.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>

#include "core/render/render_scene.h"

namespace sylva {

// A RenderScene uploaded to a device: the scene part (meshes, groups, lighting grids) stays; place()
// moves the top level and the settings (camera, size, samples) for each frame.
class DeviceFrame {
public:
    virtual ~DeviceFrame() = default;
    // Takes the top level and settings of `scene`, whose scene part must be the one uploaded (the
    // studio's camera moves and instance edits). Throws BackendError.
    virtual void place(const RenderScene& scene) = 0;
    // Device memory held, bytes.
    virtual size_t deviceBytes() const = 0;
};

// Traces a DeviceFrame and tone-maps it into a GL pixel buffer (RGBA8, width x height, top row first)
// shared with the device, so the picture never leaves the GPU. The GL context that owns the buffer
// must be current on the calling thread and run on the device: setPixelBuffer throws BackendError
// otherwise (the caller then uses the CPU path).
class DeviceDisplay {
public:
    virtual ~DeviceDisplay() = default;
    // "NVIDIA H100 ...", for the studio's status line.
    virtual std::string deviceName() const = 0;
    // Registers (or re-registers after a resize) the GL buffer object `glBuffer`. Throws BackendError.
    virtual void setPixelBuffer(unsigned glBuffer, int width, int height) = 0;
    // Unregisters the buffer (before the caller reallocates or deletes it). No-op without one.
    virtual void releasePixelBuffer() = 0;
    // Traces `frame` (its width/height must match the buffer) in `mode`, tone-mapped with Reinhard key
    // `key`; right: a second mode for columns [width/2, width) (the side-by-side compare), each half
    // tone-mapped as its mode's whole picture would be. hostCopy: also copies the picture there
    // (width x height RGBA8). frame must come from the same backend. Throws BackendError.
    virtual void render(const DeviceFrame& frame, RenderMode mode, float key, std::optional<RenderMode> right = std::nullopt,
                        uint32_t* hostCopy = nullptr) = 0;
};

} // namespace sylva
