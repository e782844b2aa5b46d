// Volume optics presets and tracer names.
#include "core/scene/volume.h"

namespace sylva {

bool volumePreset(const std::string& name, lb::LbParams* out)
{
    if (name == "smoke") {
        // Grey soot-laden smoke: albedo 0.5, mildly forward scattering (the smoke renders of the graphics-blog post
        // "Adventures in Fluid Simulation" use a
        // dark, absorbing medium); f_0 kept as for clouds (no plant absorption model).
        lb::LbParams p;
        for (auto& c : p.channels) c = lb::ChannelParams{0.25f, 0.25f, 0.3f};
        p.zeroF0 = false;
        *out = p;
        return true;
    }
    const lb::Preset* preset = lb::findPreset(name);
    if (!preset || name == "leaf" || name == "dogrose") return false;
    *out = lb::paramsFromPreset(*preset);
    return true;
}

const char* volumeTracerName(VolumeTracer t)
{
    switch (t) {
    case VolumeTracer::Lb: return "lb";
    case VolumeTracer::Single: return "single";
    case VolumeTracer::Combined: return "combined";
    }
    return "lb";
}

bool parseVolumeTracer(const std::string& name, VolumeTracer* out)
{
    for (VolumeTracer t : {VolumeTracer::Lb, VolumeTracer::Single, VolumeTracer::Combined})
        if (name == volumeTracerName(t)) {
            *out = t;
            return true;
        }
    return false;
}

} // namespace sylva
