// DEMs through OpenImageIO into core/terrain height fields.
#include "pipeline/io/dem_io.h"

#include <cmath>
#include <filesystem>
#include <vector>

#include "core/base/error.h"
#include "core/base/memory.h"
#include "pipeline/io/image_module.h"

namespace sylva {

namespace fs = std::filesystem;

HeightField loadDem(const std::string& path, double spacing, double heightScale)
{
    if (!std::isfinite(spacing) || !(spacing > 0.0)) throw Error(path + ": terrain spacing " + std::to_string(spacing) + " must be finite and > 0 (metres)");
    if (!std::isfinite(heightScale) || !(heightScale > 0.0))
        throw Error(path + ": terrain height scale " + std::to_string(heightScale) + " must be finite and > 0 (metres per DEM unit)");
    std::error_code ec;
    if (!fs::is_regular_file(path, ec)) throw Error(path + ": no such DEM file");
    std::string error;
    auto in = image_module::Reader::open(path, false, error);
    if (!in) throw Error(path + ": cannot read the DEM as an image (" + error + ")");
    const image_module::Info spec = in->info();   // a copy: the reader closes before the pixels are used
    const long long w = spec.width, h = spec.height;
    if (w < 2 || h < 2 || spec.channels < 1)
        throw Error(path + ": a DEM needs at least 2 x 2 samples, this image has " + std::to_string(w) + " x " + std::to_string(h));
    // Heights (kept) + one row of the read + the pyramid (a min and a max per block, 4/3 of its finest level's):
    // checked first.
    const double pyramid = 2.0 * 4.0 / 3.0 / double(kHeightBlock * kHeightBlock);
    const double need = double(w) * double(h) * 4.0 * (1.0 + pyramid) + double(w) * spec.channels * 4.0;
    const double avail = availableMemoryBytes();
    if (avail > 0.0 && need > avail)
        throw Error(path + ": a " + std::to_string(w) + " x " + std::to_string(h) + " DEM needs " + std::to_string(int(need / 1048576.0)) +
                    " MiB, " + std::to_string(int(avail / 1048576.0)) + " MiB are available");
    if (w > (1ll << 30) / h) throw Error(path + ": " + std::to_string(w) + " x " + std::to_string(h) + " samples is more than this build traces (2^30)");
    // Integer formats are read normalized to [0, 1]: their DEM unit is 1 / the type's maximum.
    double unit = 1.0;
    using image_module::SampleType;
    switch (spec.type) {
    case SampleType::UInt8: unit = 255.0; break;
    case SampleType::UInt16: unit = 65535.0; break;
    case SampleType::Int16: unit = 32767.0; break;
    case SampleType::UInt32: unit = 4294967295.0; break;
    case SampleType::Int32: unit = 2147483647.0; break;
    default: break;   // half, float, double: as stored
    }
    std::vector<float> heights;
    if (!in->read(1, heights, error)) throw Error(path + ": cannot decode the DEM (" + error + ")");
    in.reset();
    const double scale = unit * heightScale;
    for (size_t k = 0; k < heights.size(); ++k) {
        if (!std::isfinite(heights[k]))
            throw Error(path + ": DEM sample (column " + std::to_string(k % size_t(w)) + ", row " + std::to_string(k / size_t(w)) + ") is " +
                        (std::isnan(heights[k]) ? "NaN" : (heights[k] < 0.0f ? "-infinity" : "infinity")) + ", not a height");
        heights[k] = float(double(heights[k]) * scale);
    }
    return buildHeightField(std::move(heights), uint32_t(w), uint32_t(h), float(spacing), float(spacing));
}

void loadSceneTerrain(Scene& scene)
{
    TerrainDesc& t = scene.terrain;
    if (!t.enabled() || t.field) return;
    t.field = std::make_shared<const HeightField>(loadDem(t.dem, t.spacing, t.heightScale));
}

} // namespace sylva
