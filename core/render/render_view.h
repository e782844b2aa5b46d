// The flat, device-friendly arrays a frame is traced from (the same struct is uploaded to the GPU as-is).
#pragma once

#include <cstdint>

#include <glm/glm.hpp>

#include "core/accel/bvh.h"
#include "core/accel/kdtree.h"
#include "core/base/defines.h"
#include "core/scene/scene.h"
#include "core/sky/sky.h"
#include "core/sky/virtual_lights.h"
#include "core/render/lights/light_list.h"
#include "core/render/surfaces/surface_list.h"

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

// The levels a ray descends at most: the top level and up to kMaxLevels - 1 nested instance groups
// above a mesh (Dietrich, Marmitt & Slusallek, "Terrain Guided Multi-Level Instancing of Highly Complex Plant
// Populations": terrain cells -> tiles -> plants -> meshes).
inline constexpr int kMaxLevels = kMaxNested + 1;

// An instance: a geometry placed in its parent's frame by a 3x4 row-major affine map parent -> the
// geometry's frame (rotation and uniform scale only, so normals map back with the transpose). The top
// level's instances map the camera-relative world frame (computed in double, so precision does not
// depend on the distance from the world origin); an instance inside a group maps the group's own frame.
// 64 bytes.
struct InstanceRecord {
    glm::vec4 row[3];        // local = row[i].xyz . parent + row[i].w
    uint32_t geometry;       // RenderView::geometries[geometry]: a mesh (a species or one of its pruned
                             // levels of detail) or an instance group
    float scale;             // parent metres per geometry metre
    uint32_t light;          // 1 + index into RenderView::instanceLights (the forest grid's factors); 0 = none
                             // (factor 1: group members, landscape plants, scenes without the forest grid)
    uint32_t pad;
};
static_assert(sizeof(InstanceRecord) == 64);

// The forest-level LB grid's factors of one top-level instance (core/lb/forest_grid.h), scaling its
// species' LB lighting: `factor` (per channel) at the crown centre, blended towards face[k] (surfaces facing
// +x, -x, +y, -y, +z, -z, world axes) on the crown's side that way (core/render/shade.h forestFactor).
// 128 bytes.
struct InstanceLightRecord {
    glm::vec3 centre;        // crown centre, species frame
    float invRadius;         // 1 / (half the crown box's largest extent), species frame
    glm::vec4 factor;        // xyz: per channel
    glm::vec4 face[6];       // xyz: per channel
};
static_assert(sizeof(InstanceLightRecord) == 128);

// What an instance can point to (the surface kinds below the Instances kind, core/render/surfaces/
// surface_list.h): traceLevel (surfaces/instances_trace.h) switches on it.
enum class GeometryKind : uint32_t {
    Mesh = 0,                // triangles under a BVH (or kd-tree), shaded with a species' data
    Group = 1,               // instances of other geometries under their own BVH (groups nest)
};

// One geometry: where its acceleration structure and primitives start in the flat arrays, its bounds in
// its own frame. 64 bytes.
struct GeometryRecord {
    GeometryKind kind;
    uint32_t species;        // Mesh: RenderView::species[species] (materials, lighting grid); Group: kNoHit
    uint32_t nodeOffset;     // Mesh: into blasNodes (leaves index blocks); Group: into groupNodes (leaves
                             // index groupOrder)
    uint32_t wideNodeOffset; // the host's 8-wide copy: Mesh into blasWideNodes, Group into groupWideNodes
    uint32_t primOffset;     // Mesh: into blocks; Group: into groupOrder (slot -> index into groupInstances)
    uint32_t triOffset;      // Mesh: into tris (BVH slot order; kd-tree runs and tests)
    uint32_t kdNodeOffset;   // Mesh in kd-tree runs: into kdNodes
    uint32_t kdRefOffset;    // Mesh in kd-tree runs: into kdRefs (slots of tris)
    glm::vec3 lo;
    uint32_t primCount;      // Mesh: triangles; Group: instances
    glm::vec3 hi;
    uint32_t pad;
};
static_assert(sizeof(GeometryRecord) == 64);

// Shading data of one species: its LB lighting grid and the weights its surfaces give the grid's light
// (core/lb/leaf_optics.h scatteredWeights under lighting.direct once; 1 for the seed's sum). 48 bytes.
struct SpeciesRecord {
    glm::vec3 gridOrigin;    // species frame, metres, node (0,0,0)
    float gridInvSpacing;    // 1 / node spacing; 0 = no lighting grid
    glm::ivec3 gridDims;
    uint32_t gridOffset;     // into RenderView::lighting (3 floats per node, already normalized)
    glm::vec3 leafIndirect;  // leaf materials: kd x L x sunRadiance x this
    float barkIndirect;      // other materials
    float leafIndirectCap;   // per channel, kd x leafIndirect is at most this (energy: lb::ScatteredWeights::leafCap)
    glm::vec3 leafRatio;     // leaves' diffuse transmission per unit of diffuse colour (lb::LeafOptics::ratio; path tracer)
};
static_assert(sizeof(SpeciesRecord) == 64);

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

// The render-scene arrays, once: element type, name, part and where they live. Everything that handles
// the arrays as a set is generated from this list: RenderScene's vectors, RenderView's pointers,
// RenderScene::view(), the CUDA upload and re-placement (cuda/render_cuda.cu) and the byte statistics.
// Adding an array is one line here.
//   part  Top:    the top level, re-placed for every camera (RenderScene::placeTopLevel);
//         Scene:  built once per set of species assets.
//   where Both:   every backend; Host: the host only (null on the device: the 8-wide node copies).
//   stat  the AccelStats figure its bytes count towards (Bvh*/Kd*: only in runs of that mesh structure;
//         None: shading data, not counted).
#define SYLVA_RENDER_ARRAYS(X)                                                                                  \
    X(Top, Both, BvhNode, tlasNodes, Tlas)                 /* BVH over the top level's instances */            \
    X(Top, Host, BvhNode8, tlasWideNodes, WideTlas)        /* the same top level under 8-wide nodes */         \
    X(Top, Both, uint32_t, tlasOrder, Tlas)                /* BVH slot -> index into instances */              \
    X(Top, Both, InstanceRecord, instances, Instances)     /* the top level (camera-relative) */               \
    X(Scene, Both, GeometryRecord, geometries, Blas)       /* every mesh and group */                          \
    X(Scene, Both, InstanceRecord, groupInstances, Instances) /* instances inside groups (group frames) */     \
    X(Scene, Both, BvhNode, groupNodes, Blas)              /* groups' BVHs */                                  \
    X(Scene, Host, BvhNode8, groupWideNodes, WideBlas)     /* the same under 8-wide nodes */                   \
    X(Scene, Both, uint32_t, groupOrder, Blas)             /* group BVH slot -> index into groupInstances */   \
    X(Scene, Both, SpeciesRecord, species, None)           /* per species: lighting grid */                    \
    X(Scene, Both, BvhNode, blasNodes, BvhBlas)            /* meshes' BVHs (leaves index blocks) */            \
    X(Scene, Host, BvhNode8, blasWideNodes, WideBlas)      /* the same leaves under 8-wide nodes */            \
    X(Scene, Both, TriAccel, tris, KdTriangles)            /* every mesh triangle, BVH slot order */           \
    X(Scene, Both, TriBlock, blocks, BvhTriangles)         /* BVH leaves' triangles */                         \
    X(Scene, Both, KdNode, kdNodes, KdBlas)                /* meshes' kd-trees (kd-tree runs) */               \
    X(Scene, Both, uint32_t, kdRefs, KdBlas)               /* their leaves' slots of tris */                   \
    X(Scene, Both, glm::uvec3, triVerts, None)             /* shading, by TriAccel::tri: vertex indices */     \
    X(Scene, Both, uint32_t, triMaterial, None)            /* material index */                                \
    X(Scene, Both, glm::vec3, normals, None)               /* per vertex, species frame */                     \
    X(Scene, Both, glm::vec2, uvs, None)                   /* per vertex */                                    \
    X(Scene, Both, MaterialRecord, materials, None)                                                            \
    X(Scene, Both, TextureRecord, textures, None)                                                              \
    X(Scene, Both, glm::vec4, texels, None)                                                                    \
    X(Scene, Both, AlphaMaskRecord, alphaMasks, None)                                                          \
    X(Scene, Both, uint32_t, alphaBits, None)                                                                  \
    X(Scene, Both, float, lighting, None)                  /* normalized LB photon density, 3 per node */     \
    X(Scene, Both, InstanceLightRecord, instanceLights, None) /* the forest grid's per-instance factors */    \
    X(Scene, Both, float, terrainHeights, Terrain)         /* the terrain's samples (core/terrain) */          \
    X(Scene, Both, glm::vec2, terrainRanges, Terrain)      /* its min/max pyramid */                           \
    X(Scene, Both, LandNode, landNodes, Landscape)         /* the landscape's 2D kd-tree over cells */         \
    X(Scene, Both, LandCell, landCells, Landscape)         /* per cell: ground range, tile */                  \
    X(Scene, Both, TileRecord, tileRecords, Landscape)     /* per Wang tile */                                 \
    X(Scene, Both, TileNode, tileNodes, Landscape)         /* the tiles' 2D trees */                           \
    X(Scene, Both, TilePlant, tilePlants, Landscape)       /* the tiles' plants */                             \
    X(Scene, Both, glm::vec4, landLight, Landscape)        /* the landscape's forest grid (landLightLayout) */ \
    X(Scene, Both, float, skyMap, None)                    /* the sky's map pixels (RGB, skyModel.map's) */    \
    X(Scene, Both, sky::VirtualLight, skyLights, None)     /* the sky's virtual directional lights */          \
    X(Scene, Both, float, skySampling, None)               /* the sky's sampling distribution (CDFs) */        \
    X(Top, Both, LightRecord, lights, None)                /* the frame's lights (core/render/lights) */       \
    X(Top, Both, SphereRecord, sphereRecords, None)        /* analytic spheres (camera-relative) */            \
    X(Top, Both, VolumeInstanceRecord, volumeInstances, None) /* placed volumes (camera-relative) */        \
    X(Scene, Both, VolumeGridRecord, volumeGrids, None)    /* per volume grid: dims, optics, offsets */        \
    X(Scene, Both, float, volumeDensity, None)             /* volume densities (surfaces/volumes_trace.h) */  \
    X(Scene, Both, float, volumeBricks, None)              /* their bricks' max density (empty-space skip) */ \
    X(Scene, Both, float, volumeLight, None)               /* their LB photon density, 3 per node, normalized */ \
    X(Scene, Both, float, volumeTemperature, None)         /* their temperatures (kelvin; emission) */         \
    X(Scene, Both, glm::vec3, volumeBlackbody, None)       /* blackbody colour table (kVolumeBlackbodySize) */

enum class ArrayPart { Top, Scene };
enum class ArrayWhere { Both, Host };
enum class ArrayStat { Tlas, WideTlas, Instances, Blas, BvhBlas, KdBlas, WideBlas, KdTriangles, BvhTriangles, Terrain, Landscape, None };

// Everything a frame needs, as pointers into flat arrays (host or device memory).
struct RenderView {
#define SYLVA_X(part, where, T, name, stat) const T* name;
    SYLVA_RENDER_ARRAYS(SYLVA_X)
#undef SYLVA_X
    uint32_t instanceCount;          // of the top level
    uint32_t lightCount;             // lights

    // the scene-level surface kinds' records (core/render/surfaces)
    GroundRecord ground;
    TerrainRecord terrain;
    SpheresRecord spheres;
    LandscapeRecord landscape;
    VolumesRecord volumes;
    AtmosphereRecord atmosphere;

    // the environment, and the unit of the LB grids
    SkyRecord sky;
    glm::vec3 lbRadiance;            // the species' normalized grids are in units of it (render_scene.h lbRadiance)
    CameraRecord camera;

    // settings
    int width, height, spp;
    // Progressive refinement: this frame traces samples [sampleBegin, sampleEnd) of the spp (their positions
    // and sky-light subsets are the full frame's); sampleEnd 0: all of them. accumulateFilm (render_cpu.h)
    // averages such frames into exactly the spp frame, up to float rounding.
    int sampleBegin = 0, sampleEnd = 0;
    AccelKind accel;
    bool shadows;
    float indirectScale;
    float alphaDistance;             // adaptive transparency: alpha tests only within this distance of the camera
                                     // (metres, camera-relative frame); 0 = everywhere
    Integrator integrator;           // Lb: the stages of shade.h; Path: path_trace.h from the camera's hit on
    int maxBounces;                  // Path: bounces after the camera's hit
    int lightingBounces = 0;         // Lb: bounces traced before the LB grid's light ends a path (0: the grid at the camera's hit)
    int bounceStride = 1;            // Lb with bounces: every bounceStride-th sample traces them (render.bounce_samples;
                                     // shade.h shadeDecoupledPixel); 1: every sample
};

// Does the frame shade its camera hits along paths (shade.h pathStage): the path tracer, or the LB integrator
// with a radiance-cache prefix?
SYLVA_HD SYLVA_INLINE bool tracesPaths(const RenderView& v) { return v.integrator == Integrator::Path || v.lightingBounces > 0; }

// The light the LB grids are solved toward (the frame's sun: the first of the list, render_scene.cpp
// placeTopLevel); volumes scatter it singly and subtract it from their grids' light.
SYLVA_HD SYLVA_INLINE LightRecord lbLight(const RenderView& v)
{
    if (v.lightCount > 0 && v.lights[0].kind == LightKind::Distant) return v.lights[0];
    LightRecord none{};
    none.kind = LightKind::Distant;
    none.direction = glm::vec3(0.0f, 1.0f, 0.0f);
    return none;
}

} // namespace sylva
