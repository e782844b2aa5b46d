// SAH kd-tree over boxes: host event-sweep build, flat 8-byte nodes, short-stack traversal (host and device).
#pragma once

#include <cstdint>
#include <functional>
#include <vector>

#include <glm/glm.hpp>

#include "core/accel/ray.h"
#include "core/base/defines.h"
#include "core/mesh/triangle_mesh.h"

namespace sylva {

// Inner node: `split` is the plane position (world units) on axis bits & 3 (0 x, 1 y, 2 z); the
// child below the plane is the next node, the child above is node bits >> 2. Leaf (bits & 3 == 3):
// primitives primRefs[primOffset, primOffset + (bits >> 2)). 8 bytes.
struct KdNode {
    union {
        float split;
        uint32_t primOffset;
    };
    uint32_t bits;

    SYLVA_HD bool isLeaf() const { return (bits & 3u) == 3u; }
    SYLVA_HD uint32_t axis() const { return bits & 3u; }
    SYLVA_HD uint32_t aboveChild() const { return bits >> 2; }
    SYLVA_HD uint32_t primCount() const { return bits >> 2; }
};
static_assert(sizeof(KdNode) == 8);

inline constexpr int kKdMaxDepth = 64;     // hard cap on the tree depth; also the full traversal stack
inline constexpr int kKdShortStack = 5;    // entries of the short-stack traversal
inline constexpr uint32_t kKdMaxCount = (1u << 30) - 1;   // nodes, primitives and references each

// Clips primitive `prim` to `box` and returns the bounds of the part inside, or an invalid box when
// nothing is inside. Must be conservative (never smaller than the true part) and thread-safe.
using KdClipFn = std::function<Bounds3(uint32_t prim, const Bounds3& box)>;

struct KdBuildSettings {
    float traversalCost = 1.0f;       // SAH cost of an inner node visit
    float intersectionCost = 1.5f;    // SAH cost of one primitive test
    float emptySpaceFactor = 0.8f;    // a split with an empty side costs this fraction (a bonus)
    int maxDepth = 0;                 // <= 0: 8 + 1.3 log2(n), at most kKdMaxDepth
    KdClipFn clip;                    // optional "perfect splits"; empty: boxes are clipped as boxes
};

// Shape of a built tree.
struct KdTreeStats {
    int depth = 0;                    // deepest leaf, root = 0
    int depthLimit = 0;               // the maxDepth the build used
    uint32_t innerNodes = 0;
    uint32_t leaves = 0;
    uint32_t emptyLeaves = 0;
    uint32_t maxLeafPrims = 0;
    double meanLeafDepth = 0.0;       // over non-empty leaves
    double sahCost = 0.0;             // expected cost of a ray through the scene box, in the settings' units
};

// The host-side result: node 0 is the root (a single empty leaf when nothing is valid); primRefs
// holds input primitive indices (a primitive may appear in several leaves); bounds is the box of
// all valid input boxes.
struct KdTree {
    std::vector<KdNode> nodes;
    std::vector<uint32_t> primRefs;
    Bounds3 bounds;
    KdTreeStats stats;
};

// Builds an SAH kd-tree (event sweep, O(n log n)) over primitive boxes. Invalid boxes end up in no
// leaf. Deterministic for any thread count; uses oneTBB for large inputs.
KdTree buildKdTree(const std::vector<Bounds3>& primBounds, const KdBuildSettings& settings = {});

// Bounds of triangle (a, b, c) clipped to `box` (conservative: computed in double precision
// against a slightly grown box, rounded outwards, then intersected with `box`); invalid when the
// triangle misses the box.
Bounds3 clipTriangleToBox(const glm::vec3& a, const glm::vec3& b, const glm::vec3& c, const Bounds3& box);

// A KdClipFn for the triangles of `mesh` (primitive i = mesh.triangles[i]); keeps a reference: the
// mesh must outlive the build.
KdClipFn kdTriangleClipper(const TriangleMesh& mesh);

// Device-friendly view of a kd-tree: its arrays and the scene box the traversal clips rays to.
struct KdView {
    const KdNode* nodes;
    const uint32_t* primRefs;
    glm::vec3 lo;
    glm::vec3 hi;
};

inline KdView kdView(const KdTree& tree)
{
    return KdView{tree.nodes.data(), tree.primRefs.data(), tree.bounds.lo, tree.bounds.hi};
}

// Optional traversal counters (summed over calls).
struct KdTraversalStats {
    uint32_t innerNodes = 0;    // inner node steps
    uint32_t leaves = 0;        // leaf visits
    uint32_t restarts = 0;      // short-stack underflows that restarted from the pushdown root
    uint32_t tiePasses = 0;     // extra passes for rays lying exactly in a split plane
};

namespace kd_detail {

struct StackEntry {
    uint32_t node;
    float t0, t1;
};

// One front-to-back pass. At a node whose split plane contains the ray (dir[a] == 0, org[a] ==
// split) the ray goes above when bit a of tieAbove is set, else below; such axes are added to
// tieSeen. Returns true when the callback stopped the traversal.
template <int kStack, class LeafFn>
SYLVA_HD inline bool traverseKdPass(const KdView& tree, const glm::vec3& org, const glm::vec3& dir, float sceneT0,
                                    float sceneT1, float& tmax, LeafFn& leaf, uint32_t tieAbove, uint32_t& tieSeen,
                                    KdTraversalStats* stats)
{
    StackEntry stack[kStack];
    int top = 0;      // next free slot of the ring
    int count = 0;    // live entries; a push onto a full ring drops the oldest (farthest) entry
    uint32_t restartRoot = 0;   // pushdown root: deepest node known to hold the rest of the ray
    float cellExit = sceneT0;   // exit distance of the last visited leaf
    bool first = true;
    for (;;) {
        const float end = minf(sceneT1, tmax);
        // Done when the ray left the scene, or a hit no farther than the last leaf's exit was recorded.
        if (!first && cellExit >= end) return false;
        uint32_t node;
        float c0, c1;
        bool pushdown;
        if (count == 0) {
            if (!first && stats) ++stats->restarts;
            node = restartRoot;
            c0 = cellExit;
            c1 = end;
            pushdown = true;
            first = false;
        } else {
            top = top == 0 ? kStack - 1 : top - 1;
            --count;
            node = stack[top].node;
            c0 = stack[top].t0;
            c1 = minf(stack[top].t1, tmax);
            pushdown = false;
        }
        for (;;) {
            const KdNode n = tree.nodes[node];
            const uint32_t a = n.bits & 3u;
            if (a == 3u) break;
            if (stats) ++stats->innerNodes;
            const float o = org[int(a)];
            const float d = dir[int(a)];
            const uint32_t below = node + 1;
            const uint32_t above = n.bits >> 2;
            if (d == 0.0f) {
                // Parallel to the plane: one side for the whole interval (both, over two passes, when in it).
                bool goAbove = o > n.split;
                if (o == n.split) {
                    tieSeen |= 1u << a;
                    goAbove = ((tieAbove >> a) & 1u) != 0u;
                }
                node = goAbove ? above : below;
            } else {
                const float ts = (n.split - o) / d;
                const uint32_t nearChild = d > 0.0f ? below : above;
                const uint32_t farChild = d > 0.0f ? above : below;
                if (ts >= c1) {
                    node = nearChild;
                } else if (ts <= c0) {
                    node = farChild;
                } else {
                    stack[top].node = farChild;
                    stack[top].t0 = ts;
                    stack[top].t1 = c1;
                    top = top + 1 == kStack ? 0 : top + 1;
                    if (count < kStack) ++count;
                    node = nearChild;
                    c1 = ts;
                    pushdown = false;
                }
            }
            if (pushdown) restartRoot = node;
        }
        const KdNode n = tree.nodes[node];
        const uint32_t cnt = n.bits >> 2;
        if (stats) ++stats->leaves;
        for (uint32_t i = 0; i < cnt; ++i)
            if (leaf(tree.primRefs[n.primOffset + i], tmax)) return true;
        cellExit = c1;
    }
}

template <int kStack, class LeafFn>
SYLVA_HD inline bool traverseKdImpl(const KdView& tree, const glm::vec3& org, const glm::vec3& dir, float tmin,
                                    float& tmax, LeafFn& leaf, KdTraversalStats* stats)
{
    // Clip [tmin, tmax] to the scene box; a ray parallel to a slab is inside it or misses.
    float t0 = tmin, t1 = tmax;
    for (int a = 0; a < 3; ++a) {
        if (dir[a] == 0.0f) {
            if (!(org[a] >= tree.lo[a] && org[a] <= tree.hi[a])) return false;
        } else {
            float ta = (tree.lo[a] - org[a]) / dir[a];
            float tb = (tree.hi[a] - org[a]) / dir[a];
            if (ta > tb) {
                const float tmp = ta;
                ta = tb;
                tb = tmp;
            }
            t0 = maxf(t0, ta);
            t1 = minf(t1, tb);
        }
    }
    if (!(t0 <= t1)) return false;
    // Pass 0 sends in-plane rays below every split plane they lie in; further passes cover each
    // combination of "above" for the axes where that happened (at most 2 for a non-zero dir).
    uint32_t tieSeen = 0, done = 0;
    for (;;) {
        int mask = -1;
        for (int m = 0; m < 8; ++m)
            if (!((done >> m) & 1u) && (uint32_t(m) & ~tieSeen) == 0u) {
                mask = m;
                break;
            }
        if (mask < 0) return false;
        done |= 1u << mask;
        if (mask != 0 && stats) ++stats->tiePasses;
        if (traverseKdPass<kStack>(tree, org, dir, t0, t1, tmax, leaf, uint32_t(mask), tieSeen, stats)) return true;
    }
}

} // namespace kd_detail

// Visits, front to back, the leaves the ray [tmin, tmax] passes through and calls leaf(primIndex,
// tmax) for each of their primitives with the input primitive index (a primitive can be reported
// more than once). The callback shrinks tmax when it records a closer hit and returns true to stop
// at once (any-hit queries). Stops when a recorded hit is no farther than the current leaf's exit.
// Short stack of kKdShortStack entries; on underflow it restarts from the pushdown root at the last
// leaf's exit. Returns true when stopped by the callback.
template <class LeafFn>
SYLVA_HD inline bool traverseKd(KdView tree, const glm::vec3& org, const glm::vec3& dir, float tmin, float& tmax,
                                LeafFn&& leaf, KdTraversalStats* stats = nullptr)
{
    return kd_detail::traverseKdImpl<kKdShortStack>(tree, org, dir, tmin, tmax, leaf, stats);
}

// The same traversal with a stack as deep as the tree (never restarts): the reference for traverseKd.
template <class LeafFn>
SYLVA_HD inline bool traverseKdFullStack(KdView tree, const glm::vec3& org, const glm::vec3& dir, float tmin,
                                         float& tmax, LeafFn&& leaf, KdTraversalStats* stats = nullptr)
{
    return kd_detail::traverseKdImpl<kKdMaxDepth>(tree, org, dir, tmin, tmax, leaf, stats);
}

} // namespace sylva
