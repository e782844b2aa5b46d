// study::run: measure the chosen parts, store their numbers, write the report from every stored part.
#include "pipeline/study/study.h"

#include <filesystem>

#include "core/base/error.h"
#include "pipeline/study/study_parts.h"

namespace sylva::study {

bool parsePart(const std::string& name, Part* out)
{
    if (name == "lb") *out = Part::Lb;
    else if (name == "voxel") *out = Part::Voxel;
    else if (name == "render") *out = Part::Render;
    else if (name == "scene") *out = Part::Scene;
    else if (name == "truth") *out = Part::Truth;
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
                      renderPath = dir + "/accuracy/render.json", scenePath = dir + "/accuracy/scene.json";
    auto wants = [&](Part p) { return std::find(options.parts.begin(), options.parts.end(), p) != options.parts.end(); };

    LbData lb;
    VoxelData voxel;
    RenderData render;
    SceneData scene;
    ReportInput input;
    if (wants(Part::Lb)) {
        lb = measureLb(options);
        saveLb(lbPath, lb);
        input.lb = &lb;
    } else if (loadLb(lbPath, &lb)) {
        markDefaults(lb);   // the report follows the current default, not the one at measuring time
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
    if (wants(Part::Scene)) {
        scene = measureScene(options);
        saveScene(scenePath, scene);
        input.scene = &scene;
    } else if (loadScene(scenePath, &scene)) {
        input.scene = &scene;
    }
    if (wants(Part::Truth)) measureTruth(options);   // writes accuracy/truth.md, which the report includes
    Result result;
    writeReport(options, input, result);
    result.seconds = secondsNow() - t0;
    return result;
}

} // namespace sylva::study
