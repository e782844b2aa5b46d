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
    else if (name == "sky") *out = Part::Sky;
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
    auto wants = [&](Part p) { return std::find(options.parts.begin(), options.parts.end(), p) != options.parts.end(); };
    // A part asked for is measured and stored in DIR/accuracy/<name>.json; any other is read from there when
    // stored. Either way the report gets it (null: neither).
    auto part = [&](Part p, const char* name, auto& data, auto measure, auto save, auto load) -> decltype(&data) {
        const std::string path = dir + "/accuracy/" + name + ".json";
        if (wants(p)) {
            data = measure(options);
            save(path, data);
            return &data;
        }
        return load(path, &data) ? &data : nullptr;
    };

    LbData lb;
    VoxelData voxel;
    RenderData render;
    SceneData scene;
    ReportInput input;
    input.lb = part(Part::Lb, "lb", lb, measureLb, saveLb, loadLb);
    if (input.lb && !wants(Part::Lb)) markDefaults(lb);   // the report follows the current default, not the one at measuring time
    input.voxel = part(Part::Voxel, "voxel", voxel, measureVoxel, saveVoxel, loadVoxel);
    input.render = part(Part::Render, "render", render, measureRender, saveRender, loadRender);
    input.scene = part(Part::Scene, "scene", scene, measureScene, saveScene, loadScene);
    if (wants(Part::Truth)) measureTruth(options);   // writes accuracy/truth.md, which the report includes
    if (wants(Part::Sky)) measureSky(options);       // writes accuracy/sky.md, likewise
    Result result;
    writeReport(options, input, result);
    result.seconds = secondsNow() - t0;
    return result;
}

} // namespace sylva::study
