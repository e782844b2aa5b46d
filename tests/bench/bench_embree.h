// Embree 3 as a benchmark peer (bench_render, bench_landscape): its memory monitor, an alpha filter that asks
// trace.h's alphaOpaque, the scene's species meshes as Embree scenes (per species an opaque and an
// alpha-tested triangle geometry) and an instance's local -> world transform in Embree's layout. Include
// only where SYLVA_HAVE_EMBREE is defined.
#pragma once

#include <atomic>
#include <memory>
#include <stdexcept>
#include <vector>

#include <embree3/rtcore.h>

#include "core/render/render_scene.h"
#include "core/render/trace.h"

namespace sylva::bench {

// Bytes Embree holds, summed through its memory monitor.
inline std::atomic<long long> g_embreeBytes{0};

inline bool embreeMemoryMonitor(void*, ssize_t bytes, bool)
{
    g_embreeBytes.fetch_add(bytes, std::memory_order_relaxed);
    return true;
}

inline void embreeError(void*, RTCError code, const char* message)
{
    std::fprintf(stderr, "embree error %d: %s\n", int(code), message ? message : "");
}

// User data of one Embree triangle geometry: its primID -> slot in RenderView::tris.
struct EmbreeGeomData {
    const RenderView* view;
    std::vector<uint32_t> slots;
};

// Intersection and occlusion filter of the alpha-tested geometries: trace.h's alphaOpaque on the hit's uv.
inline void embreeAlphaFilter(const RTCFilterFunctionNArguments* args)
{
    const EmbreeGeomData& g = *static_cast<const EmbreeGeomData*>(args->geometryUserPtr);
    const RenderView& v = *g.view;
    for (unsigned i = 0; i < args->N; ++i) {
        if (args->valid[i] != -1) continue;
        const TriAccel& tri = v.tris[g.slots[RTCHitN_primID(args->hit, args->N, i)]];
        const glm::vec2 uv = triangleUv(v, tri.tri, RTCHitN_u(args->hit, args->N, i), RTCHitN_v(args->hit, args->N, i));
        if (!alphaOpaque(v, tri.alpha - 1u, uv)) args->valid[i] = 0;
    }
}

// Every mesh geometry of `rs` as an Embree scene (index = GeometryRecord index; non-meshes get none and throw
// when `meshesOnly`): an opaque and an alpha-tested triangle geometry of unshared vertices v0, v0 + e1, v0 + e2
// from the TriAccels. `data` keeps the filters' user data alive.
inline std::vector<RTCScene> embreeSpeciesScenes(RTCDevice device, const RenderScene& rs, const RenderView& v, RTCBuildQuality quality,
                                                 std::vector<std::unique_ptr<EmbreeGeomData>>& data, bool meshesOnly = true)
{
    std::vector<RTCScene> scenes;
    for (const GeometryRecord& g : rs.geometries) {
        if (g.kind != GeometryKind::Mesh) {
            if (meshesOnly) throw std::runtime_error("the Embree peer takes meshes only");
            scenes.push_back(nullptr);
            continue;
        }
        const uint32_t first = g.triOffset, last = g.triOffset + g.primCount;
        RTCScene scene = rtcNewScene(device);
        rtcSetSceneFlags(scene, RTC_SCENE_FLAG_NONE);
        rtcSetSceneBuildQuality(scene, quality);
        for (int alpha = 0; alpha < 2; ++alpha) {
            auto d = std::make_unique<EmbreeGeomData>();
            d->view = &v;
            for (uint32_t slot = first; slot < last; ++slot)
                if ((rs.tris[slot].alpha != 0u) == (alpha == 1)) d->slots.push_back(slot);
            if (d->slots.empty()) continue;
            const size_t n = d->slots.size();
            RTCGeometry geom = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
            rtcSetGeometryBuildQuality(geom, quality);
            auto* vb = static_cast<float*>(rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float), 3 * n));
            auto* ib = static_cast<uint32_t*>(rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(uint32_t), n));
            for (size_t k = 0; k < n; ++k) {
                const TriAccel& t = rs.tris[d->slots[k]];
                const glm::vec3 p[3] = {t.v0, t.v0 + t.e1, t.v0 + t.e2};
                for (int c = 0; c < 3; ++c) {
                    vb[(3 * k + size_t(c)) * 3 + 0] = p[c].x;
                    vb[(3 * k + size_t(c)) * 3 + 1] = p[c].y;
                    vb[(3 * k + size_t(c)) * 3 + 2] = p[c].z;
                    ib[3 * k + size_t(c)] = uint32_t(3 * k + size_t(c));
                }
            }
            rtcSetGeometryUserData(geom, d.get());
            if (alpha) {
                rtcSetGeometryIntersectFilterFunction(geom, embreeAlphaFilter);
                rtcSetGeometryOccludedFilterFunction(geom, embreeAlphaFilter);
            }
            rtcCommitGeometry(geom);
            rtcAttachGeometryByID(scene, geom, unsigned(alpha));
            rtcReleaseGeometry(geom);
            data.push_back(std::move(d));
        }
        rtcCommitScene(scene);
        scenes.push_back(scene);
    }
    return scenes;
}

// An instance's local -> world map in RTC_FORMAT_FLOAT3X4_COLUMN_MAJOR (three linear columns, then the
// translation): the inverse of the InstanceRecord's world -> local rows (local = A world + b, world =
// A^-1 (local - b)), computed in double.
inline void embreeInstanceTransform(const InstanceRecord& in, float xfm[12])
{
    glm::dmat3 a;   // column-major: a[col][row]
    glm::dvec3 b;
    for (int r = 0; r < 3; ++r) {
        for (int c = 0; c < 3; ++c) a[c][r] = double(in.row[r][c]);
        b[r] = double(in.row[r].w);
    }
    const glm::dmat3 ai = glm::inverse(a);
    const glm::dvec3 ti = -(ai * b);
    for (int c = 0; c < 3; ++c)
        for (int r = 0; r < 3; ++r) xfm[c * 3 + r] = float(ai[c][r]);
    for (int r = 0; r < 3; ++r) xfm[9 + r] = float(ti[r]);
}

} // namespace sylva::bench
