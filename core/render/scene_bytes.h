// A built frame (RenderScene: its flat arrays and view settings) as bytes for another process: the MPI ranks
// receive rank 0's frame this way (pipeline/mpi/mpi_render.cpp), and a frame written to a file is traced again
// elsewhere (tests/gpu/gpu_replay.cpp: the GPU checks on a machine that has a device but none of the pipeline's
// libraries). The header holds every array's element count and the view's settings (RenderView as bytes: its
// pointers mean nothing in another process; RenderScene::view() sets them); the arrays follow in
// SYLVA_RENDER_ARRAYS order. Only what tracing needs travels (not meshLevels or the other build-side members).
#pragma once

#include <algorithm>
#include <cstdint>
#include <string>
#include <type_traits>

#include "core/render/render_scene.h"

namespace sylva {

#define SYLVA_X(part, where, T, name, stat) +1
inline constexpr size_t kRenderSceneArrays = 0 SYLVA_RENDER_ARRAYS(SYLVA_X);
#undef SYLVA_X
// Each array's index in SYLVA_RENDER_ARRAYS order: kArray_instances, kArray_tris, ...
enum RenderSceneArrayIndex : size_t {
#define SYLVA_X(part, where, T, name, stat) kArray_##name,
    SYLVA_RENDER_ARRAYS(SYLVA_X)
#undef SYLVA_X
};
static_assert(std::is_trivially_copyable_v<RenderView>, "the view's settings travel as bytes");

struct RenderSceneHeader {
    uint64_t counts[kRenderSceneArrays];
    RenderView frame;
};

RenderSceneHeader renderSceneHeader(const RenderScene& rs);

// renderSceneHeader less what the host's (CPU) traversal of this frame never reads: the meshes' 4-wide BVH
// nodes when their 8-wide copy is there, and the triangles in BVH slot order outside kd-tree runs (the BVH
// reads its triangle blocks). 84 of the default forest's 287 MB. The frame the other MPI ranks trace.
RenderSceneHeader hostTracedHeader(const RenderScene& rs);

// A scene with the header's arrays sized (value-initialized) and its view settings, ready to receive the arrays.
RenderScene allocateRenderScene(const RenderSceneHeader& h);

// fn(data, bytes) for each array in SYLVA_RENDER_ARRAYS order (rs's own storage: read it to send, write it to
// receive); data is const void* for a const scene, void* otherwise.
template <class Scene, class Fn>
void forEachRenderSceneArray(Scene& rs, Fn&& fn)
{
#define SYLVA_X(part, where, T, name, stat) fn(static_cast<std::conditional_t<std::is_const_v<Scene>, const void*, void*>>(rs.name.data()), rs.name.size() * sizeof(T));
    SYLVA_RENDER_ARRAYS(SYLVA_X)
#undef SYLVA_X
}

// ---- one frame shared by the processes of a host (sylva render --mpi) ----
// The arrays packed one after another into one block, each at a 64-byte boundary, so that the ranks on one
// host map a single copy of the frame (an MPI shared-memory window) instead of holding one each. The block
// itself must start at a 64-byte boundary (types such as TilePlant are over-aligned).
struct PackedFrame {
    uint64_t offset[kRenderSceneArrays];   // of each array in SYLVA_RENDER_ARRAYS order
    uint64_t bytes;                        // the whole block
};
PackedFrame packedFrameLayout(const RenderSceneHeader& h);

// fn(data, bytes) for each array of rs in SYLVA_RENDER_ARRAYS order, as far as h counts its elements (h: rs's
// renderSceneHeader or hostTracedHeader).
template <class Fn>
void forEachHeaderArray(const RenderScene& rs, const RenderSceneHeader& h, Fn&& fn)
{
    size_t i = 0;
#define SYLVA_X(part, where, T, name, stat) fn(static_cast<const void*>(rs.name.data()), size_t(std::min<uint64_t>(h.counts[i], rs.name.size())) * sizeof(T)), ++i;
    SYLVA_RENDER_ARRAYS(SYLVA_X)
#undef SYLVA_X
}

// rs's arrays, as far as h counts them, copied to their places in `block` (layout.bytes bytes; layout from h),
// in parallel.
void packRenderScene(const RenderScene& rs, const RenderSceneHeader& h, const PackedFrame& layout, void* block);

// fn(data, bytes) for each array's place in a packed block, in SYLVA_RENDER_ARRAYS order (as
// forEachRenderSceneArray walks a scene: the same pieces, to receive them there).
template <class Fn>
void forEachPackedArray(const RenderSceneHeader& h, const PackedFrame& layout, void* block, Fn&& fn)
{
    size_t i = 0;
#define SYLVA_X(part, where, T, name, stat) fn(static_cast<void*>(static_cast<char*>(block) + layout.offset[i]), size_t(h.counts[i]) * sizeof(T)), ++i;
    SYLVA_RENDER_ARRAYS(SYLVA_X)
#undef SYLVA_X
}

// The view of a packed block: what RenderScene::view() gives for the scene it was packed from.
RenderView packedFrameView(const RenderSceneHeader& h, const PackedFrame& layout, const void* block);

// A frame and its traced film to a file, and back. The file starts with a signature of this build's layout
// (the program version, every array's element size and the header's size): readRenderSceneFile refuses a file
// another layout wrote (sylva::Error naming both), as it does a short or unreadable one.
struct Film;
void writeRenderSceneFile(const std::string& path, const RenderScene& rs, const Film& film, const glm::vec3& sky);
void readRenderSceneFile(const std::string& path, RenderScene& scene, Film& film, glm::vec3& sky);

} // namespace sylva
