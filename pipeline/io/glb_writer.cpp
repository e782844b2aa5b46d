// The GLB container and PNG bytes (glb_writer.h).
#include "pipeline/io/glb_writer.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <limits>

#include <QJsonDocument>

#include "core/base/error.h"

namespace sylva {

namespace {

void putU32(QByteArray& out, uint32_t v)
{
    const char b[4] = {char(v & 0xff), char((v >> 8) & 0xff), char((v >> 16) & 0xff), char((v >> 24) & 0xff)};
    out.append(b, 4);
}

void putU32BigEndian(QByteArray& out, uint32_t v)
{
    const char b[4] = {char((v >> 24) & 0xff), char((v >> 16) & 0xff), char((v >> 8) & 0xff), char(v & 0xff)};
    out.append(b, 4);
}

uint32_t crc32(const char* data, size_t n, uint32_t crc = 0)
{
    static const std::array<uint32_t, 256> table = [] {
        std::array<uint32_t, 256> t{};
        for (uint32_t i = 0; i < 256; ++i) {
            uint32_t c = i;
            for (int k = 0; k < 8; ++k) c = (c & 1u) ? 0xedb88320u ^ (c >> 1) : c >> 1;
            t[i] = c;
        }
        return t;
    }();
    crc = ~crc;
    for (size_t i = 0; i < n; ++i) crc = table[(crc ^ uint8_t(data[i])) & 0xffu] ^ (crc >> 8);
    return ~crc;
}

void pngChunk(QByteArray& out, const char type[4], const QByteArray& data)
{
    putU32BigEndian(out, uint32_t(data.size()));
    QByteArray typed(type, 4);
    typed.append(data);
    out.append(typed);
    putU32BigEndian(out, crc32(typed.constData(), size_t(typed.size())));
}

} // namespace

int gltfComponents(const char* type)
{
    if (std::strcmp(type, "SCALAR") == 0) return 1;
    if (std::strcmp(type, "VEC2") == 0) return 2;
    if (std::strcmp(type, "VEC3") == 0) return 3;
    if (std::strcmp(type, "VEC4") == 0) return 4;
    if (std::strcmp(type, "MAT4") == 0) return 16;
    throw Error(std::string("glTF: unknown accessor type ") + type);
}

void GlbBuilder::append(const char* name, const QJsonValue& v)
{
    QJsonArray a = json.value(QLatin1String(name)).toArray();
    a.append(v);
    json.insert(QLatin1String(name), a);
}

int GlbBuilder::addView(const void* data, size_t bytes, int target)
{
    m_bin.resize((m_bin.size() + 3) / 4 * 4, 0);
    const size_t offset = m_bin.size();
    m_bin.resize(offset + bytes);
    if (bytes > 0) std::memcpy(m_bin.data() + offset, data, bytes);
    QJsonObject view{{"buffer", 0}, {"byteOffset", double(offset)}, {"byteLength", double(bytes)}};
    if (target != 0) view.insert("target", target);
    append("bufferViews", view);
    return int(json.value("bufferViews").toArray().size()) - 1;
}

int GlbBuilder::addFloats(const float* data, size_t count, const char* type, int target, bool bounds)
{
    const int n = gltfComponents(type);
    const int view = addView(data, count * size_t(n) * sizeof(float), target);
    QJsonObject acc{{"bufferView", view}, {"componentType", gltf::kFloat}, {"count", double(count)}, {"type", type}};
    if (bounds && count > 0) {
        std::vector<float> lo(size_t(n), std::numeric_limits<float>::max()), hi(size_t(n), -std::numeric_limits<float>::max());
        for (size_t e = 0; e < count; ++e)
            for (int c = 0; c < n; ++c) {
                lo[size_t(c)] = std::min(lo[size_t(c)], data[e * size_t(n) + size_t(c)]);
                hi[size_t(c)] = std::max(hi[size_t(c)], data[e * size_t(n) + size_t(c)]);
            }
        QJsonArray jl, jh;
        for (int c = 0; c < n; ++c) jl.append(double(lo[size_t(c)])), jh.append(double(hi[size_t(c)]));
        acc.insert("min", jl);
        acc.insert("max", jh);
    }
    append("accessors", acc);
    return int(json.value("accessors").toArray().size()) - 1;
}

int GlbBuilder::addIndices(const uint32_t* data, size_t count)
{
    const int view = addView(data, count * sizeof(uint32_t), gltf::kElementArrayBuffer);
    append("accessors", QJsonObject{{"bufferView", view}, {"componentType", gltf::kUnsignedInt}, {"count", double(count)}, {"type", "SCALAR"}});
    return int(json.value("accessors").toArray().size()) - 1;
}

int GlbBuilder::addImage(const QByteArray& bytes, const char* mimeType)
{
    const int view = addView(bytes.constData(), size_t(bytes.size()));
    append("images", QJsonObject{{"bufferView", view}, {"mimeType", mimeType}});
    return int(json.value("images").toArray().size()) - 1;
}

QByteArray GlbBuilder::glb() const
{
    QJsonObject doc = json;
    const size_t binBytes = (m_bin.size() + 3) / 4 * 4;
    if (!m_bin.empty()) doc.insert("buffers", QJsonArray{QJsonObject{{"byteLength", double(m_bin.size())}}});
    QByteArray text = QJsonDocument(doc).toJson(QJsonDocument::Compact);
    while (text.size() % 4 != 0) text.append(' ');
    const size_t total = 12 + 8 + size_t(text.size()) + (m_bin.empty() ? 0 : 8 + binBytes);
    if (total > size_t(std::numeric_limits<uint32_t>::max()))
        throw Error("glTF: the file would hold " + std::to_string(total) + " bytes; a .glb holds at most 4 GiB");
    QByteArray out;
    out.reserve(qsizetype(total));
    out.append("glTF", 4);
    putU32(out, 2);
    putU32(out, uint32_t(total));
    putU32(out, uint32_t(text.size()));
    out.append("JSON", 4);
    out.append(text);
    if (!m_bin.empty()) {
        putU32(out, uint32_t(binBytes));
        out.append("BIN\0", 4);
        out.append(reinterpret_cast<const char*>(m_bin.data()), qsizetype(m_bin.size()));
        out.append(QByteArray(qsizetype(binBytes - m_bin.size()), '\0'));
    }
    return out;
}

QByteArray encodePng(const ImageRgba& image, bool alpha)
{
    if (image.empty()) throw Error("PNG: empty image");
    const int channels = alpha ? 4 : 3;
    QByteArray raw;
    raw.reserve(qsizetype(image.height) * (1 + qsizetype(image.width) * channels));
    for (int y = 0; y < image.height; ++y) {
        raw.append('\0');   // filter: none
        for (int x = 0; x < image.width; ++x) {
            const float* p = image.at(x, y);
            for (int c = 0; c < channels; ++c) {
                const float v = std::isfinite(p[c]) ? std::clamp(p[c], 0.0f, 1.0f) : 0.0f;
                raw.append(char(uint8_t(std::lround(v * 255.0f))));
            }
        }
    }
    QByteArray out("\x89PNG\r\n\x1a\n", 8);
    QByteArray ihdr;
    putU32BigEndian(ihdr, uint32_t(image.width));
    putU32BigEndian(ihdr, uint32_t(image.height));
    ihdr.append(char(8));                   // bit depth
    ihdr.append(char(alpha ? 6 : 2));       // colour type: RGBA / RGB
    ihdr.append(3, '\0');                   // compression, filter, interlace
    pngChunk(out, "IHDR", ihdr);
    pngChunk(out, "IDAT", qCompress(raw, 9).mid(4));   // qCompress: a 4-byte length, then a zlib stream
    pngChunk(out, "IEND", QByteArray());
    return out;
}

} // namespace sylva
