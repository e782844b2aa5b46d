// Builds without nvcc: no interop; the studio uploads the CPU film.
#include "cuda/gl_interop.h"

#include "core/backend/backend.h"

namespace sylva::cuda {

struct GlInterop::State {};

GlInterop::GlInterop() : m_why("this build has no CUDA backend") {}
GlInterop::~GlInterop() = default;
bool GlInterop::available() const { return false; }
void GlInterop::setPixelBuffer(unsigned, int, int) { throw BackendError("CUDA-GL interop unavailable: " + m_why); }
void GlInterop::releasePixelBuffer() {}
void GlInterop::render(const DeviceScene&, RenderMode, float, std::optional<RenderMode>, uint32_t*)
{
    throw BackendError("CUDA-GL interop unavailable: " + m_why);
}

} // namespace sylva::cuda
