// Builds without nvcc: no device scene can be made (callers check GlInterop / queryDevices first).
#include "cuda/render_cuda.h"

#include "core/backend/backend.h"

namespace sylva::cuda {

struct DeviceScene::Buffers {};
struct DeviceScene::Scratch {};

DeviceScene::DeviceScene(const RenderScene&) { throw BackendError("this build has no CUDA backend"); }
DeviceScene::~DeviceScene() = default;
void DeviceScene::place(const RenderScene&) { throw BackendError("this build has no CUDA backend"); }
DeviceScene::Scratch& DeviceScene::scratch() const { throw BackendError("this build has no CUDA backend"); }

Film renderCuda(const DeviceScene&, Progress*) { throw BackendError("this build has no CUDA backend"); }
std::vector<Hit> traceRaysCuda(const DeviceScene&, const std::vector<Ray>&, bool) { throw BackendError("this build has no CUDA backend"); }
void renderToRgba8(const DeviceScene&, RenderMode, float, uint32_t*, std::optional<RenderMode>)
{
    throw BackendError("this build has no CUDA backend");
}

} // namespace sylva::cuda
