// Backend choice: CUDA when asked for or available, CPU otherwise; device trouble falls back to the CPU.
#include "pipeline/backend_select.h"

#include "cuda/cuda_backend.h"

namespace sylva {

FallbackBackend::FallbackBackend(std::unique_ptr<Backend> primary, std::function<void(const std::string&)> onFallback)
    : m_primary(std::move(primary)), m_onFallback(std::move(onFallback))
{
}

std::shared_ptr<Backend> FallbackBackend::primary() const
{
    std::lock_guard lock(m_mutex);
    return m_primary;
}

void FallbackBackend::dropPrimary(const std::shared_ptr<Backend>& failed, const std::string& message)
{
    {
        std::lock_guard lock(m_mutex);
        if (m_primary != failed) return;   // another job fell back first and said so
        m_primary.reset();
    }
    if (m_onFallback) m_onFallback(message);
}

std::string FallbackBackend::name() const
{
    const std::shared_ptr<Backend> p = primary();
    return p ? p->name() : m_cpu.name();
}

LightingGrid FallbackBackend::solveLighting(const DensityGrid& density, const lb::LbParams& params, Progress* progress,
                                            lb::SolveStats* stats)
{
    if (const std::shared_ptr<Backend> p = primary()) {
        try {
            return p->solveLighting(density, params, progress, stats);
        } catch (const BackendError& e) {
            dropPrimary(p, std::string(e.what()) + "; solving on the CPU");
        }
    }
    return m_cpu.solveLighting(density, params, progress, stats);
}

Film FallbackBackend::render(const RenderScene& scene, Progress* progress)
{
    if (const std::shared_ptr<Backend> p = primary()) {
        try {
            return p->render(scene, progress);
        } catch (const BackendError& e) {
            dropPrimary(p, std::string(e.what()) + "; rendering on the CPU");
        }
    }
    return m_cpu.render(scene, progress);
}

std::unique_ptr<Backend> selectBackend(const std::string& request, const std::function<void(const std::string&)>& onNote)
{
    if (request == "cpu") return std::make_unique<CpuBackend>();
    if (request != "auto" && request != "cuda") throw Error("backend: expected auto, cpu or cuda, got '" + request + "'");
    std::string why;
    std::unique_ptr<Backend> cuda = cuda::makeCudaBackend(&why);
    if (!cuda) {
        if (request == "cuda" && onNote) onNote("CUDA requested but " + why + "; using the CPU");
        return std::make_unique<CpuBackend>();
    }
    return std::make_unique<FallbackBackend>(std::move(cuda), onNote);
}

std::unique_ptr<DeviceDisplay> makeDeviceDisplay(std::string* why) { return cuda::makeCudaDisplay(why); }

std::unique_ptr<DeviceFrame> uploadDeviceFrame(const RenderScene& scene) { return cuda::uploadCudaFrame(scene); }

} // namespace sylva
