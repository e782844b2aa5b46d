// The CUDA backend: device selection, the LB solve and the frame behind the Backend interface.
#include "cuda/cuda_backend.h"

#include <cstdio>
#include <utility>

#include "core/base/launch_env.h"

#include "cuda/cuda_check.h"
#include "cuda/device_query.h"
#include "cuda/gl_interop.h"
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

class CudaFrame final : public DeviceFrame {
public:
    explicit CudaFrame(const RenderScene& scene) : m_scene(scene) {}
    void place(const RenderScene& scene) override { m_scene.place(scene); }
    size_t deviceBytes() const override { return m_scene.deviceBytes(); }
    const DeviceScene& scene() const { return m_scene; }

private:
    DeviceScene m_scene;
};

class CudaDisplay final : public DeviceDisplay {
public:
    explicit CudaDisplay(std::string name) : m_name(std::move(name)) {}
    std::string deviceName() const override { return m_name; }
    void setPixelBuffer(unsigned glBuffer, int width, int height) override { m_interop.setPixelBuffer(glBuffer, width, height); }
    void releasePixelBuffer() override { m_interop.releasePixelBuffer(); }
    void render(const DeviceFrame& frame, RenderMode mode, float key, std::optional<RenderMode> right, uint32_t* hostCopy) override
    {
        const auto* f = dynamic_cast<const CudaFrame*>(&frame);
        if (!f) throw BackendError("CUDA display: the frame was not uploaded by the CUDA backend");
        m_interop.render(f->scene(), mode, key, right, hostCopy);
    }
    bool available() const { return m_interop.available(); }
    const std::string& whyUnavailable() const { return m_interop.whyUnavailable(); }

private:
    GlInterop m_interop;
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
    // Under an MPI launcher every rank of a node would take the first device: rank k on the node takes
    // device k mod count instead (one GPU per rank with --map-by ppr:G:node), and says which.
    const int local = launcherLocalRank();
    const size_t pick = local >= 0 ? size_t(local) % q.devices.size() : 0;
    const DeviceInfo& d = q.devices[pick];
    if (local >= 0)
        std::fprintf(stderr, "note: local rank %d uses CUDA device %d of %zu (%s)\n", local, d.index, q.devices.size(), d.name.c_str());
    return std::make_unique<CudaBackend>(d);
}

std::unique_ptr<DeviceDisplay> makeCudaDisplay(std::string* why)
{
    const DeviceQuery q = queryDevices();
    if (q.devices.empty()) {
        if (why) *why = q.message.empty() ? "no CUDA device" : q.message;
        return nullptr;
    }
    auto display = std::make_unique<CudaDisplay>(q.devices.front().name);
    if (!display->available()) {
        if (why) *why = display->whyUnavailable();
        return nullptr;
    }
    return display;
}

std::unique_ptr<DeviceFrame> uploadCudaFrame(const RenderScene& scene)
{
    const DeviceQuery q = queryDevices();
    if (q.devices.empty()) throw BackendError(q.message.empty() ? "no CUDA device" : q.message);
    check(cudaSetDevice(q.devices.front().index), "select device");
    return std::make_unique<CudaFrame>(scene);
}

} // namespace sylva::cuda
