// The flat, device-friendly arrays a frame is traced from (the same struct is uploaded to the GPU as-is).
#pragma once

#include <cstdint>

#include <glm/glm.hpp>

#include "core/accel/bvh.h"
#include "core/accel/kdtree.h"
#include "core/base/defines.h"
#include "core/scene/scene.h"

namespace sylva {

// A mesh triangle as the traversal tests it, in its species' frame (metres): v0 and the edges
// e1 = v1 - v0, e2 = v2 - v0. tri = global triangle index (shading arrays); alpha = alpha mask
// index + 1 (0 = opaque). 48 bytes.
struct TriAccel {
    glm::vec3 v0; uint32_t tri;
    glm::vec3 e1; uint32_t alpha;
    glm::vec3 e2; uint32_t pad;
};
static_assert(sizeof(TriAccel) == 48);

// Cut-out texture coordinates in a TriBlock: corner uv minus whole units (the cut-out wraps), times
// this scale, as 16-bit integers: steps of 6.1e-5 over [0, 4).
inline constexpr float kBlockUvScale = 16384.0f;

// Up to four triangles of one BVH leaf as structure of arrays, tested with one SIMD pass (BVH runs).
// Lanes past the leaf's count are never read as hits. Same fields as TriAccel, and in the fourth
// cache line the corner uvs of the alpha-tested triangles: the cut-out test then needs no dependent
// loads of triVerts and uvs (profiling showed those misses at about a quarter of a camera ray's time).
// 256 bytes.
struct alignas(64) TriBlock {
    float v0x[4], v0y[4], v0z[4];
    float e1x[4], e1y[4], e1z[4];
    float e2x[4], e2y[4], e2z[4];
    uint32_t tri[4];
    uint32_t alpha[4];
    uint32_t pad[4];
    uint16_t uv[4][6];       // triangle k: u0 v0 u1 v1 u2 v2, each (uv - whole units) * kBlockUvScale
    uint32_t uvPacked;       // bit k: uv[k] holds triangle k's corners (else they span 4 units or more:
                             // the test reads triVerts and uvs)
    uint32_t pad2[3];
};
static_assert(sizeof(TriBlock) == 256);

// A placed plant: world (camera-relative) -> species frame as a 3x4 row-major affine map
// (rotation and uniform scale only, so normals map back with the transpose). 64 bytes.
struct InstanceRecord {
    glm::vec4 row[3];        // local = row[i].xyz . world + row[i].w
    uint32_t species;        // shading: materials, lighting grid (RenderView::species[species])
    float scale;             // world metres per species metre
    uint32_t geometry;       // the triangles traced: RenderView::species[geometry] (kdSpecies[geometry]) is the
                             // species itself or one of its pruned levels of detail
    uint32_t pad;
};
static_assert(sizeof(InstanceRecord) == 64);

// Per species: where its BVH nodes and triangles start in the flat arrays, its lighting grid. 48 bytes.
// Records 0 .. species-1 are the species; the records after them are pruned levels of detail of a
// species (own BVH and triangles, the species' lighting grid), reached only through InstanceRecord::geometry.
struct SpeciesRecord {
    uint32_t nodeOffset;     // into RenderView::blasNodes (leaves index blocks of RenderView::blocks)
    uint32_t triOffset;      // into RenderView::tris (BVH slot order; kd-tree runs and tests)
    uint32_t blockOffset;    // into RenderView::blocks
    uint32_t wideNodeOffset; // into RenderView::blasWideNodes (host)
    glm::vec3 gridOrigin;    // species frame, metres, node (0,0,0)
    float gridInvSpacing;    // 1 / node spacing; 0 = no lighting grid
    glm::ivec3 gridDims;
    uint32_t gridOffset;     // into RenderView::lighting (3 floats per node, already normalized)
};
static_assert(sizeof(SpeciesRecord) == 48);

// The kd-tree of one species (kd-tree runs): offsets into the flat kd arrays and the box rays are
// clipped to. Its primitive references are slots of RenderView::tris, like the BVH's. 32 bytes.
struct KdSpeciesRecord {
    glm::vec3 lo;
    uint32_t nodeOffset;     // into RenderView::kdBlasNodes
    glm::vec3 hi;
    uint32_t refOffset;      // into RenderView::kdBlasRefs
};

// A surface material for shading. Texture indices are into RenderView::textures, -1 = none. 48 bytes.
struct MaterialRecord {
    glm::vec3 diffuse;       // linear RGB, times the texture colour
    float shininess;
    glm::vec3 specular;
    int32_t texture;
    uint32_t isLeaf;
    int32_t alphaMask;       // into RenderView::alphaMasks, -1 = opaque
    uint32_t pad[2];
};
static_assert(sizeof(MaterialRecord) == 48);

// A texture of linear RGBA float texels (offset into RenderView::texels, in texels). 16 bytes.
struct TextureRecord {
    int32_t width, height;
    uint32_t offset;
    uint32_t pad;
};

// A 1-bit cut-out (alpha >= 0.5) in 32-bit words, row-major, top row first. 16 bytes.
struct AlphaMaskRecord {
    int32_t width, height;
    uint32_t offset;         // into RenderView::alphaBits, in words
    uint32_t pad;
};

// Camera in the camera-relative frame: origin at the eye, orthonormal basis, image plane extents.
struct CameraRecord {
    glm::vec3 forward, right, up;
    float tanHalfX, tanHalfY;
};

// Everything a frame needs, as pointers into flat arrays (host or device memory).
struct RenderView {
    // top level (instances) and bottom level (per species) BVHs
    const BvhNode* tlasNodes;
    const BvhNode8* tlasWideNodes;   // host only, may be null: the same top level under 8-wide nodes
    const uint32_t* tlasOrder;       // BVH slot -> instance index
    const InstanceRecord* instances;
    uint32_t instanceCount;
    const SpeciesRecord* species;
    const BvhNode* blasNodes;
    const BvhNode8* blasWideNodes;   // host only, may be null: the same leaves under 8-wide nodes
    const TriAccel* tris;            // every triangle, BVH slot order (kd-tree traversal, tests)
    const TriBlock* blocks;          // BVH leaves' triangles

    // kd-tree alternative (same instances and triangles); null unless accel == KdTree
    const KdNode* kdTlasNodes;
    const uint32_t* kdTlasRefs;      // instance indices
    glm::vec3 kdTlasLo, kdTlasHi;
    const KdSpeciesRecord* kdSpecies;
    const KdNode* kdBlasNodes;
    const uint32_t* kdBlasRefs;

    // shading data, indexed by TriAccel::tri
    const glm::uvec3* triVerts;      // global vertex indices
    const uint32_t* triMaterial;     // global material index
    const glm::vec3* normals;        // per vertex, species frame
    const glm::vec2* uvs;            // per vertex
    const MaterialRecord* materials;
    const TextureRecord* textures;
    const glm::vec4* texels;
    const AlphaMaskRecord* alphaMasks;
    const uint32_t* alphaBits;
    const float* lighting;           // normalized LB photon density, 3 floats per node

    // environment
    bool groundEnabled;
    float groundY;                   // camera-relative height of the ground plane
    glm::vec3 groundColor;
    glm::vec3 sunDir;                // toward the sun, normalized
    glm::vec3 sunRadiance;           // blackbody colour (luminance 1) x intensity
    glm::vec3 sky;
    CameraRecord camera;

    // settings
    int width, height, spp;
    AccelKind accel;
    bool shadows;
    float indirectScale;
    float alphaDistance;             // adaptive transparency: alpha tests only within this distance of the camera
                                     // (metres, camera-relative frame); 0 = everywhere
};

} // namespace sylva
