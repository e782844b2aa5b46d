// Cycles for `sylva study truth` (study_blender.cpp): Blender run as an outside program (never linked) on a
// scene script of blender_scene.h, its picture read back.
#pragma once

#include <string>

#include "pipeline/study/study_image.h"

namespace sylva::study {

// The `blender` program: SYLVA_BLENDER, else `blender` on the PATH; empty when there is none.
std::string findBlender();

// A Cycles render: its EXR's channels and the seconds Blender's render call took.
struct CyclesRun {
    ExrChannels channels;
    int width = 0, height = 0;
    double seconds = 0.0;   // the render call inside Blender (scene sync, BVH, path tracing)
    Image combined() const { return layer(channels, "Combined"); }
};

// Runs `blender -b` (under `nice -n 5`, 2 threads) on `script` with these samples and seed into `exr` (its log
// beside it as exr.log): the sun and the sky on or off, the leaves translucent or opaque, at most `bounces`
// bounces (-1: the script's), the ground plane or none. Throws Error when Blender fails.
CyclesRun runCycles(const std::string& blender, const std::string& script, const std::string& exr, int samples, int seed,
                    bool sun, bool sky, bool translucent = true, int bounces = -1, bool ground = true);

} // namespace sylva::study
