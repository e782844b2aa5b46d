// The compute backends behind one interface: the LB solve and the frame (CPU always; CUDA when built and a device exists).
#pragma once

#include <memory>
#include <string>

#include "core/base/progress.h"
#include "core/grid/grid.h"
#include "core/lb/lb_params.h"
#include "core/lb/lb_solver.h"
#include "core/render/render_cpu.h"
#include "core/render/render_scene.h"

namespace sylva {

// A backend failed in a way the CPU path can take over from (no device, driver error, out of device
// memory). The message is one line for the user.
class BackendError : public Error {
public:
    using Error::Error;
};

class Backend {
public:
    virtual ~Backend() = default;
    // "cpu" or "cuda (NVIDIA H100 ...)".
    virtual std::string name() const = 0;
    // The LB lighting solve (docs/LB_MODEL.md). Throws Error on bad input, BackendError on device trouble.
    virtual LightingGrid solveLighting(const DensityGrid& density, const lb::LbParams& params, Progress* progress,
                                       lb::SolveStats* stats) = 0;
    // The film of a prepared scene (every pixel, v.spp samples). Throws BackendError on device trouble.
    virtual Film render(const RenderScene& scene, Progress* progress) = 0;
};

// The CPU backend: lb::solveLighting and renderFilm (oneTBB).
class CpuBackend final : public Backend {
public:
    std::string name() const override { return "cpu"; }
    LightingGrid solveLighting(const DensityGrid& density, const lb::LbParams& params, Progress* progress,
                               lb::SolveStats* stats) override
    {
        return lb::solveLighting(density, params, progress, stats);
    }
    Film render(const RenderScene& scene, Progress* progress) override { return renderFilm(scene.view(), progress); }
};

} // namespace sylva
