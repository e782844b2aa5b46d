// CUDA-GL interop for the studio's viewport: the GPU renders straight into a GL pixel buffer object.
#pragma once

#include <cstdint>
#include <memory>
#include <string>

#include "core/render/render_scene.h"

namespace sylva::cuda {

class DeviceScene;

// Renders a device scene into a GL pixel buffer (RGBA8, width x height, top row first) registered
// with CUDA. The GL context that owns the buffer must be current on the calling thread. Without a
// CUDA build or device, available() is false and the caller uploads the CPU film instead.
class GlInterop {
public:
    GlInterop();
    ~GlInterop();
    GlInterop(const GlInterop&) = delete;
    GlInterop& operator=(const GlInterop&) = delete;

    bool available() const;
    const std::string& whyUnavailable() const { return m_why; }

    // Registers (or re-registers after a resize) the GL buffer object `glBuffer` of width x height
    // RGBA8 pixels. Throws BackendError.
    void setPixelBuffer(unsigned glBuffer, int width, int height);

    // Traces the scene (its view's width/height must match the buffer) and writes the tone-mapped
    // picture into the buffer. Throws BackendError.
    void render(const RenderScene& scene, RenderMode mode, float key);

private:
    struct State;
    std::unique_ptr<State> m_state;
    std::string m_why;
};

} // namespace sylva::cuda
