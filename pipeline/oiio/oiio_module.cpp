// libsylva_oiio.so: the program's only use of OpenImageIO, loaded by pipeline/io/image_module.cpp when an
// image file is first read or written. It links OpenImageIO and nothing of Sylva's; no exception leaves it.
#include <memory>
#include <string>

#include <OpenImageIO/imageio.h>

#include "pipeline/io/image_module.h"

namespace {

using sylva::image_module::ColorSpace;
using sylva::image_module::Info;
using sylva::image_module::SampleType;
using sylva::image_module::Table;

SampleType sampleType(const OIIO::TypeDesc& t)
{
    switch (t.basetype) {
    case OIIO::TypeDesc::UINT8: return SampleType::UInt8;
    case OIIO::TypeDesc::UINT16: return SampleType::UInt16;
    case OIIO::TypeDesc::INT16: return SampleType::Int16;
    case OIIO::TypeDesc::UINT32: return SampleType::UInt32;
    case OIIO::TypeDesc::INT32: return SampleType::Int32;
    case OIIO::TypeDesc::HALF: return SampleType::Half;
    case OIIO::TypeDesc::FLOAT: return SampleType::Float;
    default: return SampleType::Other;
    }
}

OIIO::TypeDesc typeDesc(SampleType t)
{
    switch (t) {
    case SampleType::UInt8: return OIIO::TypeDesc::UINT8;
    case SampleType::UInt16: return OIIO::TypeDesc::UINT16;
    case SampleType::Int16: return OIIO::TypeDesc::INT16;
    case SampleType::UInt32: return OIIO::TypeDesc::UINT32;
    case SampleType::Int32: return OIIO::TypeDesc::INT32;
    case SampleType::Half: return OIIO::TypeDesc::HALF;
    default: return OIIO::TypeDesc::FLOAT;
    }
}

void* openRead(const char* path, int unassociatedAlpha, Info* info, std::string* error)
{
    try {
        // Unassociated: colour and alpha as stored, as textures are authored (OIIO would otherwise premultiply).
        OIIO::ImageSpec config;
        if (unassociatedAlpha) config.attribute("oiio:UnassociatedAlpha", 1);
        auto in = OIIO::ImageInput::open(path, unassociatedAlpha ? &config : nullptr);
        if (!in) {
            *error = OIIO::geterror();
            return nullptr;
        }
        const OIIO::ImageSpec& spec = in->spec();
        info->width = spec.width;
        info->height = spec.height;
        info->channels = spec.nchannels;
        info->alphaChannel = spec.alpha_channel;
        info->type = sampleType(spec.format);
        info->channelNames.assign(spec.channelnames.begin(), spec.channelnames.end());
        return in.release();
    } catch (const std::exception& e) {
        *error = e.what();
        return nullptr;
    }
}

int readFloat(void* input, int channels, float* out, std::string* error)
{
    auto* in = static_cast<OIIO::ImageInput*>(input);
    try {
        if (!in->read_image(0, 0, 0, channels, OIIO::TypeDesc::FLOAT, out)) {
            *error = in->geterror();
            return 0;
        }
        return 1;
    } catch (const std::exception& e) {
        *error = e.what();
        return 0;
    }
}

void closeRead(void* input)
{
    std::unique_ptr<OIIO::ImageInput> in(static_cast<OIIO::ImageInput*>(input));
    in->close();
}

void* openWrite(const char* path, int width, int height, int channels, const std::string* names, SampleType stored, int alphaChannel,
                ColorSpace colorSpace, const std::string* attributes, int attributeCount, std::string* error)
{
    try {
        auto out = OIIO::ImageOutput::create(path);
        if (!out) {
            *error = "no image writer for this extension (" + OIIO::geterror() + ")";
            return nullptr;
        }
        OIIO::ImageSpec spec(width, height, channels, typeDesc(stored));
        if (names) {
            spec.channelnames.assign(names, names + channels);
            spec.alpha_channel = -1;
            spec.z_channel = -1;
        }
        if (alphaChannel >= 0) {
            spec.alpha_channel = alphaChannel;
            spec.attribute("oiio:UnassociatedAlpha", 1);   // the pixels are straight (unassociated) RGBA
        }
        if (colorSpace == ColorSpace::LinearRec709) {
            // OpenEXR's standard attribute: the Rec.709 primaries and the D65 white, CIE xy; the colour interop ID
            // of scene-linear Rec.709; and OpenImageIO's own name for readers that keep it.
            static const float kRec709[8] = {0.64f, 0.33f, 0.30f, 0.60f, 0.15f, 0.06f, 0.3127f, 0.3290f};
            spec.attribute("chromaticities", OIIO::TypeDesc(OIIO::TypeDesc::FLOAT, 8), kRec709);
            spec.attribute("colorInteropID", "lin_rec709_scene");
            spec.attribute("oiio:ColorSpace", "lin_rec709");
        }
        for (int i = 0; i < attributeCount; ++i) spec.attribute(attributes[2 * i], OIIO::string_view(attributes[2 * i + 1]));
        if (!out->open(path, spec)) {
            *error = "cannot write image (" + out->geterror() + ")";
            return nullptr;
        }
        return out.release();
    } catch (const std::exception& e) {
        *error = e.what();
        return nullptr;
    }
}

int writeImage(void* output, const float* data, std::string* error)
{
    auto* out = static_cast<OIIO::ImageOutput*>(output);
    try {
        if (!out->write_image(OIIO::TypeDesc::FLOAT, data)) {
            *error = out->geterror();
            return 0;
        }
        return 1;
    } catch (const std::exception& e) {
        *error = e.what();
        return 0;
    }
}

int writeRows(void* output, int y0, int y1, const float* data, std::string* error)
{
    auto* out = static_cast<OIIO::ImageOutput*>(output);
    try {
        if (!out->write_scanlines(y0, y1, 0, OIIO::TypeDesc::FLOAT, data)) {
            *error = out->geterror();
            return 0;
        }
        return 1;
    } catch (const std::exception& e) {
        *error = e.what();
        return 0;
    }
}

int closeWrite(void* output, std::string* error)
{
    std::unique_ptr<OIIO::ImageOutput> out(static_cast<OIIO::ImageOutput*>(output));
    try {
        if (!out->close()) {
            *error = out->geterror();
            return 0;
        }
        return 1;
    } catch (const std::exception& e) {
        *error = e.what();
        return 0;
    }
}

const Table kTable{sylva::image_module::kAbi, openRead, readFloat, closeRead, openWrite, writeImage, writeRows, closeWrite};

} // namespace

extern "C" __attribute__((visibility("default"))) const Table* sylvaImageModule() { return &kTable; }
