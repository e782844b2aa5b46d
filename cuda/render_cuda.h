// The frame on the GPU: the scene's flat arrays uploaded as they are, the shared per-pixel kernel in 8x8 tiles,
// and tone mapping on the device.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <vector>

#include "core/base/progress.h"
#include "core/render/render_cpu.h"
#include "core/render/render_scene.h"

namespace sylva::cuda {

// A RenderScene on the device. Upload once per set of species; render many frames, moving the top level
// with place() between them.
class DeviceScene {
public:
    explicit DeviceScene(const RenderScene& scene);   // throws BackendError
    ~DeviceScene();
    DeviceScene(const DeviceScene&) = delete;
    DeviceScene& operator=(const DeviceScene&) = delete;

    // The device-side view (pointers into device memory) with the host view's settings.
    const RenderView& view() const { return m_view; }
    size_t deviceBytes() const { return m_bytes; }

    // Takes the top level (instances and their BVH) and the settings (camera, size, samples,
    // environment) of `scene`, whose species part must be the one uploaded (the studio's camera moves and
    // instance edits: placeViewFrame on the host, then this). Moves O(instances) bytes; the species
    // arrays stay. Throws BackendError (e.g. a different species count).
    void place(const RenderScene& scene);

    // Device memory reused by the frames rendered from this scene (film, tone-map sums).
    struct Scratch;
    Scratch& scratch() const;

private:
    struct Buffers;
    std::unique_ptr<Buffers> m_buffers;
    RenderView m_view{};
    RenderView m_scene{};   // device pointers of the scene part (SYLVA_RENDER_ARRAYS part Scene)
    size_t m_speciesBytes = 0, m_bytes = 0;
    size_t m_speciesCount = 0, m_geometryCount = 0;
};

// Traces every pixel on the device and returns the film on the host. Throws BackendError.
Film renderCuda(const DeviceScene& scene, Progress* progress = nullptr);

// Closest hits of the given rays (camera-relative frame) on the device, for tests against the CPU.
std::vector<Hit> traceRaysCuda(const DeviceScene& scene, const std::vector<Ray>& rays, bool anyHit);

// Traces and tone-maps on the device into an RGBA8 buffer in device memory (width x height, top row
// first), e.g. a GL pixel buffer mapped by the interop module. key: Reinhard key value. right: a
// second mode for columns [width/2, width) (the side-by-side compare), each half tone-mapped as its
// mode's whole picture would be (compareImage on the CPU).
void renderToRgba8(const DeviceScene& scene, RenderMode mode, float key, uint32_t* deviceRgba8,
                   std::optional<RenderMode> right = std::nullopt);

} // namespace sylva::cuda
