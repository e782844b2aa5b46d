// The study's parts (measurements) and its report, behind study::run.
#pragma once

#include <string>

#include "core/grid/grid.h"
#include "core/lb/lb_params.h"
#include "pipeline/study/study.h"
#include "pipeline/study/study_data.h"

namespace sylva::study {

// The quality presets the report recommends (docs/ACCURACY.md "Quality presets"): LB settings of every
// species and render settings. The LB part measures their LB settings among its runs, the render part
// renders the forest with each.
struct QualityPreset {
    const char* name;                   // "preview", "final", "reference"
    int grid;                           // LB nodes on the longest axis
    const char* steps;                  // "default", "half", "tol 1e-3", "tol 1e-4" (as LbRow::steps)
    bool fp16;
    int spp;
    float alphaDistance, pruneDistance; // metres, 0 = off
};
const std::vector<QualityPreset>& qualityPresets();
// A preset's steps/tolerance and storage applied to LB parameters ("half" needs the grid: dims).
void applyLbPreset(const QualityPreset& preset, lb::LbParams& params, const glm::ivec3& dims);

LbData measureLb(const Options& options);
VoxelData measureVoxel(const Options& options);
RenderData measureRender(const Options& options);

// What the report is written from: whichever parts have stored results.
struct ReportInput {
    const LbData* lb = nullptr;
    const VoxelData* voxel = nullptr;
    const RenderData* render = nullptr;
};

// Writes outDir/ACCURACY.md and, with gnuplot, outDir/accuracy/*.png (result.plots, result.plotNote).
void writeReport(const Options& options, const ReportInput& input, Result& result);

// The real tree of the studies: options.treeMesh or ../shared/data/trees/quaternius/OBJ/Tree_1.obj.
std::string treeMeshPath(const Options& options);

// Value of a grid's channel c at a world position: trilinear between nodes, clamped to the grid.
float sampleWorld(const LightingGrid& g, const glm::dvec3& world, int c);

// Wall-clock seconds (steady clock) and the process's CPU seconds, all threads (user + system). The
// machine is shared: CPU time is what a measurement costs whatever else runs; wall time is what a user
// waits on an idle machine, about CPU time / 2 on 2 cores when the work is parallel.
double secondsNow();
double cpuNow();

inline void say(const Options& o, const std::string& line)
{
    if (o.log) o.log(line);
}

} // namespace sylva::study
