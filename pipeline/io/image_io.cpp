// Image files through OpenImageIO (loaded on first use: image_module.h).
#include "pipeline/io/image_io.h"

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "core/base/error.h"
#include "pipeline/io/atomic_file.h"
#include "pipeline/io/image_module.h"

namespace sylva {

namespace fs = std::filesystem;

namespace {

std::string lowerExtension(const std::string& path)
{
    std::string ext = fs::path(path).extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
    return ext;
}

} // namespace

ImageRgba readImage(const std::string& path)
{
    if (!fs::exists(path)) throw Error(path + ": no such image file");
    // Keep colour and alpha as stored (unassociated), as textures are authored; OIIO would otherwise
    // premultiply, turning the colour of cut-out texels black.
    std::string error;
    auto in = image_module::Reader::open(path, true, error);
    if (!in) throw Error(path + ": cannot read image (" + error + ")");
    const image_module::Info spec = in->info();   // a copy: the reader closes before the pixels are used
    const int w = spec.width, h = spec.height, nc = spec.channels;
    if (w <= 0 || h <= 0 || nc <= 0 || size_t(w) * size_t(h) > (size_t(1) << 28))
        throw Error(path + ": image has an unsupported size " + std::to_string(w) + "x" + std::to_string(h));
    std::vector<float> data;
    if (!in->read(nc, data, error)) throw Error(path + ": cannot decode image (" + error + ")");
    in.reset();
    const int alphaChannel = spec.alphaChannel >= 0 ? spec.alphaChannel : (nc == 2 ? 1 : (nc >= 4 ? 3 : -1));
    ImageRgba img(w, h);
    for (size_t p = 0; p < size_t(w) * size_t(h); ++p) {
        const float* s = &data[p * size_t(nc)];
        float* d = &img.pixels[p * 4];
        if (nc <= 2) {
            d[0] = d[1] = d[2] = s[0];
        } else {
            d[0] = s[0];
            d[1] = s[1];
            d[2] = s[2];
        }
        d[3] = alphaChannel >= 0 ? s[alphaChannel] : 1.0f;
    }
    return img;
}

bool imageHasAlpha(const std::string& path)
{
    std::string error;
    auto in = image_module::Reader::open(path, false, error);
    if (!in) throw Error(path + ": cannot read image (" + error + ")");
    const image_module::Info spec = in->info();   // a copy: the reader closes before the pixels are used
    return spec.alphaChannel >= 0 || spec.channels == 2 || spec.channels >= 4;
}

namespace {

// The one whole-image writer: pixels from float `data` (channels interleaved), through a temporary file
// beside the target (keeping the extension, so OIIO picks the same format), renamed at the end.
void writePixels(const std::string& path, int width, int height, int channels, const std::vector<std::string>* names,
                 image_module::SampleType stored, int alphaChannel, const float* data, const std::vector<std::string>* attributes = nullptr)
{
    // Float files hold Sylva's scene-linear Rec.709 radiance (renders, passes, sky maps): the header says so.
    const bool isFloat = stored == image_module::SampleType::Half || stored == image_module::SampleType::Float;
    const image_module::ColorSpace space = isFloat ? image_module::ColorSpace::LinearRec709 : image_module::ColorSpace::Unnamed;
    AtomicFile file(path, AtomicFile::Sync::No, "image");
    const std::string& temp = file.pathForWriter();
    std::string error;
    auto out = image_module::Writer::open(temp, width, height, channels, names, stored, alphaChannel, space, error, attributes);
    if (!out) throw Error(path + ": " + error);
    if (!out->writeImage(data, error) || !out->close(error)) throw Error(path + ": cannot write image (" + error + ")");
    file.commit();
}

} // namespace

void writeImage(const std::string& path, const ImageRgba& image, int channels)
{
    if (image.empty()) throw Error(path + ": refusing to write an empty image");
    if (channels != 3 && channels != 4) throw Error(path + ": images are written with 3 or 4 channels");
    const std::string ext = lowerExtension(path);
    const bool isFloat = ext == ".exr" || ext == ".hdr";
    std::vector<float> data(size_t(image.width) * size_t(image.height) * size_t(channels));
    for (size_t p = 0; p < size_t(image.width) * size_t(image.height); ++p)
        for (int c = 0; c < channels; ++c) {
            float v = image.pixels[p * 4 + size_t(c)];
            data[p * size_t(channels) + size_t(c)] = isFloat ? v : std::clamp(v, 0.0f, 1.0f);
        }
    // 4 channels: the pixels are straight (unassociated) RGBA
    writePixels(path, image.width, image.height, channels, nullptr, isFloat ? image_module::SampleType::Half : image_module::SampleType::UInt8,
                channels == 4 ? 3 : -1, data.data());
}

void writeImageChannels(const std::string& path, int width, int height, const std::vector<std::string>& channels,
                        const std::vector<float>& interleaved, const std::vector<std::string>& attributes)
{
    if (width < 1 || height < 1 || channels.empty()) throw Error(path + ": refusing to write an empty image");
    if (lowerExtension(path) != ".exr") throw Error(path + ": named channels are written to OpenEXR files only (use .exr)");
    if (interleaved.size() != size_t(width) * size_t(height) * channels.size())
        throw Error(path + ": " + std::to_string(interleaved.size()) + " values for " + std::to_string(channels.size()) +
                    " channels of " + std::to_string(width) + "x" + std::to_string(height) + " pixels");
    if (attributes.size() % 2 != 0) throw Error(path + ": header attributes come as name, value pairs");
    writePixels(path, width, height, int(channels.size()), &channels, image_module::SampleType::Float, -1, interleaved.data(), &attributes);
}

struct RowImageWriter::Impl {
    explicit Impl(const std::string& path) : file(path, AtomicFile::Sync::No, "image") {}
    AtomicFile file;
    std::unique_ptr<image_module::Writer> out;
    int width = 0, height = 0, next = 0;
    bool isFloat = false, open = false;
    std::vector<float> clamped;
};

RowImageWriter::RowImageWriter(const std::string& path, int width, int height) : m(std::make_unique<Impl>(path))
{
    if (width < 1 || height < 1) throw Error(path + ": refusing to write an empty image");
    const std::string ext = lowerExtension(path);
    m->isFloat = ext == ".exr" || ext == ".hdr";
    m->width = width;
    m->height = height;
    std::string error;
    m->out = image_module::Writer::open(m->file.pathForWriter(), width, height, 3, nullptr,
                                        m->isFloat ? image_module::SampleType::Half : image_module::SampleType::UInt8, -1,
                                        m->isFloat ? image_module::ColorSpace::LinearRec709 : image_module::ColorSpace::Unnamed, error);
    if (!m->out) throw Error(path + ": " + error);
    m->open = true;
}

RowImageWriter::~RowImageWriter()
{
    if (m) m->out.reset();   // closes the file; the temporary file is removed by AtomicFile
}

void RowImageWriter::writeRows(const float* rgb, int rows)
{
    if (rows <= 0) return;
    if (m->next + rows > m->height)
        throw Error(m->file.target() + ": " + std::to_string(m->next + rows) + " rows written to a " + std::to_string(m->height) + "-row image");
    const float* data = rgb;
    if (!m->isFloat) {
        m->clamped.assign(rgb, rgb + size_t(m->width) * size_t(rows) * 3);
        for (float& v : m->clamped) v = std::clamp(v, 0.0f, 1.0f);
        data = m->clamped.data();
    }
    std::string error;
    if (!m->out->writeRows(m->next, m->next + rows, data, error)) throw Error(m->file.target() + ": cannot write image (" + error + ")");
    m->next += rows;
}

void RowImageWriter::finish()
{
    if (m->next != m->height)
        throw Error(m->file.target() + ": only " + std::to_string(m->next) + " of " + std::to_string(m->height) + " rows were written");
    m->open = false;
    std::string error;
    if (!m->out->close(error)) throw Error(m->file.target() + ": cannot write image (" + error + ")");
    m->file.commit();
}

} // namespace sylva
