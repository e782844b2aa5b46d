// Pictures of `sylva study truth` (study_image.h), and the report's pictures of study_parts.h (exposureOf,
// toneMap, writePng).
#include "pipeline/study/study_image.h"

#include <algorithm>
#include <cmath>
#include <utility>

#include "core/base/error.h"
#include "core/render/tonemap.h"
#include "pipeline/io/image_io.h"
#include "pipeline/io/image_module.h"
#include "pipeline/study/flip.h"
#include "pipeline/study/study_parts.h"

namespace sylva::study {

ExrChannels readExrChannels(const std::string& path, int& w, int& h)
{
    std::string error;
    auto in = image_module::Reader::open(path, false, error);
    if (!in) throw Error(path + ": cannot read the Cycles picture: " + error);
    const image_module::Info spec = in->info();   // a copy: the reader closes before the pixels are used
    w = spec.width;
    h = spec.height;
    const int nc = spec.channels;
    std::vector<float> all;
    if (!in->read(nc, all, error)) throw Error(path + ": " + error);
    ExrChannels out;
    for (int c = 0; c < nc; ++c) {
        std::vector<float>& v = out[spec.channelNames[size_t(c)]];
        v.resize(size_t(w) * size_t(h));
        for (size_t p = 0; p < v.size(); ++p) v[p] = all[p * size_t(nc) + size_t(c)];
    }
    return out;
}

Image layer(const ExrChannels& ch, const std::string& name)
{
    auto find = [&](const std::string& c) -> const std::vector<float>* {
        for (const auto& [k, v] : ch) {
            const std::string tail = name + "." + c;
            if (k == tail || (k.size() > tail.size() && k.compare(k.size() - tail.size(), tail.size(), tail) == 0 &&
                              k[k.size() - tail.size() - 1] == '.'))
                return &v;
        }
        return nullptr;
    };
    const std::vector<float>*r = find("R"), *g = find("G"), *b = find("B");
    if (!r || !g || !b) return {};
    Image im(r->size());
    for (size_t p = 0; p < im.size(); ++p) im[p] = {(*r)[p], (*g)[p], (*b)[p]};
    return im;
}

Image mul(const Image& a, const Image& b)
{
    Image o(a.size());
    for (size_t p = 0; p < a.size() && p < b.size(); ++p) o[p] = a[p] * b[p];
    return o;
}
Image add(const Image& a, const Image& b)
{
    Image o(a.size());
    for (size_t p = 0; p < a.size() && p < b.size(); ++p) o[p] = a[p] + b[p];
    return o;
}

double relL2Rgb(const Image& a, const Image& b)
{
    double d = 0.0, n = 0.0;
    for (size_t p = 0; p < a.size() && p < b.size(); ++p)
        for (int c = 0; c < 3; ++c) {
            d += double(a[p][c] - b[p][c]) * double(a[p][c] - b[p][c]);
            n += double(b[p][c]) * double(b[p][c]);
        }
    return n > 0.0 ? std::sqrt(d / n) : 0.0;
}

float exposureOf(const Image& ref) { return toneMapScale(logAverageLuminance(&ref[0].x, ref.size(), 3)); }
Image toneMap(const Image& im, float scale)
{
    Image o(im.size());
    toneMapScaled(&im[0].x, im.size(), &o[0].x, scale);
    return o;
}

void writePng(const std::string& path, const Image& srgb, int w, int h)
{
    ImageRgba img(w, h);
    for (size_t p = 0; p < srgb.size(); ++p) {
        for (int c = 0; c < 3; ++c) img.pixels[p * 4 + size_t(c)] = std::clamp(srgb[p][c], 0.0f, 1.0f);
        img.pixels[p * 4 + 3] = 1.0f;
    }
    writeImage(path, img, 3);
}

Image heat(const std::vector<float>& v)
{
    Image o(v.size());
    for (size_t p = 0; p < v.size(); ++p) {
        const float t = std::clamp(v[p], 0.0f, 1.0f) * 3.0f;
        o[p] = {std::min(t, 1.0f), std::clamp(t - 1.0f, 0.0f, 1.0f), std::clamp(t - 2.0f, 0.0f, 1.0f)};
    }
    return o;
}

Metrics compare(const Image& test, const Image& ref, int w, int h, float scale, std::vector<float>* flipMap)
{
    Metrics m;
    m.lum = imageError(test, ref);
    m.rgb = relL2Rgb(test, ref);
    FlipResult fr = flip(toneMap(ref, scale), toneMap(test, scale), w, h);
    m.flip = fr.mean;
    if (flipMap) *flipMap = std::move(fr.map);
    return m;
}

double meanLum(const Image& im, const std::vector<char>& mask)
{
    double s = 0.0;
    size_t n = 0;
    for (size_t p = 0; p < im.size(); ++p)
        if (mask[p]) {
            s += luminance(im[p]);
            ++n;
        }
    return n ? s / double(n) : 0.0;
}

} // namespace sylva::study
