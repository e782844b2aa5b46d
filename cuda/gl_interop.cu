// CUDA-GL interop: register a GL pixel buffer, map it for a frame, render and tone-map into it.
#include "cuda/gl_interop.h"

#include <GL/gl.h>
#include <cuda_gl_interop.h>

#include "cuda/cuda_check.h"
#include "cuda/device_query.h"
#include "cuda/render_cuda.h"

namespace sylva::cuda {

struct GlInterop::State {
    cudaGraphicsResource* resource = nullptr;
    int width = 0, height = 0;
};

GlInterop::GlInterop()
{
    const DeviceQuery q = queryDevices();
    if (q.devices.empty()) m_why = q.message.empty() ? "no CUDA device" : q.message;
    else m_state = std::make_unique<State>();
}

GlInterop::~GlInterop()
{
    if (m_state && m_state->resource) cudaGraphicsUnregisterResource(m_state->resource);
}

bool GlInterop::available() const { return m_state != nullptr; }

void GlInterop::setPixelBuffer(unsigned glBuffer, int width, int height)
{
    if (!m_state) throw BackendError("CUDA-GL interop unavailable: " + m_why);
    if (m_state->resource) {
        cudaGraphicsUnregisterResource(m_state->resource);
        m_state->resource = nullptr;
    }
    check(cudaGraphicsGLRegisterBuffer(&m_state->resource, GLuint(glBuffer), cudaGraphicsRegisterFlagsWriteDiscard),
          "register the GL pixel buffer");
    m_state->width = width;
    m_state->height = height;
}

void GlInterop::releasePixelBuffer()
{
    if (m_state && m_state->resource) cudaGraphicsUnregisterResource(m_state->resource);
    if (m_state) m_state->resource = nullptr;
}

void GlInterop::render(const DeviceScene& scene, RenderMode mode, float key, std::optional<RenderMode> right, uint32_t* hostCopy)
{
    if (!m_state || !m_state->resource) throw BackendError("CUDA-GL interop: no pixel buffer registered");
    const RenderView& v = scene.view();
    if (v.width != m_state->width || v.height != m_state->height)
        throw BackendError("CUDA-GL interop: the pixel buffer size does not match the render size");
    check(cudaGraphicsMapResources(1, &m_state->resource), "map the GL pixel buffer");
    void* ptr = nullptr;
    size_t bytes = 0;
    const size_t need = size_t(v.width) * size_t(v.height) * 4;
    cudaError_t err = cudaGraphicsResourceGetMappedPointer(&ptr, &bytes, m_state->resource);
    if (err == cudaSuccess && bytes < need) err = cudaErrorInvalidValue;
    if (err == cudaSuccess) {
        try {
            renderToRgba8(scene, mode, key, static_cast<uint32_t*>(ptr), right);
            if (hostCopy) check(cudaMemcpy(hostCopy, ptr, need, cudaMemcpyDeviceToHost), "picture download");
        } catch (...) {
            cudaGraphicsUnmapResources(1, &m_state->resource);
            throw;
        }
    }
    cudaGraphicsUnmapResources(1, &m_state->resource);
    check(err, "GL pixel buffer pointer");
}

} // namespace sylva::cuda
