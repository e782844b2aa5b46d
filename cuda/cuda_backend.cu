// The CUDA backend: device selection, the LB solve and the frame behind the Backend interface.
#include "cuda/cuda_backend.h"

#include "cuda/cuda_check.h"
#include "cuda/device_query.h"
#include "cuda/lb_cuda.h"
#include "cuda/render_cuda.h"

namespace sylva::cuda {
namespace {

class CudaBackend final : public Backend {
public:
    explicit CudaBackend(const DeviceInfo& d) : m_device(d.index), m_name("cuda (" + d.name + ")") {}
    std::string name() const override { return m_name; }

    LightingGrid solveLighting(const DensityGrid& density, const lb::LbParams& params, Progress* progress,
                               lb::SolveStats* stats) override
    {
        check(cudaSetDevice(m_device), "select device");
        return solveLightingCuda(density, params, progress, stats);
    }

    Film render(const RenderScene& scene, Progress* progress) override
    {
        check(cudaSetDevice(m_device), "select device");
        const DeviceScene device(scene);
        return renderCuda(device, progress);
    }

private:
    int m_device;
    std::string m_name;
};

} // namespace

std::unique_ptr<Backend> makeCudaBackend(std::string* why)
{
    const DeviceQuery q = queryDevices();
    if (q.devices.empty()) {
        if (why) *why = q.message.empty() ? "no CUDA device" : q.message;
        return nullptr;
    }
    return std::make_unique<CudaBackend>(q.devices.front());
}

} // namespace sylva::cuda
