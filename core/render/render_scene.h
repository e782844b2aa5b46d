// Host side of a frame: species geometry, textures and lighting grids flattened into the arrays a RenderView points at.
#pragma once

#include <cmath>
#include <cstddef>
#include <vector>

#include "core/base/progress.h"
#include "core/grid/grid.h"
#include "core/image/image.h"
#include "core/lb/forest_grid.h"
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
    lb::ForestSpecies forest;           // its density grid as the forest-level grid sees it (biomass 0: not known,
                                        // the species takes no part in the forest grid)
};

// The forest-level LB grid of a frame (the scene's lighting.forest_grid, core/lb/forest_grid.h).
struct ForestGridStats {
    const char* mode = "off";            // the scene's setting: off, auto, on
    bool solved = false;                 // built and solved
    bool applied = false;                // its factors scale the instances' LB lighting
    bool skipped = false;                // auto: exposure uniform (factors' spread under uniformSpread), not applied
    size_t plants = 0;                   // top-level instances of species with a density grid
    int resolution = 0;
    glm::ivec3 dims{0};
    double spacing = 0.0, seconds = 0.0; // metres; build + solve
    float spread = 0.0f;                 // (max - min) / max over the factors and face factors
    float minFactor = 1.0f, medianFactor = 1.0f, maxFactor = 1.0f;   // over instances (median: channel mean)
    float minFaceFactor = 1.0f, maxFaceFactor = 1.0f;
};

// The forest-level LB grid over the landscape's plants (core/terrain/landscape_light.h), under the same
// lighting.forest_grid setting.
struct LandscapeLightStats {
    bool solved = false;                 // built and solved
    bool applied = false;                // its factors scale the landscape plants' LB lighting
    bool skipped = false;                // auto: exposure uniform over the cells with plants
    int resolution = 0;
    glm::ivec3 dims{0};
    double spacing = 0.0, seconds = 0.0; // metres; build + solve
    double plantsTested = 0.0, plantsGrowing = 0.0;
    uint32_t stride = 1;
    size_t cells = 0;                    // cells with growing plants
    float minFactor = 1.0f, medianFactor = 1.0f, maxFactor = 1.0f, spread = 0.0f;   // over those cells
};

// Sizes in bytes of what the traversal reads, for the performance notes.
struct AccelStats {
    size_t tlasBytes = 0, instanceBytes = 0, blasBytes = 0, triangleBytes = 0;   // the structures the run traverses
    size_t wideTlasBytes = 0, wideBlasBytes = 0;   // the host's 8-wide copies of the BVHs (the host traverses them instead)
    size_t instances = 0, speciesTriangles = 0;   // instances: of the top level
    double instancedTriangles = 0.0;     // triangles the instances trace (pruned levels count their own)
    int tlasDepth = 0, maxBlasDepth = 0;
    int wideTlasDepth = 0, maxWideBlasDepth = 0;   // of the host's 8-wide copies
    size_t prunedLevels = 0;             // pruned levels of detail built (only those some instance uses)
    size_t pruneBytes = 0;               // their BVH nodes, triangles and blocks (included in the sizes above)
    size_t instancesPerLevel[kMaxPruneLevels] = {};   // instances per level of detail, 0 = full
    size_t groups = 0, groupInstances = 0;   // instance groups and the instances inside them
    size_t terrainBytes = 0;             // the terrain's heights and min/max pyramid
    size_t terrainSamplesX = 0, terrainSamplesZ = 0;
    size_t landscapeBytes = 0;           // the landscape's cells, kd-tree, tiles' trees and plants
    LandscapeStats landscape;            // cells, tiles, potentially visible instances and triangles, build time
    ForestGridStats forestGrid;          // the forest-level LB grid
    LandscapeLightStats landscapeLight;  // its share over the landscape's plants
};

// The pruned levels of detail a scene build makes meshes for: those the scene's camera gives some
// instance (sylva render), or every level each species supports (the studio's viewport, whose camera
// moves after the build).
enum class LodLevels { Used, All };

// Owns the flat arrays (SYLVA_RENDER_ARRAYS in render_view.h); view() points into them (valid while this
// object lives and is not modified). Built in two steps that every front end shares: buildSceneGeometry
// (meshes, pruned levels, groups: camera-independent) and placeTopLevel (the top level's instances and
// BVH in the camera-relative frame, environment, camera, settings).
class RenderScene {
public:
    RenderView view() const;
    const AccelStats& stats() const { return buildStats; }

#define SYLVA_X(part, where, T, name, stat) std::vector<T> name;
    SYLVA_RENDER_ARRAYS(SYLVA_X)
#undef SYLVA_X
    RenderView frame{};                 // the frame's records (surface kinds, sky), camera and settings; view() fills its pointers

    // What placeTopLevel needs of the camera-independent part (host only, never traced).
    struct MeshLevels {
        glm::dvec3 centre{0.0};         // species-frame box centre (distance to the camera for pruning)
        int levels = 1;                 // levels of detail the species supports
        uint32_t geometry[kMaxPruneLevels];   // geometry record of each level, kNoHit where not built
    };
    std::vector<MeshLevels> meshLevels;        // per species
    std::vector<uint32_t> groupGeometry;       // per scene group: its geometry record
    std::vector<Bounds3> geometryBounds;       // per geometry record: bounds in its frame (instance boxes)
    std::vector<double> geometryTriangles;     // per geometry record: the triangles an instance of it traces
    std::vector<lb::ForestSpecies> forestSpecies;   // per species: its density grid as the forest grid sees it (the
                                               // landscape's lattice is solved again after a landscape edit)
    AccelKind accel = AccelKind::Bvh;          // the mesh structures built
    LodLevels lodLevels = LodLevels::Used;
    AccelStats buildStats;                     // what the builders record (read through stats())
};

// Step 1: the camera-independent part. One BVH (or, for accel kdtree, one kd-tree) per species and per
// pruned level (in parallel; with render.pruneDistance > 0 the levels `lod` asks for, core/render/prune.h),
// one BVH per instance group of scene.groups over its instances in the group's frame (groups nest at most
// kMaxLevels - 1 deep), textures, cut-outs, lighting grids, the terrain, the landscape, the volumes and the sky.
// No LB solve: the forest-level grid the scene's instances and landscape trigger is the pipeline's
// (pipeline/render/frame_build.h lightFrame, which fills instanceLights and landLight). assets[i] belongs to
// scene.species[i].
// Throws Error on inconsistent input (missing species or group, a cycle or too deep nesting of groups).
RenderScene buildSceneGeometry(const Scene& scene, const std::vector<SpeciesAssets>& assets, LodLevels lod = LodLevels::Used,
                               Progress* progress = nullptr);

// Step 2: the top level for `scene` at width x height and spp: instance records and their BVH in the
// camera-relative frame (world minus the camera position, computed in double: precision does not depend
// on the distance from the world origin), each instance of a species at the level of detail of its
// distance to the camera; ground, sun (sunRadiance: linear RGB, colour x intensity), sky, camera and
// settings. The scene's species and groups must be those `rs` was built from. Costs O(instances); throws
// Error (no instances, a missing species or group, a degenerate camera, a level the build lacks:
// see hasLevelsFor).
void placeTopLevel(RenderScene& rs, const Scene& scene, const glm::vec3& sunRadiance, int width, int height, int spp);

// Parts of step 1 again, for a scene that differs from the one `rs` was built from only there (the studio's
// viewport keeps the species' structures across such edits; the same species list is assumed):
// buildLandscapeArrays: the landscape's tiling, tile populations and trees, cells and kd-tree (a tile, tiling
// or cell edit); setLandscapeDensity: only the density rule's layout fields (core/terrain/landscape.h:
// nothing is built, the rule thins plants while tracing); both drop the landscape's share of the forest grid
// (clearLandscapeLight: it depends on which plants grow; pipeline/render/frame_build.h lightLandscape solves
// it again); rebuildVolumeGrids: the volumes' arrays (buildVolumeGrids). Each throws Error as
// buildSceneGeometry does for its part.
void buildLandscapeArrays(RenderScene& rs, const Scene& scene);
void setLandscapeDensity(RenderScene& rs, const Scene& scene);
void clearLandscapeLight(RenderScene& rs);
void rebuildVolumeGrids(RenderScene& rs, const Scene& scene);

// Whether `rs` holds every level of detail placeTopLevel needs for `scene` (a LodLevels::All build always
// does; a LodLevels::Used build for the camera it was built with).
bool hasLevelsFor(const RenderScene& rs, const Scene& scene);

// Whether the frame has the ground plane (a terrain replaces it): then every direction below the horizon
// ends on the ground, for every point above it.
inline bool groundPlaneShown(const Scene& scene) { return scene.ground.enabled && !scene.terrain.enabled(); }

// The sky's sampling distribution for the paths' next-event estimation (the layout of RenderView::skySampling,
// core/render/lights/light_list.h): each equal-area cell in proportion to the sky's mean luminance at 3 x 3 points
// of it, plus 1% of the mean over all cells.
std::vector<float> skySamplingDistribution(const sky::SkyView& sky);

// The sky's part of a built frame: a Preetham or map sky's per-ray parameters, its map pixels, its sampling
// distribution and its virtual lights (d.lights of them, d.interleave subsets; with groundPlane, groundPlaneShown(scene), all of
// them above the horizon, since the ground hides the rest); the constant sky: none (the frame as before).
// buildSceneGeometry calls it; changing only the lights or subsets of the same sky needs nothing else (the
// sun and the LB grids stay). Throws Error when the sky is not built or its counts are out of range.
void setFrameSky(RenderScene& rs, const SkyDesc& d, bool groundPlane);

// The sun the frame lights with: the scene's direction and `sunRadiance`, or a built Preetham sky's (or a
// map sky's, with sun_from_map) own sun, radiance() x sun.intensity / pi (a surface shows albedo x radiance
// x cos). What placeTopLevel and the Blender export use. Throws Error on a zero direction.
struct FrameSun {
    glm::vec3 direction;   // toward the sun, unit
    glm::vec3 radiance;
};
FrameSun frameSun(const Scene& scene, const glm::vec3& sunRadiance);
// The frame's light list (RenderScene::lights): the sun (a distant light, first: the light the LB grids are
// solved toward) and the sky (the environment; setFrameSky sets its virtual lights). placeTopLevel calls it;
// a caller adds other lights after it (core/render/lights).
void placeLights(RenderScene& rs, const FrameSun& sun);
// The direction the species' LB grids are solved toward: the scene's sun, or a map sky's own sun when the
// frame lights with it (sun_from_map), so the LB's light comes from where the drawn sun is.
glm::vec3 lbSunDirection(const Scene& scene);
// The radiance the species' normalized LB grids are in units of (RenderView::lbRadiance; surfaces show
// albedo x grid x it): the frame sun's; with lighting.boundary sun_sky a channel the sun leaves dark takes 1,
// so a sky without a sun (a map with none, a Preetham sky at night, sun.intensity 0) still lights the grid.
glm::vec3 lbRadiance(const Scene& scene, const FrameSun& sun);

// The byte statistics of the frame's arrays (AccelStats): every builder recounts after it changes them.
void countFrameBytes(RenderScene& rs);

// The terrain-frame height above which the ground is snow (> any height: none), and the cosine below which
// a normal is rock: the shader's colour rule and the landscape's masks (TerrainRecord::snowY, rockCos).
inline float terrainSnowY(const TerrainDesc& t) { return t.snowLine > 0.0f ? float(double(t.snowLine) - t.origin.y) : 3.0e38f; }
inline float terrainRockCos(const TerrainDesc& t) { return float(std::cos(double(t.rockSlope) * 3.14159265358979323846 / 180.0)); }


// Camera basis and image extents for a camera and image size (throws Error on a degenerate camera).
// The rotation of an instance from its degrees about x, y, z: R = Rz Ry Rx (column-major glm).
glm::dmat3 rotationDeg(const glm::vec3& deg);

CameraRecord makeCamera(const CameraDesc& camera, int width, int height);

// `scene` with its on-terrain instances (InstanceDesc::onTerrain, the scene's own instances) standing on the
// terrain, world y = the surface's height at their x, z + their y, as every frame places them: `storage` holds
// that copy, or `scene` itself is returned when no instance stands on the terrain. Throws Error naming an
// on-terrain instance without a terrain or off its footprint.
const Scene& sceneOnTerrain(const Scene& scene, Scene& storage);

// The instance's parent -> geometry map in the frame whose origin is `frameOrigin` (parent-frame metres).
// geometry = the species (placeTopLevel picks a pruned level or the group's record).
InstanceRecord makeInstance(const InstanceDesc& inst, const glm::dvec3& frameOrigin);

} // namespace sylva
