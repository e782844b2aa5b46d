// A forest scene as the user describes it: species, instances, ground, sun, sky, camera, render settings.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "core/base/param_spec.h"
#include "core/lb/lb_params.h"
#include "core/scene/volume.h"
#include "core/sky/sky.h"
#include "core/sky/sun_position.h"
#include "core/terrain/landscape.h"

namespace sylva {

// How a species' mesh is produced: a file (any format the importer reads) or the procedural grower.
struct GrowSpec {
    std::string species = "broadleaf";   // grower species name (broadleaf, birch, conifer, shrub)
    uint64_t seed = 1;
    uint64_t triangles = 100000;         // target triangle count
    float height = 0.0f;                 // metres; 0 = the grower's default for the species
};

// The LB solve of a species unless its scene says otherwise (docs/ACCURACY.md "LB lighting"): the
// preset's optics, kDefaultStepsPerEdge x the longest edge fixed steps, fp16 storage. On the measured
// fronts (a real tree, a grown dense tree, a cloud against Monte Carlo) that is the cheapest solve at
// its error: the seed's 2 x longest edge or a tolerance of 1e-3/1e-4 moves the error against the
// reference by under 0.7% (the LB's transport error, 5-11%, dwarfs the convergence error) for 1.3-2x
// the time, and fp16 changes it by under 3e-4 for 0.6-0.8x the time of fp32.
inline constexpr int kDefaultStepsPerEdge = 1;
lb::LbParams defaultSpeciesLighting(const lb::Preset& preset);

// The species' LB grid size, declared once: the scene file's field (`lighting.grid`, scene_fields.cpp) and
// the studio's property panel read it.
inline constexpr ParamSpec kSpeciesGrid{.key = "grid", .kind = ParamSpec::Kind::Integer, .metavar = "N", .lo = 8, .hi = 512,
                                        .def = {64}, .help = "LB grid nodes along the longest edge"};

// One plant model shared by all its instances. Its lighting grid is solved once, in its own frame.
struct SpeciesDesc {
    std::string name;                    // unique within the scene; instances refer to it
    std::string meshPath;                // absolute path (resolved against the scene file); empty when grown
    std::optional<GrowSpec> grow;        // set when the mesh is grown instead of read
    std::vector<std::string> leafMaterials;   // importer override: material names that are leaves
    std::string preset = "leaf";         // LB preset the lighting starts from
    lb::LbParams lighting;               // preset + overrides (sun is set from the scene's sun at solve time);
                                         // scene files start from defaultSpeciesLighting
    int grid = int(kSpeciesGrid.def[0]); // LB grid nodes along the longest edge
    bool solid = false;                  // voxelized as a solid (interior filled, core/voxel/solid_voxelize.h): plastics
    bool lit = true;                     // false: no LB grid, conventional lighting (ambient = the diffuse colour x
                                         // the sun's radiance: the LB's open-space value; Geist & Westall,
                                         // "Lattice-Boltzmann Lighting Models", Figure 5)
};

inline constexpr uint32_t kNoGroup = 0xffffffffu;

// One placed plant (or group of them). Metres of the parent frame (the world, or the group it belongs
// to); rotation in degrees applied X, then Y, then Z (R = Rz * Ry * Rx), then uniform scale, then
// translation. 56 bytes.
struct InstanceDesc {
    uint32_t species = 0;                // index into Scene::species (when group == kNoGroup)
    uint32_t group = kNoGroup;           // else: index into Scene::groups, placed as a whole
    glm::dvec3 position{0.0};            // world metres of the mesh origin (doubles: terrains are km wide)
    glm::vec3 rotationDeg{0.0f};
    float scale = 1.0f;                  // uniform, > 0
    bool onTerrain = false;              // position.y is the height above the terrain's surface at (x, z)
};

// A reusable set of instances in its own frame (a tile of plants, a stand), placed by instances of the
// scene or of other groups: groups nest, at most 3 deep below the scene's own instances (the renderer's
// kMaxLevels), and never contain themselves. Each is traced through its own acceleration structure,
// built once however often it is placed.
struct GroupDesc {
    std::string name;
    std::vector<InstanceDesc> instances;
};

struct GroundDesc {
    bool enabled = true;
    double height = 0.0;                 // world y of the plane, metres
    glm::vec3 color{0.18f, 0.15f, 0.10f};   // linear RGB albedo
};

struct HeightField;   // core/terrain/height_field.h

// A terrain from a digital elevation model: a regular grid of heights, triangulated on the fly (two
// triangles a cell), with a ground colour from altitude and slope. Replaces the ground plane.
struct TerrainDesc {
    std::string dem;                     // height image (16-bit PNG, float TIFF or EXR); absolute once read; empty = none
    glm::dvec3 origin{0.0};              // world position of the DEM's first sample (row 0, column 0), metres
    double spacing = 10.0;               // metres between samples (rows run along +z, columns along +x)
    double heightScale = 1.0;            // metres per DEM unit (the integer value of integer images)
    glm::vec3 rock{0.24f, 0.22f, 0.20f}; // albedo of slopes steeper than rockSlope degrees
    glm::vec3 snow{0.80f, 0.82f, 0.86f}; // albedo above snowLine
    float rockSlope = 35.0f;             // degrees
    float snowLine = 0.0f;               // world y, metres; 0 = no snow
    // Plants (Dietrich, Marmitt & Slusallek, "Terrain Guided Multi-Level Instancing of Highly Complex Plant
    // Populations"): the terrain cut into `cells` x `cells` cells along its longer side (0 = no plant tiles),
    // each carrying a Wang tile of `tiles`' population chosen by `tiling`, thinned by `density`.
    int cells = 0;
    TileSetDesc tiles;
    TilingDesc tiling;
    DensityDesc density;
    // The loaded heights (pipeline/io/dem_io: loadSceneTerrain), shared by the scene's copies; not in the file.
    std::shared_ptr<const HeightField> field;
    bool enabled() const { return !dem.empty(); }
};

// Sun: direction toward the sun (world, +Y up), blackbody colour temperature, intensity (scales radiance).
// place set: the sun by date, time and place (NOAA, core/sky/sun_position.h); direction is then its
// result (placeSunDirection) and the file stores the place instead of the direction.
struct SunDesc {
    glm::vec3 direction{0.4f, 0.8f, 0.3f};
    double temperature = 6500.0;         // kelvin
    float intensity = 1.0f;
    std::optional<sky::SunPlace> place;
};

namespace sky {
struct Sky;   // core/sky/sky_light.h
}

// The sky beyond the constant colour (Scene::sky): a Preetham sky or an HDR map, seen by camera rays that
// leave the scene and lighting surfaces through `lights` virtual directional lights (core/sky), split over
// `interleave` subsets by interleaved sampling. kind Constant (old files, the default): Scene::sky as
// before, none of the rest is used.
struct SkyDesc {
    sky::SkyKind kind = sky::SkyKind::Constant;
    double turbidity = 3.0;              // Preetham, 2 .. 10
    float scale = 0.03f;                 // Preetham: kcd/m^2 -> the renderer's unit (0.03: a high sun near sun.intensity 1's)
    std::string path;                    // HDR map (absolute once read; relative to the scene file in it)
    float rotationDeg = 0.0f;            // map: about +Y, adds to every azimuth
    float intensity = 1.0f;              // map: multiplies its pixels (and its sun)
    int lights = 32;                     // N virtual lights (default measured: docs/ACCURACY.md "Sky light")
    int interleave = 16;                 // K subsets: N / K shadow rays per pixel and sample
    bool sunFromMap = true;              // map: its sun found, taken out and made the sun (replacing `sun`)
    bool aerialPerspective = false;      // the air between the camera and what it sees, hazed by `turbidity`
                                         // (core/render/surfaces/atmosphere.h); off in files without the key
    // The built sky (pipeline/io/env_map_io: loadSceneSky), shared by the scene's copies; not in the file.
    std::shared_ptr<const sky::Sky> built;
    // Lit through virtual lights (shadow rays) with its own background: every kind but Constant.
    bool analytic() const { return kind != sky::SkyKind::Constant; }
    // The scene's `sky` colour is the sky's radiance: Constant (background, the ground's unoccluded ambient light)
    // and Uniform (the same colour as a map: it lights leaves, bark and ground with shadow rays).
    bool hasColor() const { return kind == sky::SkyKind::Constant || kind == sky::SkyKind::Uniform; }
};

// Pinhole camera. fovY in degrees (vertical field of view).
struct CameraDesc {
    glm::dvec3 position{0.0, 1.7, -10.0};
    glm::dvec3 target{0.0, 1.7, 0.0};
    glm::vec3 up{0.0f, 1.0f, 0.0f};
    float fovY = 45.0f;
};

// How the species' LB grids and the renderer's shadow-ray sun share the direct light:
// Seed = Geist & Steele's sum (the grid as solved, uncollided sunlight included, added to the drawn sun: direct
// light counted twice inside crowns); Once = the grid less its uncollided part (lb::scatteredPart), so
// the grid adds only scattered light to the drawn sun.
enum class DirectLight { Seed, Once };

// The forest-level LB grid (core/lb/forest_grid.h): Off = every instance of a species lit
// alike (as before); On = each top-level instance's species lighting scaled by the grid's factors; Auto = as
// On where exposure differs (factors spread by 2% or more), else skipped (said in render --stats).
enum class ForestGridMode { Off, Auto, On };

// What the species' LB boundary holds: Sun = the papers' sun alone (docs/LB_MODEL.md "Boundary
// condition"; old files); SunSky = the sun plus the sky's radiance over each lattice direction's share of
// the upper hemisphere (lb::skyWeights), so leaves also receive skylight scattered through the crown.
enum class LbBoundary { Sun, SunSky };

// The scene's lighting beyond sun and sky (the `lighting` block).
struct LightingDesc {
    DirectLight direct = DirectLight::Seed;
    LbBoundary boundary = LbBoundary::Sun;
    ForestGridMode forestGrid = ForestGridMode::Off;
    int forestGridResolution = 0;        // forest grid nodes along the plants' longest horizontal extent; 0 =
                                         // automatic (4 across the median crown, at most 32: lb::kAutoResolution)
    int bounces = 0;                     // the LB integrator's radiance cache: bounces a camera path traces (next-event
                                         // estimation at each vertex) before the LB grid's scattered light ends it;
                                         // 0 = the grid at the camera's hit (the seed's lookup), 0 .. kMaxPathBounces
    bool operator==(const LightingDesc&) const = default;   // the scene file writes the block only when it differs
};

// The direct light the species' LB grids leave to the renderer: with lighting.bounces > 0 the paths trace all
// direct light, so the grids give their scattered light only, as with `once`, whatever `direct` says.
inline DirectLight gridDirectLight(const LightingDesc& l) { return l.bounces > 0 ? DirectLight::Once : l.direct; }

enum class RenderMode { Full, Local, Ambient, Lb };
enum class AccelKind { Bvh, KdTree };
// How a camera sample's light is computed: lb, the LB model (direct light with shadow rays, the LB grids'
// scattered light); path, the reference path tracer (every bounce, next-event estimation, core/render/path_trace.h).
enum class Integrator : uint32_t { Lb, Path };
inline constexpr int kMaxPathBounces = 100;

struct RenderSettings {
    int width = 896;
    int height = 448;
    int spp = 1;                         // samples per pixel (stratified; box-filtered to the pixel)
    RenderMode mode = RenderMode::Full;
    AccelKind accel = AccelKind::Bvh;
    bool shadows = true;
    float indirectScale = 1.0f;          // weight of the LB indirect light (1 = as solved, normalized to open sky)
    float exposureKey = 0.18f;           // Reinhard key value a
    glm::vec3 leafTint{1.0f};            // multiplies every leaf material's diffuse colour (what leaves reflect and,
                                         // with the path tracer, transmit); each in [0, 2], 1 = as modelled
    float alphaDistance = 0.0f;          // metres; beyond it from the camera leaf cut-outs are not tested
                                         // (cards count as opaque; Geist & Steele, "A Lighting Model for Fast
                                         // Rendering of Forest Ecosystems", section 2.1); 0 = off
    float pruneDistance = 0.0f;          // metres; stochastic pruning of leaves starts there (Cook et al. 2007): an
                                         // instance at distance d keeps about start / d of them; 0 = off
    Integrator integrator = Integrator::Lb;
    int maxBounces = 64;                 // path: bounces after the camera's hit, 0 .. kMaxPathBounces (Russian roulette from the 4th)
    int bounceSamples = 0;               // lb with lighting.bounces: samples of a pixel that trace the bounces (every
                                         // spp / bounceSamples-th); the others share their light by albedo; 0 = all
    // The picture's display transform (pipeline/render/display_view.h): a view of an OpenColorIO display,
    // or the in-house Reinhard curve, "Sylva Reinhard", the picture of files written without the key.
    std::string view = "Sylva Reinhard";
    std::string display;                 // empty: the OpenColorIO config's default display
};

struct Scene {
    int version = 1;
    std::vector<SpeciesDesc> species;
    std::vector<InstanceDesc> instances;
    std::vector<GroupDesc> groups;       // instance groups (built in code today; scene files hold none yet)
    GroundDesc ground;
    TerrainDesc terrain;                 // with a DEM, the terrain is the ground (the plane is not traced)
    std::vector<VolumeDesc> volumes;     // participating media (clouds, smoke), beside plants and ground
    SunDesc sun;
    glm::vec3 sky{0.55f, 0.70f, 0.95f};  // linear RGB radiance of the background (the constant sky: sky.color)
    SkyDesc skyModel;                    // the rest of the sky block (Preetham, HDR map, virtual lights)
    LightingDesc lighting;               // the `lighting` block (direct light once or the seed's sum)
    CameraDesc camera;
    RenderSettings render;
};

// The constant background radiance a film's skyCover multiplies when composed: Scene::sky for the
// constant sky, 0 for the others (their background is in SampleParts::background).
inline glm::vec3 composeSky(const Scene& s) { return s.skyModel.analytic() ? glm::vec3(0.0f) : s.sky; }

// What a scene started from nothing (the studio's File > New) holds: Scene's defaults with `sky.kind` uniform and
// the `final` quality preset's lighting, the closest to Cycles on every scene the ground truth measures
// (`lighting.direct` once, `lighting.boundary` sun_sky, `lighting.bounces` 2; docs/ACCURACY.md "Ground truth"). Scene{} keeps the defaults old files were
// written against, so they render the picture they always did. The sky is not built (loadSceneSky).
Scene newSceneDefaults();

const char* renderModeName(RenderMode mode);      // "full", "local", "ambient", "lb"
bool parseRenderMode(const std::string& name, RenderMode* out);
const char* directLightName(DirectLight d);       // "seed", "once"
bool parseDirectLight(const std::string& name, DirectLight* out);
const char* lbBoundaryName(LbBoundary b);         // "sun", "sun_sky"
bool parseLbBoundary(const std::string& name, LbBoundary* out);
const char* forestGridModeName(ForestGridMode m); // "off", "auto", "on"
bool parseForestGridMode(const std::string& name, ForestGridMode* out);
const char* accelName(AccelKind kind);            // "bvh", "kdtree"
bool parseAccel(const std::string& name, AccelKind* out);
const char* integratorName(Integrator i);         // "lb", "path"
bool parseIntegrator(const std::string& name, Integrator* out);

// Direction toward the sun from elevation (degrees above the horizon) and azimuth (degrees, 0 = +Z,
// 90 = +X), +Y up.
glm::vec3 sunDirection(double elevationDeg, double azimuthDeg);

} // namespace sylva
