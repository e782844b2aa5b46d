// A scene as one binary glTF 2.0 file (.glb): each species' mesh once with its materials, its instances through
// EXT_mesh_gpu_instancing (translation, rotation as a unit quaternion, scale: the renderer's instance placement),
// instance groups flattened, the landscape's plants of a region, and the ground (a quad) or the terrain (its
// height field, decimated above kGltfTerrainMaxSamples a side). Metres, +Y up (Sylva's world is glTF's).
// `sylva export --output FILE.glb` and the studio's File > Export Scene as glTF call it.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include <glm/glm.hpp>
#include <glm/gtc/quaternion.hpp>

#include "core/base/progress.h"
#include "core/render/render_scene.h"
#include "core/scene/scene.h"

namespace sylva {

// What an export holds beyond which it is refused unless forced (GltfExportOptions::force): instances, and
// the file's estimated size. A .glb cannot exceed 4 GiB at all.
inline constexpr size_t kGltfInstanceLimit = 2000000;
inline constexpr double kGltfByteLimit = 1024.0 * 1024.0 * 1024.0;
// Terrain samples a side at most: a larger DEM is exported every k-th sample (its last row and column kept).
inline constexpr size_t kGltfTerrainMaxSamples = 1025;

struct GltfExportOptions {
    // World x0, z0, x1, z1 (metres): only instances and landscape plants whose root lies in the box (x0 <= x < x1,
    // z0 <= z < z1), and the terrain's samples within it; none = everything.
    std::optional<std::array<double, 4>> region;
    std::vector<size_t> species;   // the species exported (indices); empty = all
    bool force = false;            // write above the limits
    size_t instanceLimit = kGltfInstanceLimit;   // the limits (the front ends keep the defaults)
    double byteLimit = kGltfByteLimit;
};

// One placed mesh: world = translation + rotation (scale x local). Double here, float32 in the file.
struct GltfInstance {
    glm::dvec3 translation{0.0};
    glm::dquat rotation{1.0, 0.0, 0.0, 0.0};   // unit, w first
    double scale = 1.0;
    bool landscape = false;                   // one of the landscape's plants
};

// Every exported instance of `scene` through `visit(species, instance)`: the scene's instances (groups flattened
// with their transforms composed; those standing on the terrain lifted as the renderer lifts them), then the
// landscape's plants (speciesBoxes: each species' mesh box, the population's input), within options' region and
// species. Throws Error as the renderer does (an instance off the terrain, a missing species or group).
void forEachGltfInstance(const Scene& scene, const std::vector<Bounds3>& speciesBoxes, const GltfExportOptions& options,
                         const std::function<void(uint32_t species, const GltfInstance& instance)>& visit);

// The counts an export would write and its estimated size, before anything is written.
struct GltfPlan {
    std::vector<size_t> perSpecies;   // instances per scene species (0 for those not exported)
    size_t instances = 0;             // all of them
    size_t landscapePlants = 0;       // of which from the landscape
    size_t terrainSamplesX = 0, terrainSamplesZ = 0;   // the terrain mesh's grid (0: no terrain)
    double estimatedBytes = 0.0;      // meshes, instances, terrain and textures (uncompressed size for encoded ones)
    size_t instanceLimit = kGltfInstanceLimit;   // the options' limits
    double byteLimit = kGltfByteLimit;
    bool overLimit() const { return instances > instanceLimit || estimatedBytes > byteLimit; }
    std::string summary() const;      // "N instances (a: n, b: m), about X MB"
};
GltfPlan planGltfExport(const Scene& scene, const std::vector<SpeciesAssets>& assets, const GltfExportOptions& options = {});

// Writes the .glb (atomically). Throws Error when the plan is over the limits and options.force is not set (the
// message says the counts and size; nothing is written), on bad input or a write failure; Cancelled.
// assets[i] belongs to scene.species[i] (loadSpeciesAssets without lighting suffices). Returns the plan written,
// its estimatedBytes replaced by the file's size.
GltfPlan exportGltf(const Scene& scene, const std::vector<SpeciesAssets>& assets, const std::string& path,
                    const GltfExportOptions& options = {}, Progress* progress = nullptr);

// The species' mesh boxes (the renderer's: meshBounds).
std::vector<Bounds3> speciesMeshBoxes(const std::vector<SpeciesAssets>& assets);

// Parses "x0,z0,x1,z1" (metres, x0 < x1, z0 < z1); throws Error naming what is wrong.
std::array<double, 4> parseGltfRegion(const std::string& text);

} // namespace sylva
