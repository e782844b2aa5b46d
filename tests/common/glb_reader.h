// A binary glTF (.glb) reader written from the glTF 2.0 specification (sections 3.6 and 4.4) for the tests of the
// glTF export: the GLB header and chunks, the JSON through QJsonDocument, accessors through their bufferViews
// (checking alignment and bounds), EXT_mesh_gpu_instancing's instances. Independent of the writer
// (pipeline/io/glb_writer.h): it shares no code with it.
#pragma once

#include <QFile>
#include <QJsonArray>
#include <QJsonDocument>
#include <QJsonObject>
#include <QString>

#include <cmath>
#include <cstring>
#include <vector>

#include <glm/glm.hpp>
#include <glm/gtc/quaternion.hpp>

namespace sylva::test {

struct Glb {
    QString problem;        // empty when the container and the document are well formed
    QJsonObject json;
    QByteArray bin;
    quint32 jsonChunkLength = 0, binChunkLength = 0;
};

inline quint32 u32(const QByteArray& b, qsizetype at)
{
    quint32 v = 0;
    for (int i = 3; i >= 0; --i) v = (v << 8) | quint8(b[at + i]);
    return v;
}

inline Glb readGlb(const QString& path)
{
    Glb g;
    QFile f(path);
    if (!f.open(QIODevice::ReadOnly)) return g.problem = "cannot open " + path, g;
    const QByteArray b = f.readAll();
    if (b.size() < 20) return g.problem = "shorter than a header", g;
    if (b.left(4) != "glTF") return g.problem = "magic is not glTF", g;
    if (u32(b, 4) != 2) return g.problem = "version is not 2", g;
    if (u32(b, 8) != quint32(b.size())) return g.problem = QString("length %1, file %2 bytes").arg(u32(b, 8)).arg(b.size()), g;
    qsizetype at = 12;
    int chunk = 0;
    while (at < b.size()) {
        if (at + 8 > b.size()) return g.problem = "truncated chunk header", g;
        const quint32 length = u32(b, at), type = u32(b, at + 4);
        if (length % 4 != 0) return g.problem = QString("chunk %1's length %2 is not a multiple of 4").arg(chunk).arg(length), g;
        if (at + 8 + qsizetype(length) > b.size()) return g.problem = "chunk beyond the file", g;
        const QByteArray data = b.mid(at + 8, length);
        if (chunk == 0) {
            if (type != 0x4E4F534Au) return g.problem = "the first chunk is not JSON", g;
            QJsonParseError err;
            const QJsonDocument doc = QJsonDocument::fromJson(data, &err);
            if (err.error != QJsonParseError::NoError || !doc.isObject()) return g.problem = "JSON: " + err.errorString(), g;
            g.json = doc.object();
            g.jsonChunkLength = length;
        } else if (chunk == 1) {
            if (type != 0x004E4942u) return g.problem = "the second chunk is not BIN", g;
            g.bin = data;
            g.binChunkLength = length;
        }
        at += 8 + qsizetype(length);
        ++chunk;
    }
    return g;
}

inline int componentsOf(const QString& type)
{
    return type == "SCALAR" ? 1 : type == "VEC2" ? 2 : type == "VEC3" ? 3 : type == "VEC4" ? 4 : type == "MAT4" ? 16 : 0;
}

// An accessor's elements as doubles (float32 or uint32 components), checking its view: 4-byte alignment of
// offsets, the data inside the view and the view inside the buffer.
inline std::vector<double> readAccessor(const Glb& g, int index, int* components, QString* problem)
{
    const QJsonObject a = g.json["accessors"].toArray()[index].toObject();
    const QJsonObject v = g.json["bufferViews"].toArray()[a["bufferView"].toInt()].toObject();
    const int n = componentsOf(a["type"].toString());
    const int ct = a["componentType"].toInt();
    *components = n;
    if (n == 0 || (ct != 5126 && ct != 5125)) return *problem = "accessor type", std::vector<double>{};
    const qint64 count = qint64(a["count"].toDouble()), viewOffset = qint64(v["byteOffset"].toDouble()), viewLength = qint64(v["byteLength"].toDouble());
    const qint64 offset = viewOffset + qint64(a["byteOffset"].toDouble());
    const qint64 stride = v.contains("byteStride") ? qint64(v["byteStride"].toDouble()) : 4 * n;
    if (offset % 4 != 0) return *problem = QString("accessor %1 at offset %2: not 4-byte aligned").arg(index).arg(offset), std::vector<double>{};
    if (stride % 4 != 0) return *problem = "stride not aligned", std::vector<double>{};
    const qint64 need = count > 0 ? (count - 1) * stride + 4 * n : 0;
    if (qint64(a["byteOffset"].toDouble()) + need > viewLength) return *problem = QString("accessor %1 runs past its view").arg(index), std::vector<double>{};
    if (viewOffset + viewLength > qint64(g.json["buffers"].toArray()[0].toObject()["byteLength"].toDouble()))
        return *problem = "view past the buffer", std::vector<double>{};
    std::vector<double> out(size_t(count) * size_t(n));
    for (qint64 e = 0; e < count; ++e)
        for (int c = 0; c < n; ++c) {
            const char* p = g.bin.constData() + offset + e * stride + 4 * c;
            if (ct == 5126) {
                float f;
                std::memcpy(&f, p, 4);
                out[size_t(e * n + c)] = double(f);
            } else {
                quint32 u;
                std::memcpy(&u, p, 4);
                out[size_t(e * n + c)] = double(u);
            }
        }
    return out;
}

// One instance's world matrix from the file: T * R(q) * S (the extension's order: scale, rotate, translate).
struct FileInstance {
    glm::dvec3 t;
    glm::dquat q;
    glm::dvec3 s;
    glm::dvec3 apply(const glm::dvec3& x) const { return t + glm::mat3_cast(q) * (s * x); }
};

struct SpeciesNode {
    QString name;
    int mesh = -1;
    std::vector<FileInstance> instances;
};

inline std::vector<SpeciesNode> instancedNodes(const Glb& g, QString* problem)
{
    std::vector<SpeciesNode> out;
    for (const QJsonValue& nv : g.json["nodes"].toArray()) {
        const QJsonObject n = nv.toObject();
        const QJsonObject ext = n["extensions"].toObject()["EXT_mesh_gpu_instancing"].toObject();
        if (ext.isEmpty()) continue;
        const QJsonObject at = ext["attributes"].toObject();
        int c1 = 0, c2 = 0, c3 = 0;
        const std::vector<double> t = readAccessor(g, at["TRANSLATION"].toInt(), &c1, problem);
        const std::vector<double> r = readAccessor(g, at["ROTATION"].toInt(), &c2, problem);
        const std::vector<double> s = readAccessor(g, at["SCALE"].toInt(), &c3, problem);
        if (!problem->isEmpty()) return out;
        if (c1 != 3 || c2 != 4 || c3 != 3 || t.size() / 3 != r.size() / 4 || t.size() != s.size()) return *problem = "instance accessors differ", out;
        SpeciesNode sn{n["name"].toString(), n["mesh"].toInt(), {}};
        for (size_t i = 0; i < t.size() / 3; ++i) {
            FileInstance fi{{t[3 * i], t[3 * i + 1], t[3 * i + 2]}, glm::dquat(r[4 * i + 3], r[4 * i], r[4 * i + 1], r[4 * i + 2]),
                            {s[3 * i], s[3 * i + 1], s[3 * i + 2]}};
            if (std::abs(glm::length(fi.q) - 1.0) > 1e-6) return *problem = QString("%1: instance %2's quaternion is not unit").arg(sn.name).arg(i), out;
            sn.instances.push_back(fi);
        }
        out.push_back(sn);
    }
    return out;
}

// The container's and the document's own rules: every bufferView inside the buffer at a 4-aligned offset, the
// BIN chunk holding the buffer, POSITION accessors with min and max that bound their data.
inline QString structureProblems(const Glb& g)
{
    if (!g.problem.isEmpty()) return g.problem;
    const qint64 bufferLength = qint64(g.json["buffers"].toArray()[0].toObject()["byteLength"].toDouble());
    if (bufferLength > qint64(g.binChunkLength) || qint64(g.binChunkLength) - bufferLength > 3) return "buffer and BIN chunk lengths disagree";
    for (const QJsonValue& vv : g.json["bufferViews"].toArray()) {
        const QJsonObject v = vv.toObject();
        if (qint64(v["byteOffset"].toDouble()) % 4 != 0) return "a bufferView is not 4-byte aligned";
        if (!(v["byteLength"].toDouble() > 0)) return "a bufferView without bytes";
        if (qint64(v["byteOffset"].toDouble() + v["byteLength"].toDouble()) > bufferLength) return "a bufferView past the buffer";
    }
    for (const QJsonValue& mv : g.json["meshes"].toArray())
        for (const QJsonValue& pv : mv.toObject()["primitives"].toArray()) {
            const int pos = pv.toObject()["attributes"].toObject()["POSITION"].toInt(-1);
            if (pos < 0) return "a primitive without POSITION";
            const QJsonObject a = g.json["accessors"].toArray()[pos].toObject();
            if (!a.contains("min") || !a.contains("max")) return "POSITION without min / max";
            int n = 0;
            QString problem;
            const std::vector<double> p = readAccessor(g, pos, &n, &problem);
            if (!problem.isEmpty()) return problem;
            for (size_t e = 0; e < p.size() / 3; ++e)
                for (int c = 0; c < 3; ++c)
                    if (p[3 * e + size_t(c)] < a["min"].toArray()[c].toDouble() || p[3 * e + size_t(c)] > a["max"].toArray()[c].toDouble())
                        return "POSITION outside its min / max";
        }
    return {};
}

} // namespace sylva::test
