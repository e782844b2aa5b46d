// Binned-SAH bounding volume hierarchy over boxes: host build, flat 64-byte nodes, stack traversal (host and device).
#pragma once

#include <cstdint>
#include <tuple>
#include <type_traits>
#include <utility>
#include <vector>

#include <glm/glm.hpp>

#include "core/accel/ray.h"
#include "core/base/defines.h"
#include "core/mesh/triangle_mesh.h"

namespace sylva {

// A 4-wide node: the boxes of up to four children as structure of arrays (one SIMD test for all
// four). Child k with count[k] == 0 is an inner node at index child[k]; count[k] > 0 is a leaf of
// primitives [child[k], child[k] + count[k]) in the BVH's primitive order; unused children have
// child[k] == kNoHit and count 0 (their boxes are not tested: an inverted box is still a slab hit).
// 128 bytes, 64-byte aligned.
struct alignas(64) BvhNode {
    float lox[4], hix[4], loy[4], hiy[4], loz[4], hiz[4];
    uint32_t child[4];
    uint32_t count[4];
};
static_assert(sizeof(BvhNode) == 128);

struct BvhBuildSettings {
    int maxLeafSize = 8;          // primitives per leaf at most
    float traversalCost = 1.0f;   // SAH cost of a node visit, relative to one primitive test
    int bins = 16;                // SAH bins per axis
};

// The host-side result: nodes (node 0 is the root's pair), the primitive order (primOrder[slot] =
// input primitive index) and the bounds of everything.
struct Bvh {
    std::vector<BvhNode> nodes;
    std::vector<uint32_t> primOrder;
    Bounds3 bounds;
    int depth = 0;                // deepest leaf, root children at depth 1
};

// Builds over primitive boxes (invalid boxes are allowed and end up in no leaf). Deterministic for
// any thread count. Uses oneTBB for large inputs.
Bvh buildBvh(const std::vector<Bounds3>& primBounds, const BvhBuildSettings& settings = {});

// Device-friendly view of a BVH's nodes.
struct BvhView {
    const BvhNode* nodes;
};

// Every visit pushes at most three children; build depth is capped below 64.
inline constexpr int kBvhStackSize = 192;

#if !defined(__CUDA_ARCH__)
namespace detail {
typedef float Float4 __attribute__((vector_size(16)));
typedef int Int4 __attribute__((vector_size(16)));
SYLVA_INLINE Float4 load4(const float* p)
{
    Float4 v;
    __builtin_memcpy(&v, p, 16);
    return v;
}
SYLVA_INLINE Float4 min4(Float4 a, Float4 b) { return a < b ? a : b; }
SYLVA_INLINE Float4 max4(Float4 a, Float4 b) { return a > b ? a : b; }
} // namespace detail
#endif

// Entry distances of the ray into the node's four child boxes; a lane is > tmax when missed.
SYLVA_HD SYLVA_INLINE void nodeEntry(const BvhNode& n, const glm::vec3& org, const glm::vec3& inv, unsigned zeroAxes,
                                     float tmin, float tmax, float tn[4])
{
#if !defined(__CUDA_ARCH__)
    using namespace detail;
    const Float4 ox = {org.x, org.x, org.x, org.x}, oy = {org.y, org.y, org.y, org.y}, oz = {org.z, org.z, org.z, org.z};
    const Float4 ix = {inv.x, inv.x, inv.x, inv.x}, iy = {inv.y, inv.y, inv.y, inv.y}, iz = {inv.z, inv.z, inv.z, inv.z};
    const Float4 x0 = (load4(n.lox) - ox) * ix, x1 = (load4(n.hix) - ox) * ix;
    const Float4 y0 = (load4(n.loy) - oy) * iy, y1 = (load4(n.hiy) - oy) * iy;
    const Float4 z0 = (load4(n.loz) - oz) * iz, z1 = (load4(n.hiz) - oz) * iz;
    const Float4 lo = {tmin, tmin, tmin, tmin}, hi = {tmax, tmax, tmax, tmax};
    Float4 tnear = max4(max4(min4(x0, x1), min4(y0, y1)), max4(min4(z0, z1), lo));
    Float4 tfar = min4(min4(max4(x0, x1), max4(y0, y1)), min4(max4(z0, z1), hi));
    if (__builtin_expect(zeroAxes != 0, 0)) {
        // Rays with a zero direction component (rare; the same branch for the whole traversal):
        // on such an axis the slab is all of t when the origin lies in [lo, hi], else empty.
        const Float4 big = {1e30f, 1e30f, 1e30f, 1e30f};
        const Float4 lox = load4(n.lox), hix = load4(n.hix), loy = load4(n.loy), hiy = load4(n.hiy);
        const Float4 loz = load4(n.loz), hiz = load4(n.hiz);
        auto fix = [&](const Float4& l, const Float4& h, const Float4& o) {
            const auto inside = (l <= o) & (o <= h);
            const Float4 t0 = inside ? -big : big, t1 = inside ? big : -big;
            return std::pair<Float4, Float4>(t0, t1);
        };
        Float4 ax0 = x0, ax1 = x1, ay0 = y0, ay1 = y1, az0 = z0, az1 = z1;
        if (zeroAxes & 1) std::tie(ax0, ax1) = fix(lox, hix, ox);
        if (zeroAxes & 2) std::tie(ay0, ay1) = fix(loy, hiy, oy);
        if (zeroAxes & 4) std::tie(az0, az1) = fix(loz, hiz, oz);
        tnear = max4(max4(min4(ax0, ax1), min4(ay0, ay1)), max4(min4(az0, az1), lo));
        tfar = min4(min4(max4(ax0, ax1), max4(ay0, ay1)), min4(max4(az0, az1), hi));
    }
    const Float4 miss = {missDistance(), missDistance(), missDistance(), missDistance()};
    const Float4 r = tnear <= tfar ? tnear : miss;
    __builtin_memcpy(tn, &r, 16);
#else
    (void)zeroAxes;
    for (int k = 0; k < 4; ++k)
        tn[k] = rayBoxEntry(glm::vec3(n.lox[k], n.loy[k], n.loz[k]), glm::vec3(n.hix[k], n.hiy[k], n.hiz[k]), org, inv,
                            tmin, tmax);
#endif
}

// Visits, in roughly front-to-back order, every leaf whose box the ray [tmin, tmax] enters. With a
// callback leaf(slot, tmax) it is called per primitive with the primitive's slot in BVH order; with
// leaf(first, count, tmax) once per leaf. The callback shrinks tmax when it records a closer hit and
// returns true to stop at once (any-hit queries). Returns true when stopped by the callback.
template <class LeafFn>
SYLVA_HD inline bool traverseBvh(BvhView bvh, const glm::vec3& org, const glm::vec3& dir, float tmin, float& tmax,
                                 LeafFn&& leaf)
{
    const glm::vec3 inv = safeReciprocal(dir);
    const unsigned zeroAxes = (dir.x == 0.0f ? 1u : 0u) | (dir.y == 0.0f ? 2u : 0u) | (dir.z == 0.0f ? 4u : 0u);
    uint32_t stackNode[kBvhStackSize];
    float stackDist[kBvhStackSize];
    int sp = 0;
    uint32_t node = 0;
    for (;;) {
        const BvhNode& n = bvh.nodes[node];
        float tn[4];
        nodeEntry(n, org, inv, zeroAxes, tmin, tmax, tn);
        // Leaves are handled at once (they may shrink tmax); inner children are sorted near to far.
        uint32_t innerNode[4];
        float innerDist[4];
        int inner = 0;
        for (int k = 0; k < 4; ++k) {
            if (!(tn[k] <= tmax) || n.child[k] == kNoHit) continue;
            if (n.count[k] > 0) {
                if constexpr (std::is_invocable_v<LeafFn, uint32_t, uint32_t, float&>) {
                    if (leaf(n.child[k], n.count[k], tmax)) return true;
                } else {
                    for (uint32_t p = 0; p < n.count[k]; ++p)
                        if (leaf(n.child[k] + p, tmax)) return true;
                }
            } else {
                int j = inner++;
                while (j > 0 && innerDist[j - 1] < tn[k]) {   // descending: the nearest ends last
                    innerDist[j] = innerDist[j - 1];
                    innerNode[j] = innerNode[j - 1];
                    --j;
                }
                innerDist[j] = tn[k];
                innerNode[j] = n.child[k];
#if !defined(__CUDA_ARCH__)
                // Start the fetch of the child's 128-byte node now: traversal is bound by memory latency.
                __builtin_prefetch(&bvh.nodes[n.child[k]]);
                __builtin_prefetch(reinterpret_cast<const char*>(&bvh.nodes[n.child[k]]) + 64);
#endif
            }
        }
        // Push the farther ones, continue with the nearest (re-checked against a shrunken tmax).
        for (int j = 0; j + 1 < inner; ++j) {
            if (!(innerDist[j] <= tmax)) continue;
            SYLVA_KERNEL_ASSERT(sp < kBvhStackSize);
            stackNode[sp] = innerNode[j];
            stackDist[sp] = innerDist[j];
            ++sp;
        }
        if (inner > 0 && innerDist[inner - 1] <= tmax) {
            node = innerNode[inner - 1];
            continue;
        }
        for (;;) {
            if (sp == 0) return false;
            --sp;
            if (stackDist[sp] <= tmax) break;
        }
        node = stackNode[sp];
    }
}

} // namespace sylva
