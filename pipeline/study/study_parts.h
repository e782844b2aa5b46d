// The study's parts (measurements) and its report, behind study::run.
#pragma once

#include <string>

#include "core/grid/grid.h"
#include "core/lb/lb_params.h"
#include "core/scene/quality.h"
#include "pipeline/study/study.h"
#include "pipeline/study/study_data.h"

namespace sylva::study {

// The quality presets the report recommends (core/scene/quality.h): the LB part measures their LB
// settings among its runs, the render part renders the forest with each.
using sylva::QualityPreset;
using sylva::qualityPresets;

// The product's default solve of a scene species (defaultSpeciesLighting, SpeciesDesc::grid) in the
// study's terms: sets data.defaultConfig and marks the rows that are it. Run when measuring and again
// when writing the report, so the report follows the current default.
void markDefaults(LbData& data);

LbData measureLb(const Options& options);
VoxelData measureVoxel(const Options& options);
RenderData measureRender(const Options& options);
// The forest-level grid against per-instance solves on a stand, and the relighting basis against direct
// solves (study_scene.cpp).
SceneData measureScene(const Options& options);
// Sylva against Cycles (study_truth.cpp): writes outDir/accuracy/truth.md, truth/*.png and truth_time.svg;
// false (and a log line) when skipped: no `blender` (SYLVA_BLENDER overrides the program) or --quick.
bool measureTruth(const Options& options);

// Sky light (study_sky.cpp): N virtual lights x K subsets x spp on the default forest under a Preetham sky and
// two HDR maps against 1024 lights x 64 spp, beside the sun-only frame's time; the LB with the sky in its
// boundary against Monte Carlo with the same boundary. Writes outDir/accuracy/sky.md (the report includes it).
bool measureSky(const Options& options);

// What the report is written from: whichever parts have stored results.
struct ReportInput {
    const LbData* lb = nullptr;
    const VoxelData* voxel = nullptr;
    const RenderData* render = nullptr;
    const SceneData* scene = nullptr;
};

// Writes outDir/ACCURACY.md and, with gnuplot, outDir/accuracy/*.png (result.plots, result.plotNote).
void writeReport(const Options& options, const ReportInput& input, Result& result);

// The real tree of the studies: options.treeMesh or resources/trees/quaternius/OBJ/Tree_1.obj.
std::string treeMeshPath(const Options& options);

// Value of a grid's channel c at a world position: trilinear between nodes, clamped to the grid.
float sampleWorld(const LightingGrid& g, const glm::dvec3& world, int c);

// Relative L2 of linear luminance, image a against reference b: sqrt(sum (L_a - L_b)^2 / sum L_b^2).
double imageError(const std::vector<glm::vec3>& a, const std::vector<glm::vec3>& b);

// Pictures for the report (study_image.cpp): the exposure of Reinhard's mapping for a reference picture (the
// same for every picture compared with it, so they differ as their linear pictures do), the mapping with it
// (sRGB-encoded), and an sRGB picture as PNG (throws Error).
float exposureOf(const std::vector<glm::vec3>& reference);
std::vector<glm::vec3> toneMap(const std::vector<glm::vec3>& linear, float scale);
void writePng(const std::string& path, const std::vector<glm::vec3>& srgb, int w, int h);

// Wall-clock seconds (steady clock) and the process's CPU seconds, all threads (user + system). The
// machine is shared: CPU time is what a measurement costs whatever else runs; wall time is what a user
// waits on an idle machine, about CPU time / 2 on 2 cores when the work is parallel.
double secondsNow();
double cpuNow();

// A part's RunInfo: startRun fills in the date, machine, --quick and the load now (and holds the start
// time in `seconds`); finishRun makes `seconds` the wall time since then and records the load at the end.
RunInfo startRun(const Options& o);
void finishRun(RunInfo& run);

inline void say(const Options& o, const std::string& line)
{
    if (o.log) o.log(line);
}

} // namespace sylva::study
