// Cycles for `sylva study truth` (study_blender.h).
#include "pipeline/study/study_blender.h"

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "core/base/error.h"

namespace sylva::study {
namespace fs = std::filesystem;

std::string findBlender()
{
    if (const char* e = std::getenv("SYLVA_BLENDER")) return e;
    const char* path = std::getenv("PATH");
    std::stringstream ss(path ? path : "");
    std::string d;
    while (std::getline(ss, d, ':'))
        if (!d.empty() && fs::exists(d + "/blender")) return d + "/blender";
    return {};
}

CyclesRun runCycles(const std::string& blender, const std::string& script, const std::string& exr, int samples, int seed,
                    bool sun, bool sky, bool translucent, int bounces, bool ground)
{
    const std::string log = exr + ".log";
    const std::string cmd = "nice -n 5 '" + blender + "' -b --factory-startup --python '" + script + "' -- --samples " +
                            std::to_string(samples) + " --seed " + std::to_string(seed) + " --out '" + exr + "' --sun " +
                            (sun ? "1" : "0") + " --sky " + (sky ? "1" : "0") + " --translucent " + (translucent ? "1" : "0") +
                            (bounces >= 0 ? " --bounces " + std::to_string(bounces) : std::string()) + (ground ? "" : " --ground 0") + " --threads 2 > '" + log + "' 2>&1";
    const int rc = std::system(cmd.c_str());
    std::ifstream in(log);
    std::string line;
    CyclesRun r;
    r.seconds = -1.0;
    while (std::getline(in, line))
        if (line.rfind("SYLVA_CYCLES_SECONDS=", 0) == 0) r.seconds = std::atof(line.c_str() + 21);
    if (rc != 0 || r.seconds < 0.0) throw Error("Cycles run failed (exit " + std::to_string(rc) + "): see " + log);
    r.channels = readExrChannels(exr, r.width, r.height);
    return r;
}

} // namespace sylva::study
