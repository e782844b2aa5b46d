// Host side of a frame: species geometry, textures and lighting grids flattened into the arrays a RenderView points at.
#pragma once

#include <cstddef>
#include <vector>

#include "core/base/progress.h"
#include "core/grid/grid.h"
#include "core/image/image.h"
#include "core/mesh/triangle_mesh.h"
#include "core/render/prune.h"
#include "core/render/render_view.h"
#include "core/scene/scene.h"

namespace sylva {

// What the renderer needs of one species, already in memory.
struct SpeciesAssets {
    TriangleMesh mesh;                  // species frame, metres
    std::vector<ImageRgba> diffuse;     // per material: colour texture (sRGB-encoded), empty = none
    std::vector<ImageRgba> cutout;      // per material: coverage in the alpha channel, empty = opaque
    LightingGrid lighting;              // species frame; empty rgb = none (indirect light as in open sky)
    glm::vec3 lightingNorm{1.0f};       // photon density of unobstructed space per channel (divides the grid)
};

// Sizes in bytes of what the traversal reads, for the performance notes.
struct AccelStats {
    size_t tlasBytes = 0, instanceBytes = 0, blasBytes = 0, triangleBytes = 0;   // the structures the run traverses
    size_t wideTlasBytes = 0, wideBlasBytes = 0;   // the host's 8-wide copies of the BVHs (the host traverses them instead)
    size_t instances = 0, speciesTriangles = 0;
    double instancedTriangles = 0.0;     // triangles the instances trace (pruned levels count their own)
    int tlasDepth = 0, maxBlasDepth = 0;
    int wideTlasDepth = 0, maxWideBlasDepth = 0;   // of the host's 8-wide copies
    size_t prunedLevels = 0;             // pruned levels of detail built (only those some instance uses)
    size_t pruneBytes = 0;               // their BVH nodes, triangles and blocks (included in the sizes above)
    size_t instancesPerLevel[kMaxPruneLevels] = {};   // instances per level of detail, 0 = full
};

// Owns the flat arrays; view() points into them (valid while this object lives and is not modified).
class RenderScene {
public:
    RenderView view() const;
    const AccelStats& stats() const { return m_stats; }

    // Everything below is filled by buildRenderScene; the CUDA backend uploads these arrays as they are.
    std::vector<BvhNode> tlasNodes;
    std::vector<BvhNode8> tlasWideNodes;   // host only: the same top level under 8-wide nodes (BVH runs)
    std::vector<uint32_t> tlasOrder;
    std::vector<InstanceRecord> instances;
    std::vector<SpeciesRecord> species;
    std::vector<BvhNode> blasNodes;
    std::vector<BvhNode8> blasWideNodes;   // host only: the same leaves under 8-wide nodes (BVH runs)
    std::vector<TriAccel> tris;
    std::vector<TriBlock> blocks;
    std::vector<glm::uvec3> triVerts;
    std::vector<uint32_t> triMaterial;
    std::vector<glm::vec3> normals;
    std::vector<glm::vec2> uvs;
    std::vector<MaterialRecord> materials;
    std::vector<TextureRecord> textures;
    std::vector<glm::vec4> texels;
    std::vector<AlphaMaskRecord> alphaMasks;
    std::vector<uint32_t> alphaBits;
    std::vector<float> lighting;
    // kd-tree alternative, built only when the scene asks for accel kdtree
    std::vector<KdNode> kdTlasNodes, kdBlasNodes;
    std::vector<uint32_t> kdTlasRefs, kdBlasRefs;
    std::vector<KdSpeciesRecord> kdSpecies;
    RenderView base{};                  // environment, camera and settings (pointers filled by view())
    AccelStats m_stats;
};

// Builds the arrays for a scene: one BVH (or, for accel kdtree, one kd-tree) per species (in
// parallel), one over the instances in the
// camera-relative frame (world minus the camera position, computed in double: precision does not
// depend on the distance from the world origin). assets[i] belongs to scene.species[i].
// With render.pruneDistance > 0 each instance gets the level of detail of its distance to the camera
// (core/render/prune.h) and every level in use gets its own BVH (kd-tree), after the species' records;
// render.alphaDistance goes to RenderView::alphaDistance.
// sunRadiance is the sun's linear RGB (colour x intensity). Throws Error on inconsistent input.
RenderScene buildRenderScene(const Scene& scene, const std::vector<SpeciesAssets>& assets, const glm::vec3& sunRadiance,
                             Progress* progress = nullptr);

// Camera basis and image extents for a camera and image size (throws Error on a degenerate camera).
CameraRecord makeCamera(const CameraDesc& camera, int width, int height);

// The instance's world -> species map in the frame whose origin is `frameOrigin` (world metres).
InstanceRecord makeInstance(const InstanceDesc& inst, const glm::dvec3& frameOrigin);

} // namespace sylva
