// Golden pictures in linear radiance: tests/data/golden/NAME.exr holds a picture's linear RGB as 32-bit
// float OpenEXR (before exposure and tone curve) and a render is compared with it by compareLinear.
// A missing baseline is written and the check fails; SYLVA_TEST_UPDATE=1 rewrites the baselines (look at
// them before committing: `sylva info`, or any EXR viewer). On failure the render and a picture of each
// pixel's difference over its bound (white = at the bound) are written to outDir.
#pragma once

#include <QDir>
#include <QFile>
#include <QString>

#include <algorithm>
#include <string>
#include <vector>

#include "pipeline/io/image_io.h"
#include "tests/common/linear_compare.h"

namespace sylva::test {

inline void writeLinearExr(const std::string& path, const std::vector<glm::vec3>& rgb, int w, int h)
{
    std::vector<float> v;
    v.reserve(rgb.size() * 3);
    for (const glm::vec3& c : rgb) v.insert(v.end(), {c.x, c.y, c.z});
    writeImageChannels(path, w, h, {"R", "G", "B"}, v);
}

inline std::vector<glm::vec3> readLinearExr(const std::string& path, int* w = nullptr, int* h = nullptr)
{
    const ImageRgba img = readImage(path);
    std::vector<glm::vec3> rgb(size_t(img.width) * size_t(img.height));
    for (size_t p = 0; p < rgb.size(); ++p) rgb[p] = {img.pixels[4 * p], img.pixels[4 * p + 1], img.pixels[4 * p + 2]};
    if (w) *w = img.width;
    if (h) *h = img.height;
    return rgb;
}

// Compares `linear` (w x h) with tests/data/golden/<name>.exr. Returns an empty string when it passes,
// else what failed; `summary` (when given) receives compareLinear's line. `writes`: whether this render may
// write the baseline (false for a variant compared with another render's baseline).
inline QString checkGolden(const std::string& name, const std::vector<glm::vec3>& linear, int w, int h, const LinearTolerance& tol,
                           const QString& outDir, std::string* summary = nullptr, bool writes = true)
{
    const std::string golden = std::string(SYLVA_TEST_DATA) + "/golden/" + name + ".exr";
    const bool update = writes && qEnvironmentVariableIsSet("SYLVA_TEST_UPDATE");
    if (update || (writes && !QFile::exists(QString::fromStdString(golden)))) {
        QDir().mkpath(QString(SYLVA_TEST_DATA) + "/golden");
        writeLinearExr(golden, linear, w, h);
        return update ? QString() : QString::fromStdString("baseline was missing; wrote " + golden);
    }
    int gw = 0, gh = 0;
    const std::vector<glm::vec3> want = readLinearExr(golden, &gw, &gh);
    if (gw != w || gh != h)
        return QString("%1: the baseline is %2x%3, the render %4x%5").arg(name.c_str()).arg(gw).arg(gh).arg(w).arg(h);
    const LinearComparison c = compareLinear(linear, want, tol);
    if (summary) *summary = c.summary;
    if (c.pass) return QString();
    QDir().mkpath(outDir);
    const std::string base = (outDir + "/").toStdString() + name;
    writeLinearExr(base + ".exr", linear, w, h);
    ImageRgba diff(w, h, glm::vec4(0.0f, 0.0f, 0.0f, 1.0f));
    for (size_t p = 0; p < want.size(); ++p)
        for (int k = 0; k < 3; ++k)
            diff.pixels[4 * p + size_t(k)] =
                float(std::min(1.0, std::fabs(double(linear[p][k]) - want[p][k]) / (tol.pixelRelative * std::fabs(want[p][k]) + c.floor)));
    writeImage(base + ".diff.png", diff);
    return QString("%1: %2; see %3.exr and .diff.png").arg(name.c_str(), QString::fromStdString(c.summary), QString::fromStdString(base));
}

} // namespace sylva::test
