// Display transforms (display_view.h): the bundled or $OCIO's OpenColorIO config, its views resolved to CPU
// processors, and the in-house Reinhard view.
#include "pipeline/render/display_view.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <mutex>
#include <sstream>

#include <OpenColorIO/OpenColorIO.h>
#include <QFile>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "core/base/error.h"
#include "core/render/tonemap.h"

namespace OCIO = OCIO_NAMESPACE;

namespace sylva {

namespace {

constexpr size_t kGrain = 16384;   // pixels per task (and per OpenColorIO call)

struct LoadedConfig {
    OCIO::ConstConfigRcPtr config;
    ColorConfigInfo info;
};

// Names a config may give linear Rec.709 (Sylva's render space), tried in order before the scene_linear role.
const char* const kLinearRec709Names[] = {"lin_rec709", "Linear Rec.709 (sRGB)", "Utility - Linear - sRGB", "lin_srgb", "Linear"};

std::string joined(const std::vector<std::string>& names)
{
    std::string s;
    for (const std::string& n : names) s += (s.empty() ? "" : ", ") + n;
    return s;
}

LoadedConfig load()
{
    LoadedConfig out;
    const char* env = std::getenv("OCIO");
    const std::string path = env ? env : "";
    try {
        if (!path.empty()) {
            out.config = OCIO::Config::CreateFromFile(path.c_str());
            out.info.source = "$OCIO (" + path + ")";
        } else {
            std::istringstream text(bundledColorConfigText());
            out.config = OCIO::Config::CreateFromStream(text);
            out.info.source = "the bundled config";
        }
        out.config->validate();
    } catch (const OCIO::Exception& e) {
        throw Error((path.empty() ? std::string("the bundled OpenColorIO config") : "$OCIO=" + path) + ": cannot read it as an OpenColorIO config: " +
                    e.what());
    }
    const OCIO::Config& c = *out.config;
    out.info.name = c.getName() ? c.getName() : "";
    for (const char* name : kLinearRec709Names)
        if (OCIO::ConstColorSpaceRcPtr cs = c.getColorSpace(name)) {
            out.info.inputSpace = cs->getName();
            break;
        }
    if (out.info.inputSpace.empty())
        if (OCIO::ConstColorSpaceRcPtr cs = c.getColorSpace(OCIO::ROLE_SCENE_LINEAR)) out.info.inputSpace = cs->getName();
    if (out.info.inputSpace.empty())
        throw Error(out.info.source + ": the OpenColorIO config has no colour space for scene-linear Rec.709 (lin_rec709) and no "
                                      "scene_linear role; Sylva's pixels need one to enter the config");
    out.info.defaultDisplay = c.getDefaultDisplay() ? c.getDefaultDisplay() : "";
    for (int d = 0; d < c.getNumDisplays(); ++d) {
        ColorConfigInfo::Display display{c.getDisplay(d), {kReinhardView}};
        for (int v = 0; v < c.getNumViews(display.name.c_str()); ++v) {
            const std::string view = c.getView(display.name.c_str(), v);
            if (view != kReinhardView) display.views.push_back(view);   // the in-house view keeps its name
        }
        out.info.displays.push_back(std::move(display));
    }
    if (out.info.displays.empty()) throw Error(out.info.source + ": the OpenColorIO config has no (active) display");
    if (out.info.defaultDisplay.empty()) out.info.defaultDisplay = out.info.displays.front().name;
    return out;
}

const LoadedConfig& loaded()
{
    static std::mutex mutex;
    static std::unique_ptr<LoadedConfig> config;
    std::lock_guard<std::mutex> lock(mutex);
    if (!config) config = std::make_unique<LoadedConfig>(load());   // a failed load throws and is tried again
    return *config;
}

} // namespace

struct DisplayTransform::Impl {
    OCIO::ConstCPUProcessorRcPtr cpu;
};

std::string bundledColorConfigText()
{
    QFile f(QStringLiteral(":/sylva/ocio/config.ocio"));
    if (!f.open(QIODevice::ReadOnly)) throw Error("bundled resource missing: ocio/config.ocio");
    const QByteArray bytes = f.readAll();
    return std::string(bytes.constData(), size_t(bytes.size()));
}

const ColorConfigInfo& colorConfig() { return loaded().info; }

std::string describeViews(const ColorConfigInfo& config)
{
    std::string s = "OpenColorIO config " + (config.name.empty() ? std::string("(unnamed)") : "'" + config.name + "'") + " from " +
                     config.source + "; pixels enter as " + config.inputSpace + "\n";
    for (const ColorConfigInfo::Display& d : config.displays)
        s += d.name + (d.name == config.defaultDisplay ? " (default)" : "") + ": " + joined(d.views) + "\n";
    return s;
}

DisplayTransform::DisplayTransform() : m_view(kReinhardView) {}

DisplayTransform DisplayTransform::find(const std::string& display, const std::string& view)
{
    DisplayTransform t;
    if (display.empty() && view == kReinhardView) return t;
    const LoadedConfig& c = loaded();
    const std::string name = display.empty() ? c.info.defaultDisplay : display;
    const auto d = std::find_if(c.info.displays.begin(), c.info.displays.end(), [&](const auto& x) { return x.name == name; });
    if (d == c.info.displays.end()) {
        std::vector<std::string> names;
        for (const auto& x : c.info.displays) names.push_back(x.name);
        throw Error("unknown display '" + name + "' in " + c.info.source + " (displays: " + joined(names) + ")");
    }
    if (std::find(d->views.begin(), d->views.end(), view) == d->views.end())
        throw Error("unknown view '" + view + "' of display '" + name + "' in " + c.info.source + " (views: " + joined(d->views) +
                    "; sylva render --list-views lists every display's)");
    t.m_display = name;
    t.m_view = view;
    if (view == kReinhardView) return t;
    try {
        auto impl = std::make_shared<Impl>();
        impl->cpu = c.config->getProcessor(c.info.inputSpace.c_str(), name.c_str(), view.c_str(), OCIO::TRANSFORM_DIR_FORWARD)
                        ->getDefaultCPUProcessor();
        t.m_impl = std::move(impl);
    } catch (const OCIO::Exception& e) {
        throw Error("view '" + view + "' of display '" + name + "' in " + c.info.source + ": " + e.what());
    }
    return t;
}

void DisplayTransform::apply(const float* linearRgb, size_t pixels, float* outRgb01, float scale) const
{
    if (!m_impl) {
        toneMapScaled(linearRgb, pixels, outRgb01, scale);
        return;
    }
    if (pixels == 0) return;
    if (!linearRgb || !outRgb01) throw Error("display transform: null pixel buffer");
    const OCIO::CPUProcessor& cpu = *m_impl->cpu;
    tbb::parallel_for(tbb::blocked_range<size_t>(0, pixels, kGrain), [&](const tbb::blocked_range<size_t>& r) {
        float* out = outRgb01 + r.begin() * 3;
        const float* in = linearRgb + r.begin() * 3;
        const size_t n = r.size() * 3;
        for (size_t i = 0; i < n; ++i) out[i] = in[i] * scale;
        OCIO::PackedImageDesc image(out, long(r.size()), 1, 3);
        cpu.apply(image);
        for (size_t i = 0; i < n; ++i) out[i] = std::fmin(std::fmax(out[i], 0.0f), 1.0f);   // NaN -> 0
    });
}

void displayEncode(const float* linearRgb, size_t pixels, float* outRgb01, float key, const DisplayTransform& view)
{
    if (view.isReinhard()) {
        ToneMapParams params;
        params.key = key;
        toneMapToSrgb(linearRgb, pixels, outRgb01, params);
        return;
    }
    view.apply(linearRgb, pixels, outRgb01, displayExposureScale(linearRgb, pixels, key));
}

float displayExposureScale(const float* linearRgb, size_t pixels, float key)
{
    return toneMapScale(pixels > 0 && linearRgb ? logAverageLuminance(linearRgb, pixels, 3) : 0.0f, ToneMapParams{key});
}

} // namespace sylva
