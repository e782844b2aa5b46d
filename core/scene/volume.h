// Volumes of a scene (participating media: clouds, smoke, glowing plastics): a density grid with its
// optics, LB lighting, emission and placements. The renderer's side is the volumes kind (core/render/surfaces/volume*).
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "core/grid/grid.h"
#include "core/lb/lb_params.h"
#include "core/render/surfaces/volume.h"

namespace sylva {

// One placement of a volume: world position of the grid frame's origin, rotation (degrees, X then Y
// then Z, as instances), uniform scale.
struct VolumePlacement {
    glm::dvec3 position{0.0};
    glm::vec3 rotationDeg{0.0f};
    float scale = 1.0f;
};

// What the pipeline loads for a volume (pipeline/scene/scene_volumes: loadSceneVolumes, pipeline/render:
// lightSceneVolumes); shared by the scene's copies, not in the file.
struct VolumeData {
    DensityGrid density;                 // grid frame (its geometry: origin, spacing), values >= 0, finite
    std::vector<float> temperature;      // kelvin per node (same dims), empty = no emission
    LightingGrid lighting;               // LB photon density (same dims), empty = not solved
    glm::vec3 lightingNorm{1.0f};        // photon density of unobstructed space per channel
    std::vector<glm::vec3> blackbody;    // kVolumeBlackbodySize linear-RGB blackbody colours (with emission)
};

struct VolumeDesc {
    std::string name;                    // unique among volumes
    std::string grid;                    // density grid file (.npy with its sidecar, or .vdb), absolute once read
    std::string temperature;             // temperature grid file (kelvin), optional
    std::string preset = "cloud";        // optics preset: cloud, smoke, pmma (or sigma_a / sigma_s / g given)
    lb::LbParams lighting;               // optics per channel (per node spacing at density 1) + LB solve settings
    bool lit = true;                     // LB lighting solved (tracer lb or combined)
    VolumeTracer tracer = VolumeTracer::Lb;
    float step = 1.0f;                   // largest camera-ray step, nodes
    float shadowStep = 2.0f;             // shadow-march step, nodes
    float densityScale = 1.0f;           // multiplies the grid's values (must keep them in [0, 1] for the LB)
    float emissionExposure = 0.0f;       // stops: emission = 2^this x sigma_a rho B(T) / Y(B(6500 K))
    std::vector<VolumePlacement> instances;
    std::shared_ptr<const VolumeData> data;
};

// The optics presets of volumes: the LB presets (cloud, pmma, ...) and "smoke".
// Returns false when `name` is none of them.
bool volumePreset(const std::string& name, lb::LbParams* out);
const char* volumeTracerName(VolumeTracer t);                    // "lb", "single", "combined"
bool parseVolumeTracer(const std::string& name, VolumeTracer* out);

} // namespace sylva
