// The numbers a study part measures, stored as JSON beside the report so one part can be rerun alone.
#pragma once

#include <string>
#include <vector>

namespace sylva::study {

// Where and how a part was measured.
struct RunInfo {
    std::string date;                   // ISO date of the measurement
    std::string machine;                // CPU model and logical cores
    bool quick = false;
    double seconds = 0.0;               // wall time of the part
    double loadBefore = 0.0, loadAfter = 0.0;   // 1-minute load average at the start and the end (2 cores)
};

// ---- LB: grid x steps x storage against the Monte Carlo reference ----

struct LbReference {
    int grid = 0;                       // nodes on the longest axis
    std::string dims;                   // "XxYxZ"
    double paths = 0.0;                 // paths of the (single, green-channel) solve
    double noise = 0.0;                 // relativeNoiseInterior
    double seconds = 0.0;               // solve time (0 when it came from the cache)
    bool cached = false;
};

struct LbRow {
    int grid = 0;
    std::string dims;
    std::string steps;                  // "default", "half", "tol 1e-3", "tol 1e-4"
    bool fp16 = false;
    double seconds = 0.0;               // LB solve, all three channels, wall clock (best of the repeats)
    double cpuSeconds = 0.0;            // the same solve's CPU time, all threads (best of the repeats)
    int stepsTaken = 0;
    double errSame = -1.0;              // green channel vs the reference on the same grid (-1: none at this grid)
    double errFine = 0.0;               // green channel vs the finest reference, at its nodes
    bool isDefault = false;             // the product's default solve of a scene species (LbData::defaultConfig)
};

struct LbCase {
    std::string name;                   // "tree", "dense", "cloud"
    std::string title;                  // one line: what the case is
    std::string preset;                 // LB preset
    int fineGrid = 0;                   // grid of the finest reference (errFine)
    std::string skipped;                // non-empty: why the case did not run
    std::vector<LbReference> references;
    std::vector<LbRow> rows;
};

struct LbData {
    RunInfo run;
    std::string note;                   // e.g. why 256 was left out
    std::string defaultConfig;          // the product default the rows mark, e.g. "grid 64, tol 1e-3, fp32"
    std::vector<LbCase> cases;
};

// ---- Voxelization sub-cells ----

// A leaf is a surface: the share of sub-cells it meets falls about as 1/s with s sub-cells per edge, so
// the density's scale is part of the model (the seed's optics go with 3^3) and the study compares
// shapes: the finest density scaled to the same total as the run's.
struct VoxelRow {
    std::string caseName;
    int grid = 0;
    int subcells = 0;
    double voxelSeconds = 0.0;
    double meanVs3 = 0.0;               // total density / the 3^3 total (the 1/s trend)
    double densityErr = 0.0;            // relative L2 against the finest density scaled to this total
    double lbErr = 0.0;                 // relative L2 of the LB result against the LB on that scaled finest density
};

struct VoxelData {
    RunInfo run;
    int referenceSubcells = 0;
    std::vector<VoxelRow> rows;
};

// ---- Rendering ----

struct SppRow {
    int spp = 0;
    double traceSeconds = 0.0;
    double traceCpu = 0.0;
    double err = 0.0;                   // relative L2 of linear luminance against the reference render
};

struct LodRow {
    std::string label;                  // "off", "alpha 50 m", "prune 25 m", ...
    float alphaDistance = 0.0f;
    float pruneDistance = 0.0f;
    double buildSeconds = 0.0;
    double instancedTriangles = 0.0;
    double pruneMegabytes = 0.0;
    bool isDefault = false;
    // One entry per RenderData::lodSpps:
    std::vector<double> traceSeconds;
    std::vector<double> traceCpu;
    std::vector<double> err;            // against the reference render (both off, many samples)
    std::vector<double> errOff;         // against both off at the same samples per pixel: the knob's own change
};

// A quality preset rendered end to end on the forest: its LB settings for every species, its render settings.
struct PresetRow {
    std::string name;                   // "preview", "final", "reference"
    double buildSeconds = 0.0;          // acceleration structures (pruned levels included)
    double traceSeconds = 0.0;
    double traceCpu = 0.0;
    double err = 0.0;                   // against the preset reference render
    std::string settings;               // qualityPresetSettings of the preset measured (empty: measured before it was kept)
};

struct RenderData {
    RunInfo run;
    std::string sppScene;               // one line: the small scene
    int sppWidth = 0, sppHeight = 0, sppReference = 0;
    std::vector<SppRow> spp;
    std::string lodScene;               // one line: the forest
    int lodWidth = 0, lodHeight = 0, lodReferenceSpp = 0;
    std::vector<int> lodSpps;           // samples per pixel each setting is traced with
    double lodReferenceSeconds = 0.0;
    std::vector<LodRow> lod;
    int presetReferenceSpp = 0;         // the presets' reference: the reference preset's LB, this many samples
    double presetReferenceSeconds = 0.0;
    std::vector<PresetRow> presets;
};

// ---- Scene scale: the forest-level grid and the relighting basis ----

// One forest-grid setting on the stand, against the per-instance reference.
struct ForestGridRow {
    int resolution = 0;                 // as used; 0: the forest grid off (every instance lit by its species grid alone)
    bool automatic = false;             // the automatic resolution (lighting.forest_grid_resolution 0)
    std::string dims;                   // the forest grid's nodes "XxYxZ" ("-" when off)
    double cellsPerCrown = 0.0;         // the crown's width over the forest grid's spacing
    double seconds = 0.0;               // the forest grid's build + solve, wall clock (best of the repeats)
    double imageErr = 0.0;              // relative L2 of the LB pass's luminance against the reference render
    double factorRms = 0.0, factorMax = 0.0;   // per instance: |applied factor - the reference's factor| (green)
    double interior = 1.0, edge = 1.0;  // mean green factor of the stand's interior / edge instances
    bool isDefault = false;             // the scene default's resolution setting (lighting.forest_grid_resolution)
};

// One basis storage: building it, relighting from it, and its error against direct solves.
struct BasisRow {
    bool fp16 = false;
    int directions = 0;                 // basis solves (lattice directions)
    double basisSeconds = 0.0, basisCpu = 0.0;   // solving every basis grid
    double directSeconds = 0.0, directCpu = 0.0; // one direct RGB solve, median over the suns
    double relightMs = 0.0;             // composing one sun's lighting from the basis, median over the suns
    double megabytes = 0.0;             // the basis held as fp32 grids
    double errMedian = 0.0, errMax = 0.0;   // relative L2 of the relit grid against the direct solve, over the suns
    bool isDefault = false;             // the species default's storage
};

struct SceneData {
    RunInfo run;
    std::string standScene;             // one line: the stand
    int width = 0, height = 0, spp = 0;
    int speciesGrid = 0;                // the species grid's nodes on its longest edge
    double crownWidth = 0.0;            // the crown box's larger horizontal extent, metres
    std::string speciesDims;
    std::string referenceDims;          // the reference's LB grid over the whole stand
    double referenceSeconds = 0.0;      // its solve (0 when it came from the cache)
    double floorErr = 0.0;              // the lone tree solved alone in the reference's domain vs its species grid
                                        // (relative L2 over its crown): what the larger domain changes
    double isolatedFactor = 1.0;        // the lone tree's reference factor (green): light its neighbours scatter onto it
    double oracleErr = 0.0;             // image error with each instance scaled by its reference factor: the best a
                                        // factor per instance can do
    double referenceInterior = 1.0, referenceEdge = 1.0;   // mean reference factor, interior / edge instances
    std::vector<ForestGridRow> forest;
    int suns = 0;                       // random suns the basis is checked with
    std::vector<BasisRow> basis;
};

// JSON files: accuracy/lb.json, accuracy/voxel.json, accuracy/render.json, accuracy/scene.json. save* write atomically and
// throw Error; load* return false when the file is missing and throw Error when it is unreadable.
void saveLb(const std::string& path, const LbData& d);
bool loadLb(const std::string& path, LbData* d);
void saveVoxel(const std::string& path, const VoxelData& d);
bool loadVoxel(const std::string& path, VoxelData* d);
void saveRender(const std::string& path, const RenderData& d);
bool loadRender(const std::string& path, RenderData* d);
void saveScene(const std::string& path, const SceneData& d);
bool loadScene(const std::string& path, SceneData* d);

// Indices of the points on the Pareto front of (time, error), both smaller-is-better, by ascending time.
std::vector<size_t> paretoFront(const std::vector<double>& time, const std::vector<double>& error);

// Today's date and "CPU model, N logical cores" for RunInfo.
std::string today();
std::string machineDescription();
double loadAverage();                   // 1-minute load average (/proc/loadavg), -1 when unknown

} // namespace sylva::study
