// The volumes kind's records: participating media (density grids with LB lighting, emission) placed in a
// frame. The volumes kind is the list's medium (core/render/surfaces/surface_list.h): rays cross it rather
// than end on it; volumes_trace.h marches it, volumes_build.cpp fills these records.
#pragma once

#include <cstdint>

#include <glm/glm.hpp>

namespace sylva {

// How a volume's in-scattered light is computed (docs/RENDERING.md "Volumes").
//   Lb:       sigma_s x the LB photon density (isotropic), Geist & Westall: no shadow rays, all of it indirect;
//   Single:   as in those posts: sun single scattering with the Henyey-Greenstein phase and a shadow march
//             toward the sun at every step (direct, `local`), no multiple scattering;
//   Combined: Single's sun term plus the LB solution less its uncollided part (multiple scattering,
//             indirect).
enum class VolumeTracer : uint32_t { Lb = 0, Single = 1, Combined = 2 };

// Nodes per side of a brick of the empty-space grid.
inline constexpr int kVolumeBrick = 8;
// Blackbody table: kVolumeBlackbodySize entries from kVolumeBlackbodyLo to kVolumeBlackbodyHi kelvin.
inline constexpr int kVolumeBlackbodySize = 256;
inline constexpr float kVolumeBlackbodyLo = 1000.0f, kVolumeBlackbodyHi = 40000.0f;
// A ray's march stops where every channel's transmittance is below this (the rest adds < 1e-4).
inline constexpr float kVolumeMinTransmittance = 1e-4f;
// The adaptive step keeps the optical depth of one step below this (down to step / 8).
inline constexpr float kVolumeTauPerStep = 0.25f;
// Volumes one camera ray composes (the nearest entries beyond are dropped; shadows take them all).
inline constexpr int kMaxRayVolumes = 8;

// One volume grid (asset), its optics per node spacing at density 1. 96 bytes.
struct VolumeGridRecord {
    glm::ivec3 dims;            // density nodes per axis (z fastest)
    uint32_t densityOffset;     // into RenderView::volumeDensity
    glm::ivec3 bricks;          // brick grid dims (ceil(dims / kVolumeBrick))
    uint32_t brickOffset;       // into volumeBricks: max density over a brick's trilinear support
    glm::vec3 sigmaT;           // extinction per node spacing at density 1, per channel
    uint32_t lightOffset;       // into volumeLight (3 floats per node, normalized: 1 = unobstructed); kNoHit = none
    glm::vec3 sigmaS;           // scattering per node spacing at density 1
    uint32_t temperatureOffset; // into volumeTemperature (kelvin per node); kNoHit = no emission
    glm::vec3 g;                // Henyey-Greenstein asymmetry per channel
    uint32_t tracer;            // VolumeTracer
    float step;                 // largest camera-ray step, nodes
    float shadowStep;           // shadow-march step, nodes
    float emission;             // 2^exposure: multiplies sigma_a rho B(T) / Y(B(6500 K))
    float maxSigmaT;            // max over channels of sigmaT
};

// A placed volume: camera-relative world -> grid node coordinates (node (i,j,k) at (i,j,k); the medium
// fills the node-centred cells, [-0.5, N - 0.5] per axis). 64 bytes.
struct VolumeInstanceRecord {
    glm::vec4 row[3];
    uint32_t grid;              // into RenderView::volumeGrids
    float nodesPerMetre;        // 1 / (spacing x instance scale)
    uint32_t pad[2];
};

// The volumes' arrays, what the march reads of RenderView (volumeViewOf, volumes_trace.h).
struct VolumeArrays {
    const VolumeGridRecord* grids;
    const VolumeInstanceRecord* instances;
    const float* density;
    const float* bricks;
    const float* light;
    const float* temperature;
    const glm::vec3* blackbody;
    uint32_t count;             // instances
};

// The volumes of a frame (RenderView::volumeInstances).
struct VolumesRecord {
    uint32_t count;             // placed volumes (0: none, every stage as without them)
};

} // namespace sylva
