// Image files through OpenImageIO.
#include "pipeline/io/image_io.h"

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imagebufalgo.h>
#include <OpenImageIO/imageio.h>

#include "core/base/error.h"
#include "pipeline/io/atomic_file.h"

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
    OIIO::ImageSpec config;
    config.attribute("oiio:UnassociatedAlpha", 1);
    auto in = OIIO::ImageInput::open(path, &config);
    if (!in) throw Error(path + ": cannot read image (" + OIIO::geterror() + ")");
    const OIIO::ImageSpec& spec = in->spec();
    const int w = spec.width, h = spec.height, nc = spec.nchannels;
    if (w <= 0 || h <= 0 || nc <= 0 || size_t(w) * size_t(h) > (size_t(1) << 28))
        throw Error(path + ": image has an unsupported size " + std::to_string(w) + "x" + std::to_string(h));
    std::vector<float> data(size_t(w) * size_t(h) * size_t(nc));
    if (!in->read_image(0, 0, 0, nc, OIIO::TypeDesc::FLOAT, data.data()))
        throw Error(path + ": cannot decode image (" + in->geterror() + ")");
    in->close();
    const int alphaChannel = spec.alpha_channel >= 0 ? spec.alpha_channel : (nc == 2 ? 1 : (nc >= 4 ? 3 : -1));
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
    auto in = OIIO::ImageInput::open(path);
    if (!in) throw Error(path + ": cannot read image (" + OIIO::geterror() + ")");
    const OIIO::ImageSpec& spec = in->spec();
    return spec.alpha_channel >= 0 || spec.nchannels == 2 || spec.nchannels >= 4;
}

namespace {

// The one whole-image writer: `spec`'s pixels from float `data`, through a temporary file beside the
// target (keeping the extension, so OIIO picks the same format), renamed at the end.
void writePixels(const std::string& path, const OIIO::ImageSpec& spec, const float* data)
{
    AtomicFile file(path, AtomicFile::Sync::No, "image");
    const std::string& temp = file.pathForWriter();
    auto out = OIIO::ImageOutput::create(temp);
    if (!out) throw Error(path + ": no image writer for this extension (" + OIIO::geterror() + ")");
    if (!out->open(temp, spec) || !out->write_image(OIIO::TypeDesc::FLOAT, data) || !out->close())
        throw Error(path + ": cannot write image (" + out->geterror() + ")");
    file.commit();
}

} // namespace

void writeImage(const std::string& path, const ImageRgba& image, int channels)
{
    if (image.empty()) throw Error(path + ": refusing to write an empty image");
    if (channels != 3 && channels != 4) throw Error(path + ": images are written with 3 or 4 channels");
    const std::string ext = lowerExtension(path);
    const bool isFloat = ext == ".exr" || ext == ".hdr";
    OIIO::ImageSpec spec(image.width, image.height, channels, isFloat ? OIIO::TypeDesc::HALF : OIIO::TypeDesc::UINT8);
    if (channels == 4) {
        spec.alpha_channel = 3;
        spec.attribute("oiio:UnassociatedAlpha", 1);   // the pixels are straight (unassociated) RGBA
    }
    std::vector<float> data(size_t(image.width) * size_t(image.height) * size_t(channels));
    for (size_t p = 0; p < size_t(image.width) * size_t(image.height); ++p)
        for (int c = 0; c < channels; ++c) {
            float v = image.pixels[p * 4 + size_t(c)];
            data[p * size_t(channels) + size_t(c)] = isFloat ? v : std::clamp(v, 0.0f, 1.0f);
        }
    writePixels(path, spec, data.data());
}

void writeImageChannels(const std::string& path, int width, int height, const std::vector<std::string>& channels,
                        const std::vector<float>& interleaved)
{
    if (width < 1 || height < 1 || channels.empty()) throw Error(path + ": refusing to write an empty image");
    if (lowerExtension(path) != ".exr") throw Error(path + ": named channels are written to OpenEXR files only (use .exr)");
    if (interleaved.size() != size_t(width) * size_t(height) * channels.size())
        throw Error(path + ": " + std::to_string(interleaved.size()) + " values for " + std::to_string(channels.size()) +
                    " channels of " + std::to_string(width) + "x" + std::to_string(height) + " pixels");
    OIIO::ImageSpec spec(width, height, int(channels.size()), OIIO::TypeDesc::FLOAT);
    spec.channelnames = channels;
    spec.alpha_channel = -1;
    spec.z_channel = -1;
    writePixels(path, spec, interleaved.data());
}

struct RowImageWriter::Impl {
    explicit Impl(const std::string& path) : file(path, AtomicFile::Sync::No, "image") {}
    AtomicFile file;
    std::unique_ptr<OIIO::ImageOutput> out;
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
    m->out = OIIO::ImageOutput::create(m->file.pathForWriter());
    if (!m->out) throw Error(path + ": no image writer for this extension (" + OIIO::geterror() + ")");
    OIIO::ImageSpec spec(width, height, 3, m->isFloat ? OIIO::TypeDesc::HALF : OIIO::TypeDesc::UINT8);
    if (!m->out->open(m->file.tempPath(), spec)) throw Error(path + ": cannot write image (" + m->out->geterror() + ")");
    m->open = true;
}

RowImageWriter::~RowImageWriter()
{
    if (m && m->out && m->open) m->out->close();   // the temporary file is removed by AtomicFile
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
    if (!m->out->write_scanlines(m->next, m->next + rows, 0, OIIO::TypeDesc::FLOAT, data))
        throw Error(m->file.target() + ": cannot write image (" + m->out->geterror() + ")");
    m->next += rows;
}

void RowImageWriter::finish()
{
    if (m->next != m->height)
        throw Error(m->file.target() + ": only " + std::to_string(m->next) + " of " + std::to_string(m->height) + " rows were written");
    m->open = false;
    if (!m->out->close()) throw Error(m->file.target() + ": cannot write image (" + m->out->geterror() + ")");
    m->file.commit();
}

} // namespace sylva
