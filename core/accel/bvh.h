// Binned-SAH bounding volume hierarchy over boxes: host build, flat 4-wide (every backend) and 8-wide (host) nodes, stack traversal.
#pragma once

#include <cstdint>
#include <tuple>
#include <type_traits>
#include <utility>
#include <vector>

#include <glm/glm.hpp>

#include "core/accel/ray.h"
#include "core/base/defines.h"
#include "core/base/traversal_stats.h"
#include "core/mesh/triangle_mesh.h"

namespace sylva {

// A W-wide node: the boxes of up to W children as structure of arrays (one SIMD test for all of
// them). Child k with count[k] == 0 is an inner node at index child[k]; count[k] > 0 is a leaf of
// primitives [child[k], child[k] + count[k]) in the BVH's primitive order; unused children have
// child[k] == kNoHit and count 0 (their boxes are not tested: an inverted box is still a slab hit).
// 64-byte aligned. BvhNode (4-wide, 128 bytes) is the structure every backend traverses; BvhNode8
// (8-wide, 256 bytes) is a second flattening of the same build for the host's 8-wide SIMD: half the
// levels, so half the dependent node loads a ray waits for.
template <int W>
struct alignas(64) BvhNodeW {
    float lox[W], hix[W], loy[W], hiy[W], loz[W], hiz[W];
    uint32_t child[W];
    uint32_t count[W];
};
using BvhNode = BvhNodeW<4>;
using BvhNode8 = BvhNodeW<8>;
static_assert(sizeof(BvhNode) == 128);
static_assert(sizeof(BvhNode8) == 256);

struct BvhBuildSettings {
    int maxLeafSize = 8;          // primitives per leaf at most
    float traversalCost = 1.0f;   // SAH cost of a node visit, relative to one primitive test
    int leafBlock = 1;            // primitives tested together (SIMD leaf blocks): leaves cost per started block
    int bins = 16;                // SAH bins per axis
    bool wide = false;            // also flatten the build 8-wide (Bvh::wideNodes)
};

// The host-side result: nodes (node 0 is the root's pair), the primitive order (primOrder[slot] =
// input primitive index) and the bounds of everything.
struct Bvh {
    std::vector<BvhNode> nodes;
    std::vector<uint32_t> primOrder;
    Bounds3 bounds;
    int depth = 0;                // deepest leaf, root children at depth 1
    std::vector<BvhNode8> wideNodes;   // with BvhBuildSettings::wide: the same leaves under 8-wide nodes
    int wideDepth = 0;
};

// Builds over primitive boxes (invalid boxes are allowed and end up in no leaf). Deterministic for
// any thread count. Uses oneTBB for large inputs.
Bvh buildBvh(const std::vector<Bounds3>& primBounds, const BvhBuildSettings& settings = {});

// Device-friendly view of a BVH's nodes (BvhView: 4-wide, BvhView8: 8-wide, host only).
// Optionally, where leaf records live (leaf child c at leafData + c * leafBytes) so that the traversal
// can prefetch them: the host fetches the first 192 bytes of every leaf of a node before testing the
// nearest.
template <class Node>
struct BvhViewT {
    const Node* nodes;
    const char* leafData = nullptr;
    uint32_t leafBytes = 0;
};
using BvhView = BvhViewT<BvhNode>;
using BvhView8 = BvhViewT<BvhNode8>;

// Optional traversal counters (g_bvhNodeVisits, g_bvhLeafVisits): core/base/traversal_stats.h.

// Every visit pushes at most W - 1 children; build depth is capped below 64.
template <int W>
inline constexpr int kBvhStackSizeW = (W - 1) * 64;
inline constexpr int kBvhStackSize = kBvhStackSizeW<4>;

#if !defined(__CUDA_ARCH__)
namespace detail {
// W floats as one GCC vector (SSE for 4, AVX for 8 where the target has it).
template <int W>
struct FloatVec {
    typedef float type __attribute__((vector_size(4 * W)));
};
typedef FloatVec<4>::type Float4;
template <class V>
SYLVA_INLINE V loadVec(const float* p)
{
    V v;
    __builtin_memcpy(&v, p, sizeof(V));
    return v;
}
template <class V>
SYLVA_INLINE V minVec(V a, V b)
{
    return a < b ? a : b;
}
template <class V>
SYLVA_INLINE V maxVec(V a, V b)
{
    return a > b ? a : b;
}
SYLVA_INLINE Float4 load4(const float* p) { return loadVec<Float4>(p); }

// One axis of the slab test for nodeEntry's rare path (a zero direction component on some axis): on a
// zero axis the slab is all of t when the origin lies in [lo, hi] (a ray in a box face enters it), else
// empty; unused (inverted) children are never entered. A function, not a lambda, so that it is always
// inlined: as a lambda GCC began calling it out of line once the traversal grew its levels.
template <class V>
SYLVA_INLINE void slabAxis(const float* l, const float* h, const V& o, const V& i, bool zeroAxis, V& t0, V& t1)
{
    const V zero = {};
    const V big = zero + 1e30f;
    const V L = loadVec<V>(l), H = loadVec<V>(h);
    if (zeroAxis) {
        const auto inside = (L <= o) & (o <= H);
        t0 = inside ? -big : big;
        t1 = inside ? big : -big;
    } else {
        const V a = (L - o) * i, b = (H - o) * i;
        t0 = minVec(a, b);
        t1 = maxVec(a, b);
        const auto inverted = L > H;   // unused child
        t0 = inverted ? big : t0;
        t1 = inverted ? -big : t1;
    }
}
} // namespace detail
#endif

// Entry distances of the ray into the node's W child boxes and the mask of children entered
// within [tmin, tmax] (bit k = child k; unused children are never entered). One SIMD slab test on
// the host, a loop on the device.
template <int W>
SYLVA_HD SYLVA_INLINE unsigned nodeEntry(const BvhNodeW<W>& n, const glm::vec3& org, const glm::vec3& inv, unsigned zeroAxes,
                                         float tmin, float tmax, float tn[W])
{
#if !defined(__CUDA_ARCH__)
    using namespace detail;
    using V = typename FloatVec<W>::type;
    const V zero = {};
    const V ox = zero + org.x, oy = zero + org.y, oz = zero + org.z;
    const V ix = zero + inv.x, iy = zero + inv.y, iz = zero + inv.z;
    const V lo = zero + tmin, hi = zero + tmax;
    V tnear, tfar;
    if (__builtin_expect(zeroAxes == 0, 1)) {
        // Near and far planes chosen by the direction's signs: no min/max per axis, and an inverted
        // (unused) box gives near > far on every axis, so it is never entered.
        const V nx = (loadVec<V>(inv.x >= 0.0f ? n.lox : n.hix) - ox) * ix, fx = (loadVec<V>(inv.x >= 0.0f ? n.hix : n.lox) - ox) * ix;
        const V ny = (loadVec<V>(inv.y >= 0.0f ? n.loy : n.hiy) - oy) * iy, fy = (loadVec<V>(inv.y >= 0.0f ? n.hiy : n.loy) - oy) * iy;
        const V nz = (loadVec<V>(inv.z >= 0.0f ? n.loz : n.hiz) - oz) * iz, fz = (loadVec<V>(inv.z >= 0.0f ? n.hiz : n.loz) - oz) * iz;
        tnear = maxVec(maxVec(nx, ny), maxVec(nz, lo));
        tfar = minVec(minVec(fx, fy), minVec(fz, hi));
    } else {
        // A zero direction component (rare; the same branch for the whole traversal).
        V x0, x1, y0, y1, z0, z1;
        slabAxis(n.lox, n.hix, ox, ix, zeroAxes & 1u, x0, x1);
        slabAxis(n.loy, n.hiy, oy, iy, zeroAxes & 2u, y0, y1);
        slabAxis(n.loz, n.hiz, oz, iz, zeroAxes & 4u, z0, z1);
        tnear = maxVec(maxVec(x0, y0), maxVec(z0, lo));
        tfar = minVec(minVec(x1, y1), minVec(z1, hi));
    }
    const auto entered = tnear <= tfar;
    __builtin_memcpy(tn, &tnear, sizeof(V));
    unsigned mask = 0;
    for (int k = 0; k < W; ++k) mask |= entered[k] ? 1u << k : 0u;
    return mask;
#else
    (void)zeroAxes;
    unsigned mask = 0;
    for (int k = 0; k < W; ++k) {
        tn[k] = rayBoxEntry(glm::vec3(n.lox[k], n.loy[k], n.loz[k]), glm::vec3(n.hix[k], n.hiy[k], n.hiz[k]), org, inv,
                            tmin, tmax);
        if (tn[k] <= tmax && n.child[k] != kNoHit) mask |= 1u << k;
    }
    return mask;
#endif
}

SYLVA_HD SYLVA_INLINE int lowestBit(unsigned mask)
{
#if defined(__CUDA_ARCH__)
    return __ffs(int(mask)) - 1;
#else
    return __builtin_ctz(mask);
#endif
}

// Visits, in roughly front-to-back order, every leaf whose box the ray [tmin, tmax] enters. With a
// callback leaf(slot, tmax) it is called per primitive with the primitive's slot in BVH order; with
// leaf(first, count, tmax) once per leaf. The callback shrinks tmax when it records a closer hit and
// returns true to stop at once (any-hit queries). Returns true when stopped by the callback.
template <int W, class LeafFn>
SYLVA_HD inline bool traverseBvh(BvhViewT<BvhNodeW<W>> bvh, const glm::vec3& org, const glm::vec3& dir, float tmin,
                                 float& tmax, LeafFn&& leaf)
{
    constexpr int kStack = kBvhStackSizeW<W>;
    const glm::vec3 inv = safeReciprocal(dir);
    const unsigned zeroAxes = (dir.x == 0.0f ? 1u : 0u) | (dir.y == 0.0f ? 2u : 0u) | (dir.z == 0.0f ? 4u : 0u);
    // Stack entries and the sorted children are inner nodes (count 0) or leaves (count > 0, tested
    // when they come up): every entered child is taken nearest first, so a far leaf is tested only
    // if nothing nearer hit before it (closest hit), and a hit shrinks tmax for everything behind.
    uint32_t stackNode[kStack], stackCount[kStack];
    float stackDist[kStack];
    int sp = 0;
    uint32_t node = 0;
    auto testLeaf = [&](uint32_t first, uint32_t count) {
        SYLVA_COUNT(g_bvhLeafVisits);
        if constexpr (std::is_invocable_v<LeafFn, uint32_t, uint32_t, float&>) {
            return leaf(first, count, tmax);
        } else {
            for (uint32_t p = 0; p < count; ++p)
                if (leaf(first + p, tmax)) return true;
            return false;
        }
    };
    for (;;) {
        const BvhNodeW<W>& n = bvh.nodes[node];
        SYLVA_COUNT(g_bvhNodeVisits);
        float tn[W];
        unsigned mask = nodeEntry(n, org, inv, zeroAxes, tmin, tmax, tn);
        // Entered children sorted far to near (the nearest ends last); their data fetched at once.
        uint32_t kidNode[W], kidCount[W];
        float kidDist[W];
        int kids = 0;
        while (mask) {
            const int k = lowestBit(mask);
            mask &= mask - 1u;
            int j = kids++;
            while (j > 0 && kidDist[j - 1] < tn[k]) {
                kidDist[j] = kidDist[j - 1];
                kidNode[j] = kidNode[j - 1];
                kidCount[j] = kidCount[j - 1];
                --j;
            }
            kidDist[j] = tn[k];
            kidNode[j] = n.child[k];
            kidCount[j] = n.count[k];
#if !defined(__CUDA_ARCH__)
            // Start the fetches now: traversal is bound by memory latency.
            if (n.count[k] > 0) {
                if (bvh.leafData) {
                    const char* p = bvh.leafData + size_t(n.child[k]) * bvh.leafBytes;
                    __builtin_prefetch(p);
                    __builtin_prefetch(p + 64);
                    __builtin_prefetch(p + 128);
                }
            } else {
                const char* p = reinterpret_cast<const char*>(&bvh.nodes[n.child[k]]);
                for (unsigned line = 0; line < sizeof(BvhNodeW<W>); line += 64) __builtin_prefetch(p + line);
            }
#endif
        }
        // Leaves nearer than every inner child are tested now, nearest first.
        while (kids > 0 && kidCount[kids - 1] > 0) {
            --kids;
            if (kidDist[kids] <= tmax && testLeaf(kidNode[kids], kidCount[kids])) return true;
        }
        // Push the farther ones, continue with the nearest inner child (re-checked against tmax).
        for (int j = 0; j + 1 < kids; ++j) {
            if (!(kidDist[j] <= tmax)) continue;
            SYLVA_KERNEL_ASSERT(sp < kStack);
            stackNode[sp] = kidNode[j];
            stackCount[sp] = kidCount[j];
            stackDist[sp] = kidDist[j];
            ++sp;
        }
        if (kids > 0 && kidDist[kids - 1] <= tmax) {
            node = kidNode[kids - 1];
            continue;
        }
        // Pop: leaves are tested on the way, the first inner node still in reach is visited.
        for (;;) {
            if (sp == 0) return false;
            --sp;
            if (!(stackDist[sp] <= tmax)) continue;
            if (stackCount[sp] == 0) break;
            if (testLeaf(stackNode[sp], stackCount[sp])) return true;
        }
        node = stackNode[sp];
    }
}

} // namespace sylva
