// The display transform of the picture: linear Rec.709 radiance to the display-encoded values of a PNG or
// the studio's screen. The in-house Reinhard curve (the seed's picture, the default), or a display and view
// of an OpenColorIO config: the bundled resources/ocio/config.ocio, or $OCIO's. OpenColorIO is the colour
// management library artists' tools share (Nuke, Blender, Houdini, Resolve), so a view named here shows a
// render as those tools show its EXR. Every view gets the picture exposed as today, key / log-average
// luminance (core/render/tonemap.h), so middle grey sits at render.key; the view applies its curve. CPU only:
// the GPU viewport keeps its Reinhard pass (core/render/tonemap_film.h).
#pragma once

#include <cstddef>
#include <memory>
#include <string>
#include <vector>

namespace sylva {

// The view that keeps the seed's picture to the bit: Reinhard's global operator on luminance, then the sRGB
// curve (toneMapScaled). It is not an OpenColorIO view (its curve depends on the image's log-average, and it
// scales colour by a luminance ratio), so Sylva computes it and offers it beside the config's views, first.
inline constexpr const char* kReinhardView = "Sylva Reinhard";

// The OpenColorIO config the views come from.
struct ColorConfigInfo {
    std::string source;       // "the bundled config" or "$OCIO (PATH)"
    std::string name;         // the config's name
    std::string inputSpace;   // the config's colour space Sylva's linear Rec.709 pixels are read as
    std::string defaultDisplay;
    struct Display {
        std::string name;
        std::vector<std::string> views;   // kReinhardView first, then the config's active views
    };
    std::vector<Display> displays;        // the config's active displays, in its order
};

// The config in use: the one $OCIO names when the variable is set and not empty, else the bundled one (built
// into the program; installed as share/sylva/ocio/config.ocio). Read on first use (thread-safe), once per
// process. The input colour space is the config's first of lin_rec709, "Linear Rec.709 (sRGB)", "Utility -
// Linear - sRGB", lin_srgb and Linear (names, aliases or roles), else its scene_linear role. Throws Error
// naming $OCIO's file when it cannot be read, or a config without displays or without such a colour space
// (and tries again at the next call).
const ColorConfigInfo& colorConfig();

// The bundled config's text (resources/ocio/config.ocio).
std::string bundledColorConfigText();

// For `sylva render --list-views`: the config's source and name, then one line per display,
// "DISPLAY: VIEW, VIEW, ..." (the default display marked "(default)").
std::string describeViews(const ColorConfigInfo& config);

// A resolved display and view. Copies share the OpenColorIO processor; apply() may run on many threads.
class DisplayTransform {
public:
    DisplayTransform();   // kReinhardView; reads no config

    // The view `view` of `display` (empty: the config's default display). kReinhardView with no display reads
    // no config. Throws Error naming the unknown display (and the displays) or view (and the display's views).
    static DisplayTransform find(const std::string& display, const std::string& view);

    bool isReinhard() const { return !m_impl; }
    const std::string& display() const { return m_display; }   // empty for kReinhardView without a display
    const std::string& view() const { return m_view; }

    // `pixels` linear RGB pixels (3 floats each) x scale through the view into outRgb01 (3 floats each,
    // display-encoded, in [0, 1]; NaN gives 0). kReinhardView: toneMapScaled(linearRgb, pixels, outRgb01,
    // scale) itself. Parallel over pixels; in and out may be the same buffer.
    void apply(const float* linearRgb, size_t pixels, float* outRgb01, float scale) const;

private:
    struct Impl;
    std::shared_ptr<const Impl> m_impl;
    std::string m_display, m_view;
};

// A whole picture through a view: scale = key / log-average luminance (toneMapScale), then apply. With
// kReinhardView exactly toneMapToSrgb. Throws Error on a bad key, as toneMapToSrgb does.
void displayEncode(const float* linearRgb, size_t pixels, float* outRgb01, float key, const DisplayTransform& view);

// The scale displayEncode exposes a picture of these pixels with (key / log-average luminance): held from
// one picture and passed to DisplayTransform::apply for others, a series of pictures keeps one exposure.
float displayExposureScale(const float* linearRgb, size_t pixels, float key);

} // namespace sylva
