// CUDA-GL interop for the studio's viewport: the GPU renders straight into a GL pixel buffer object.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <string>

#include "core/render/render_scene.h"

namespace sylva::cuda {

class DeviceScene;

// Renders a device scene into a GL pixel buffer (RGBA8, width x height, top row first) registered
// with CUDA; the caller then fills a texture from the buffer (glTexSubImage2D with the buffer bound
// to GL_PIXEL_UNPACK_BUFFER) without the picture leaving the GPU. The GL context that owns the buffer
// must be current on the calling thread and belong to the CUDA device (an NVIDIA driver's GL):
// setPixelBuffer throws otherwise. Without a CUDA build or device, available() is false and the
// caller uploads the CPU film instead.
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
    // Unregisters the buffer (before the caller reallocates or deletes it). No-op without one.
    void releasePixelBuffer();

    // Traces the scene (its view's width/height must match the buffer) and writes the tone-mapped
    // picture into the buffer (renderToRgba8: mode, key, compare mode for the right half). hostCopy:
    // also copies the picture there (width x height RGBA8). Throws BackendError.
    void render(const DeviceScene& scene, RenderMode mode, float key, std::optional<RenderMode> right = std::nullopt,
                uint32_t* hostCopy = nullptr);

private:
    struct State;
    std::unique_ptr<State> m_state;
    std::string m_why;
};

} // namespace sylva::cuda
