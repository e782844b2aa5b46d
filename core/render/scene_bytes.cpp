#include "core/render/scene_bytes.h"

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <memory>
#include <vector>

#include <tbb/parallel_for.h>

#include "core/base/error.h"
#include "core/base/version.h"
#include "core/render/render_cpu.h"

namespace sylva {

RenderSceneHeader renderSceneHeader(const RenderScene& rs)
{
    RenderSceneHeader h{};
    size_t i = 0;
#define SYLVA_X(part, where, T, name, stat) h.counts[i++] = rs.name.size();
    SYLVA_RENDER_ARRAYS(SYLVA_X)
#undef SYLVA_X
    h.frame = rs.frame;
    return h;
}

RenderSceneHeader hostTracedHeader(const RenderScene& rs)
{
    RenderSceneHeader h = renderSceneHeader(rs);
    if (!rs.blasWideNodes.empty()) h.counts[kArray_blasNodes] = 0;   // traceMesh walks the 8-wide copy
    if (rs.kdNodes.empty()) h.counts[kArray_tris] = 0;                // only the kd-tree path reads tris
    return h;
}

RenderScene allocateRenderScene(const RenderSceneHeader& h)
{
    RenderScene rs;
    size_t i = 0;
#define SYLVA_X(part, where, T, name, stat) rs.name.resize(size_t(h.counts[i++]));
    SYLVA_RENDER_ARRAYS(SYLVA_X)
#undef SYLVA_X
    rs.frame = h.frame;
    return rs;
}

PackedFrame packedFrameLayout(const RenderSceneHeader& h)
{
    PackedFrame L{};
    uint64_t at = 0;
    size_t i = 0;
#define SYLVA_X(part, where, T, name, stat)                                                                                                    \
    static_assert(alignof(T) <= 64, "an array's type is aligned beyond the packed frame's 64-byte boundaries");                                \
    L.offset[i] = at, at += (uint64_t(h.counts[i]) * sizeof(T) + 63u) & ~uint64_t(63u), ++i;
    SYLVA_RENDER_ARRAYS(SYLVA_X)
#undef SYLVA_X
    L.bytes = at;
    return L;
}

void packRenderScene(const RenderScene& rs, const RenderSceneHeader& h, const PackedFrame& layout, void* block)
{
    // Pieces of at most 4 MB, so that the threads share the large arrays (the copy is mostly the first touch
    // of the block's pages).
    struct Piece {
        const char* from;
        char* to;
        size_t bytes;
    };
    constexpr size_t kPiece = size_t(4) << 20;
    std::vector<Piece> pieces;
    size_t i = 0;
    forEachHeaderArray(rs, h, [&](const void* data, size_t bytes) {
        char* to = static_cast<char*>(block) + layout.offset[i++];
        for (size_t at = 0; at < bytes; at += kPiece)
            pieces.push_back({static_cast<const char*>(data) + at, to + at, std::min(kPiece, bytes - at)});
    });
    tbb::parallel_for(size_t(0), pieces.size(), [&](size_t k) { std::memcpy(pieces[k].to, pieces[k].from, pieces[k].bytes); });
}

RenderView packedFrameView(const RenderSceneHeader& h, const PackedFrame& layout, const void* block)
{
    RenderView v = h.frame;
    const char* b = static_cast<const char*>(block);
    size_t i = 0;
#define SYLVA_X(part, where, T, name, stat) v.name = h.counts[i] ? reinterpret_cast<const T*>(b + layout.offset[i]) : nullptr, ++i;
    SYLVA_RENDER_ARRAYS(SYLVA_X)
#undef SYLVA_X
    v.instanceCount = uint32_t(h.counts[kArray_instances]);
    v.volumes.count = uint32_t(h.counts[kArray_volumeInstances]);
    v.lightCount = uint32_t(h.counts[kArray_lights]);
    v.spheres.count = uint32_t(h.counts[kArray_sphereRecords]);
    return v;
}

namespace {

// This build's layout: the version, then the size of the header, of a film sample and of each array's element.
std::string layoutSignature()
{
    char part[64];
    std::snprintf(part, sizeof part, " header %zu sample %zu arrays", sizeof(RenderSceneHeader), sizeof(SampleParts));
    std::string s = "sylva frame ";
    s.append(versionString()).append(part);
#define SYLVA_X(part_, where, T, name, stat) std::snprintf(part, sizeof part, " %zu", sizeof(T)), s.append(part);
    SYLVA_RENDER_ARRAYS(SYLVA_X)
#undef SYLVA_X
    return s;
}

struct FilmHeader {
    int32_t width, height;
    float sky[3];
};

} // namespace

void writeRenderSceneFile(const std::string& path, const RenderScene& rs, const Film& film, const glm::vec3& sky)
{
    const std::string tmp = path + ".part";
    {
        std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
        if (!out) throw Error("cannot write " + tmp);
        const std::string sig = layoutSignature();
        const uint64_t sigBytes = sig.size();
        out.write(reinterpret_cast<const char*>(&sigBytes), sizeof sigBytes);
        out.write(sig.data(), std::streamsize(sig.size()));
        const RenderSceneHeader h = renderSceneHeader(rs);
        out.write(reinterpret_cast<const char*>(&h), sizeof h);
        forEachRenderSceneArray(rs, [&](const void* data, size_t bytes) { out.write(static_cast<const char*>(data), std::streamsize(bytes)); });
        const FilmHeader fh{film.width, film.height, {sky.x, sky.y, sky.z}};
        out.write(reinterpret_cast<const char*>(&fh), sizeof fh);
        out.write(reinterpret_cast<const char*>(film.pixels.data()), std::streamsize(film.pixels.size() * sizeof(SampleParts)));
        if (!out) throw Error("cannot write " + tmp + " (disk full?)");
    }
    if (std::rename(tmp.c_str(), path.c_str()) != 0) {
        std::remove(tmp.c_str());
        throw Error("cannot write " + path);
    }
}

void readRenderSceneFile(const std::string& path, RenderScene& scene, Film& film, glm::vec3& sky)
{
    std::ifstream in(path, std::ios::binary);
    if (!in) throw Error("cannot read " + path);
    auto readBytes = [&](void* data, size_t bytes) {
        in.read(static_cast<char*>(data), std::streamsize(bytes));
        if (!in || size_t(in.gcount()) != bytes) throw Error(path + ": the file ends early (not a whole frame)");
    };
    const std::string want = layoutSignature();
    uint64_t sigBytes = 0;
    readBytes(&sigBytes, sizeof sigBytes);
    if (sigBytes > 4096) throw Error(path + ": not a frame file");
    std::string sig(size_t(sigBytes), '\0');
    readBytes(sig.data(), sig.size());
    if (sig != want) throw Error(path + ": written by another build (\"" + sig + "\"; this one is \"" + want + "\")");
    RenderSceneHeader h{};
    readBytes(&h, sizeof h);
    scene = allocateRenderScene(h);
    forEachRenderSceneArray(scene, readBytes);
    FilmHeader fh{};
    readBytes(&fh, sizeof fh);
    if (fh.width <= 0 || fh.height <= 0 || fh.width > (1 << 16) || fh.height > (1 << 16)) throw Error(path + ": bad film size");
    film.width = fh.width;
    film.height = fh.height;
    film.pixels.resize(size_t(fh.width) * size_t(fh.height));
    readBytes(film.pixels.data(), film.pixels.size() * sizeof(SampleParts));
    sky = glm::vec3(fh.sky[0], fh.sky[1], fh.sky[2]);
}

} // namespace sylva
