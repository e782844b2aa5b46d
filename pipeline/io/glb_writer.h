// Binary glTF 2.0 (.glb) in memory: a JSON document and one binary buffer, written as the GLB container
// (a 12-byte header, a JSON chunk padded with spaces and a BIN chunk padded with zeros, each to 4 bytes:
// glTF 2.0 specification, section 4.4). The glTF export (pipeline/services/gltf_export.h) fills it.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include <QByteArray>
#include <QJsonArray>
#include <QJsonObject>

#include "core/image/image.h"

namespace sylva {

// glTF's accessor component types and bufferView targets (the GL enums the specification names).
namespace gltf {
inline constexpr int kUnsignedInt = 5125, kFloat = 5126;
inline constexpr int kArrayBuffer = 34962, kElementArrayBuffer = 34963;
} // namespace gltf

class GlbBuilder {
public:
    // The document's top-level arrays; the builder adds buffers, bufferViews and accessors itself.
    QJsonObject json;

    // Appends `bytes` to the binary buffer at a 4-byte aligned offset (every accessor's component is 4 bytes,
    // so each accessor's offset and stride stay multiples of its component size) as a new bufferView;
    // target 0 = none (images, instance attributes). Returns the view's index.
    int addView(const void* data, size_t bytes, int target = 0);
    // An accessor of `count` elements of `type` ("SCALAR", "VEC2", "VEC3", "VEC4") over floats or uint32s
    // (componentType gltf::kFloat / kUnsignedInt) in a new bufferView; min/max written when `bounds`
    // (each component's minimum and maximum over the elements). Returns the accessor's index.
    int addFloats(const float* data, size_t count, const char* type, int target, bool bounds = false);
    int addIndices(const uint32_t* data, size_t count);
    // An image (PNG or JPEG bytes) in a bufferView; returns the image's index.
    int addImage(const QByteArray& bytes, const char* mimeType);

    // The GLB's bytes: header, JSON chunk, BIN chunk (left out when the buffer is empty). Throws Error above
    // the format's 4 GiB.
    QByteArray glb() const;
    size_t binaryBytes() const { return m_bin.size(); }

private:
    void append(const char* name, const QJsonValue& v);
    std::vector<uint8_t> m_bin;
};

// Components per element of an accessor type ("SCALAR" 1 .. "VEC4" 4, "MAT4" 16).
int gltfComponents(const char* type);

// The image as an 8-bit RGBA PNG (values as stored: a colour texture stays sRGB-encoded), compressed with
// zlib through Qt (qCompress); `alpha` false writes RGB.
QByteArray encodePng(const ImageRgba& image, bool alpha = true);

} // namespace sylva
