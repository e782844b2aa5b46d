// A scene whose Cryptomatte mattes have an answer computed without the renderer's tracer, and a compositor's
// reading of a passes EXR: two upright square cards of two species (the near one a leaf, the far one half leaf,
// half bark, split along a diagonal) over the ground plane under the sky, seen by a pinhole camera; which card,
// triangle or ground a camera sample sees follows from ray-plane intersections in double. The EXR is read with
// OpenImageIO and each matte extracted as a compositor does: the coverage of the ranks whose ID is the name's.
#pragma once

#include <array>
#include <cmath>
#include <cstring>
#include <map>
#include <string>
#include <vector>

#include <QJsonDocument>
#include <QJsonObject>

#include <OpenImageIO/imageio.h>

#include "core/render/cryptomatte.h"
#include "core/render/render_scene.h"
#include "core/render/shade.h"
#include "tests/common/pinhole.h"

namespace sylva::test {

// The cards: centre (x, y, z), half side; both face the camera (normal -z), the near one (species "aspen",
// scene instance 0) in front of the left half of the far one (species "spruce", instance 1).
struct MatteCard {
    double x, y, z, half;
};
inline constexpr MatteCard kNearCard{-0.6, 1.2, 0.0, 0.8};
inline constexpr MatteCard kFarCard{0.5, 1.3, 1.5, 1.0};

// A unit square card in the x-y plane (normal -z), corners (-1,-1), (1,-1), (1,1), (-1,1); triangle 0 holds
// a >= b, triangle 1 a <= b. split: triangle 1 has a bark material.
inline TriangleMesh matteCardMesh(bool split)
{
    TriangleMesh m;
    for (auto [a, b] : {std::pair{-1.0f, -1.0f}, std::pair{1.0f, -1.0f}, std::pair{1.0f, 1.0f}, std::pair{-1.0f, 1.0f}}) {
        m.positions.push_back(glm::vec3(a, b, 0.0f));
        m.normals.push_back(glm::vec3(0.0f, 0.0f, -1.0f));
    }
    m.triangles = {{0, 1, 2}, {0, 2, 3}};
    m.triangleMaterial = {0, split ? 1u : 0u};
    m.materials.resize(split ? 2 : 1);
    m.materials[0].name = "leaves";
    m.materials[0].isLeaf = true;
    m.materials[0].diffuse = glm::vec3(0.2f, 0.6f, 0.3f);
    if (split) {
        m.materials[1].name = "wood";
        m.materials[1].isLeaf = false;
        m.materials[1].diffuse = glm::vec3(0.4f, 0.3f, 0.2f);
    }
    return m;
}

inline Scene matteScene(int spp, int width = 48, int height = 36)
{
    Scene sc;
    sc.species.resize(2);
    sc.species[0].name = "aspen";
    sc.species[1].name = "spruce";
    for (SpeciesDesc& s : sc.species) s.lit = false;
    for (uint32_t k = 0; k < 2; ++k) {
        const MatteCard& c = k == 0 ? kNearCard : kFarCard;
        InstanceDesc in;
        in.species = k;
        in.position = glm::dvec3(c.x, c.y, c.z);
        in.scale = float(c.half);
        sc.instances.push_back(in);
    }
    sc.ground.enabled = true;
    sc.ground.height = 0.0;
    sc.camera.position = glm::dvec3(0.0, 1.4, -4.0);
    sc.camera.target = glm::dvec3(0.0, 1.0, 0.0);
    sc.camera.fovY = 45.0f;
    sc.render.width = width;
    sc.render.height = height;
    sc.render.spp = spp;
    sc.render.mode = RenderMode::Local;
    return sc;
}

inline std::vector<SpeciesAssets> matteAssets()
{
    std::vector<SpeciesAssets> a(2);
    a[0].mesh = matteCardMesh(false);
    a[1].mesh = matteCardMesh(true);
    return a;
}

// What sample s of pixel (x, y) sees, from the renderer's sample position and the test's own pinhole ray:
// -1 the sky, 0 the ground, 1 the near card, 2 the far card's leaf triangle, 3 its bark triangle. *nearEdge:
// the ray passes within `margin` (card units) of a card's edge or the far card's diagonal, where float
// rounding may decide either way.
inline int matteTruth(const Scene& sc, int x, int y, int s, bool* nearEdge, double margin = 1e-4)
{
    const glm::vec2 pos = samplePosition(x, y, s, sc.render.spp);
    const glm::dvec3 d = pinholeDirection(sc, double(pos.x), double(pos.y));
    const glm::dvec3 o = sc.camera.position;
    double best = INFINITY;
    int what = -1;
    *nearEdge = false;
    if (d.y < 0.0) {
        best = (sc.ground.height - o.y) / d.y;
        what = 0;
    }
    for (int k = 0; k < 2; ++k) {
        const MatteCard& c = k == 0 ? kNearCard : kFarCard;
        const double t = (c.z - o.z) / d.z;
        if (!(t > 0.0)) continue;
        const glm::dvec3 p = o + t * d;
        const double a = (p.x - c.x) / c.half, b = (p.y - c.y) / c.half;
        if (std::abs(std::abs(a) - 1.0) < margin && std::abs(b) < 1.0 + margin) *nearEdge = true;
        if (std::abs(std::abs(b) - 1.0) < margin && std::abs(a) < 1.0 + margin) *nearEdge = true;
        if (std::abs(a) > 1.0 || std::abs(b) > 1.0 || t >= best) continue;
        if (k == 1 && std::abs(a - b) < margin) *nearEdge = true;
        best = t;
        what = k == 0 ? 1 : (a >= b ? 2 : 3);
    }
    return what;
}

// One Cryptomatte type of a passes EXR as a compositor reads it: the header's name, hash, conversion and
// manifest under its key, and per pixel its ranks' (ID, coverage) pairs.
struct ExrCryptomatte {
    std::string key, hash, conversion;
    std::map<std::string, std::string> manifest;   // name -> 8 hex digits
    int width = 0, height = 0, ranks = 0;
    std::vector<std::array<float, 2>> pairs;       // width * height * ranks
    std::string error;                             // set when the file lacks something

    // The matte of the IDs of `names` (looked up in the manifest): per pixel the summed coverage of the ranks
    // whose ID has those bits.
    std::vector<float> matte(const std::vector<std::string>& names) const
    {
        std::vector<uint32_t> wanted;
        for (const std::string& n : names)
            if (manifest.count(n)) wanted.push_back(uint32_t(std::stoul(manifest.at(n), nullptr, 16)));
        std::vector<float> out(size_t(width) * size_t(height), 0.0f);
        for (size_t p = 0; p < out.size(); ++p)
            for (int r = 0; r < ranks; ++r) {
                const std::array<float, 2>& pr = pairs[p * size_t(ranks) + size_t(r)];
                uint32_t bits;
                std::memcpy(&bits, &pr[0], 4);
                for (uint32_t w : wanted)
                    if (bits == w) out[p] += pr[1];
            }
        return out;
    }
};

inline ExrCryptomatte readCryptomatte(const std::string& path, const std::string& typeName)
{
    ExrCryptomatte out;
    auto in = OIIO::ImageInput::open(path);
    if (!in) {
        out.error = "cannot open " + path;
        return out;
    }
    const OIIO::ImageSpec spec = in->spec();
    out.width = spec.width;
    out.height = spec.height;
    // The type's key: the header attribute cryptomatte/<key>/name whose value is the type's name.
    for (const OIIO::ParamValue& p : spec.extra_attribs) {
        const std::string n = p.name().string();
        if (n.rfind("cryptomatte/", 0) == 0 && n.size() > 17 && n.substr(n.size() - 5) == "/name" && p.get_string() == typeName)
            out.key = n.substr(12, n.size() - 17);
    }
    if (out.key.empty()) {
        out.error = "no cryptomatte/<key>/name = " + typeName + " in the header";
        return out;
    }
    const std::string prefix = "cryptomatte/" + out.key + "/";
    out.hash = spec.get_string_attribute(prefix + "hash");
    out.conversion = spec.get_string_attribute(prefix + "conversion");
    const std::string manifest = spec.get_string_attribute(prefix + "manifest");
    const QJsonObject m = QJsonDocument::fromJson(QByteArray::fromStdString(manifest)).object();
    for (auto it = m.begin(); it != m.end(); ++it) out.manifest[it.key().toStdString()] = it.value().toString().toStdString();
    // The rank layers <type>00, <type>01, ... while all four channels are there.
    std::vector<int> channels;
    for (int layer = 0;; ++layer) {
        char digits[16];
        std::snprintf(digits, sizeof digits, "%02d", layer);
        std::vector<int> four;
        for (const char* c : {".R", ".G", ".B", ".A"}) four.push_back(spec.channelindex(typeName + digits + c));
        if (four[0] < 0 || four[1] < 0 || four[2] < 0 || four[3] < 0) break;
        channels.insert(channels.end(), four.begin(), four.end());
    }
    out.ranks = int(channels.size() / 2);
    std::vector<float> data(size_t(spec.width) * size_t(spec.height) * size_t(spec.nchannels));
    if (!in->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::FLOAT, data.data())) {
        out.error = "cannot read the pixels of " + path;
        return out;
    }
    const size_t n = size_t(spec.width) * size_t(spec.height);
    out.pairs.resize(n * size_t(out.ranks));
    for (size_t p = 0; p < n; ++p)
        for (int r = 0; r < out.ranks; ++r)
            out.pairs[p * size_t(out.ranks) + size_t(r)] = {data[p * size_t(spec.nchannels) + size_t(channels[size_t(2 * r)])],
                                                            data[p * size_t(spec.nchannels) + size_t(channels[size_t(2 * r + 1)])]};
    return out;
}

} // namespace sylva::test
