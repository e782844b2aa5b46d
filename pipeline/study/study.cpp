// study::run: measure the chosen parts, store their numbers, write the report from every stored part.
#include "pipeline/study/study.h"

#include <filesystem>

#include "core/base/error.h"
#include "pipeline/study/study_parts.h"

namespace sylva::study {

const std::vector<QualityPreset>& qualityPresets()
{
    // Chosen from the measured fronts (docs/ACCURACY.md "Quality presets"); the report checks that
    // each sits on its front and prints what it costs.
    static const std::vector<QualityPreset> presets{
        {"preview", 32, "tol 1e-3", false, 1, 50.0f, 25.0f},
        {"final", 64, "tol 1e-3", false, 4, 0.0f, 0.0f},
        {"reference", 128, "tol 1e-4", false, 64, 0.0f, 0.0f},
    };
    return presets;
}

void applyLbPreset(const QualityPreset& preset, lb::LbParams& params, const glm::ivec3& dims)
{
    const std::string steps = preset.steps;
    params.steps = 0;
    params.tolerance = 0.0;
    if (steps == "half") {
        if (dims.x <= 0) throw Error(std::string("preset ") + preset.name + ": half steps need the grid");
        params.steps = std::max(1, lb::defaultSteps(dims) / 2);
    } else if (steps == "tol 1e-3") {
        params.tolerance = 1e-3;
    } else if (steps == "tol 1e-4") {
        params.tolerance = 1e-4;
    } else if (steps != "default") {
        throw Error(std::string("preset ") + preset.name + ": unknown steps '" + steps + "'");
    }
    params.storage = preset.fp16 ? lb::Storage::Fp16 : lb::Storage::Fp32;
}

bool parsePart(const std::string& name, Part* out)
{
    if (name == "lb") *out = Part::Lb;
    else if (name == "voxel") *out = Part::Voxel;
    else if (name == "render") *out = Part::Render;
    else return false;
    return true;
}

Result run(const Options& options)
{
    const double t0 = secondsNow();
    const std::string dir = options.outDir.empty() ? std::string(".") : options.outDir;
    std::error_code ec;
    std::filesystem::create_directories(dir + "/accuracy", ec);
    if (ec) throw Error(dir + "/accuracy: cannot create the folder: " + ec.message());
    const std::string lbPath = dir + "/accuracy/lb.json", voxelPath = dir + "/accuracy/voxel.json",
                      renderPath = dir + "/accuracy/render.json";
    auto wants = [&](Part p) { return std::find(options.parts.begin(), options.parts.end(), p) != options.parts.end(); };

    LbData lb;
    VoxelData voxel;
    RenderData render;
    ReportInput input;
    if (wants(Part::Lb)) {
        lb = measureLb(options);
        saveLb(lbPath, lb);
        input.lb = &lb;
    } else if (loadLb(lbPath, &lb)) {
        input.lb = &lb;
    }
    if (wants(Part::Voxel)) {
        voxel = measureVoxel(options);
        saveVoxel(voxelPath, voxel);
        input.voxel = &voxel;
    } else if (loadVoxel(voxelPath, &voxel)) {
        input.voxel = &voxel;
    }
    if (wants(Part::Render)) {
        render = measureRender(options);
        saveRender(renderPath, render);
        input.render = &render;
    } else if (loadRender(renderPath, &render)) {
        input.render = &render;
    }
    Result result;
    writeReport(options, input, result);
    result.seconds = secondsNow() - t0;
    return result;
}

} // namespace sylva::study
