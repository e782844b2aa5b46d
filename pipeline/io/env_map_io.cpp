// Environment maps through OpenImageIO (image_module.h).
#include "pipeline/io/env_map_io.h"

#include <cstdio>
#include <filesystem>
#include <vector>

#include "core/base/error.h"
#include "core/scene/scene.h"
#include "core/sky/sky_light.h"
#include "pipeline/io/image_module.h"
#include "pipeline/render/render_job.h"

namespace sylva {

namespace fs = std::filesystem;

EnvMapFile readEnvMap(const std::string& path, float spikeRatio)
{
    if (!fs::exists(path)) throw Error(path + ": no such environment map");
    if (fs::is_directory(path)) throw Error(path + ": is a folder, not an environment map");
    std::string error;
    auto in = image_module::Reader::open(path, false, error);
    if (!in) throw Error(path + ": not an image OpenImageIO can read (" + error + ")");
    const image_module::Info spec = in->info();   // a copy: the reader closes before the pixels are used
    const int w = spec.width, h = spec.height, nc = spec.channels;
    sky::checkEnvMapShape(w, h, path);
    if (nc <= 0) throw Error(path + ": the image has no channels");
    std::vector<float> data;
    if (!in->read(nc, data, error)) throw Error(path + ": cannot decode the image (" + error + ")");
    in.reset();
    EnvMapFile f;
    f.map.width = w;
    f.map.height = h;
    f.map.rgb.resize(size_t(w) * size_t(h) * 3);
    for (size_t p = 0; p < size_t(w) * size_t(h); ++p)
        for (int c = 0; c < 3; ++c) f.map.rgb[p * 3 + size_t(c)] = data[p * size_t(nc) + size_t(nc >= 3 ? c : 0)];
    f.cleaned = sky::cleanEnvMap(f.map, spikeRatio);
    return f;
}

std::string envMapCleanSummary(const std::string& path, const EnvMapFile& file)
{
    const sky::EnvMapCleanReport& r = file.cleaned;
    char buf[512];
    std::snprintf(buf, sizeof buf, "%s: %d x %d", path.c_str(), file.map.width, file.map.height);
    std::string s = buf;
    if (r.negative == 0 && r.nonFinite == 0 && r.spikes == 0) return s + ", no negative, non-finite or isolated extreme pixels";
    std::snprintf(buf, sizeof buf, ", cleaned: %zu pixels with negative values -> 0, %zu with NaN/Inf -> 0, %zu extreme values from lossy "
                  "compression (isolated: -> the neighbours' maximum, %.4g luminance x sr removed; single-channel: -> grey)",
                  r.negative, r.nonFinite, r.spikes, r.spikeEnergy);
    return s + buf;
}

std::string loadSceneSky(Scene& scene, const EnvMapReader& read)
{
    SkyDesc& d = scene.skyModel;
    if (!d.analytic() || d.built) return std::string();
    if (d.kind == sky::SkyKind::Preetham) {
        sky::PreethamParams p;
        p.turbidity = d.turbidity;
        p.sunDirection = scene.sun.direction;
        p.scale = d.scale;
        d.built = std::make_shared<const sky::Sky>(sky::preethamSky(p, bundledCieTable()));
        return std::string();
    }
    if (d.kind == sky::SkyKind::Uniform) {
        // The constant colour as a map: 256 x 128 pixels (more than the virtual lights the defaults ask for), no sun
        // search (the scene's sun stays).
        const glm::vec3 c = scene.sky;
        if (!std::isfinite(c.x + c.y + c.z) || glm::any(glm::lessThan(c, glm::vec3(0.0f))))
            throw Error("uniform sky: the colour must be finite and >= 0");
        sky::EnvMap map;
        map.width = 256;
        map.height = 128;
        map.rgb.resize(size_t(map.width) * size_t(map.height) * 3);
        for (size_t i = 0; i < map.rgb.size(); i += 3) map.rgb[i] = c.x, map.rgb[i + 1] = c.y, map.rgb[i + 2] = c.z;
        d.built = std::make_shared<const sky::Sky>(sky::mapSky(std::move(map), 0.0f, 1.0f, false));
        return std::string();
    }
    EnvMapFile f = read ? read(d.path) : readEnvMap(d.path);
    const std::string summary = envMapCleanSummary(d.path, f);
    d.built = std::make_shared<const sky::Sky>(sky::mapSky(std::move(f.map), d.rotationDeg, d.intensity, d.sunFromMap));
    return summary;
}

} // namespace sylva
