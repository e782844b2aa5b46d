// Binned-SAH BVH build: a temporary tree built with oneTBB tasks, collapsed into 4-wide 128-byte nodes.
#include "core/accel/bvh.h"

#include <algorithm>
#include <memory>
#include <numeric>

#include <tbb/parallel_invoke.h>

namespace sylva {
namespace {

constexpr int kMaxBins = 64;
constexpr int kMedianDepth = 40;   // below this depth splits are object medians: depth stays < kBvhStackSize
constexpr uint32_t kParallelThreshold = 16384;

struct BuildNode {
    Bounds3 bounds;
    uint32_t begin = 0, end = 0;   // range of the reference array (leaf when children are null)
    std::unique_ptr<BuildNode> child[2];
    bool leaf() const { return !child[0]; }
};

struct Builder {
    const std::vector<Bounds3>& boxes;
    std::vector<glm::vec3> centroid;
    std::vector<uint32_t> refs;
    BvhBuildSettings s;

    float area(const Bounds3& b) const
    {
        if (!b.valid()) return 0.0f;
        const glm::vec3 e = b.extent();
        return 2.0f * (e.x * e.y + e.y * e.z + e.z * e.x);
    }

    // Cost of testing n primitives: per started block of leafBlock (a 4-wide test costs one).
    float blocks(uint32_t n) const
    {
        const uint32_t b = uint32_t(std::max(1, s.leafBlock));
        return float((n + b - 1) / b);
    }

    static Bounds3 merge(Bounds3 a, const Bounds3& b)
    {
        a.lo = glm::min(a.lo, b.lo);
        a.hi = glm::max(a.hi, b.hi);
        return a;
    }

    std::unique_ptr<BuildNode> build(uint32_t begin, uint32_t end, int depth)
    {
        auto node = std::make_unique<BuildNode>();
        node->begin = begin;
        node->end = end;
        Bounds3 cb;
        for (uint32_t i = begin; i < end; ++i) {
            node->bounds = merge(node->bounds, boxes[refs[i]]);
            cb.extend(centroid[refs[i]]);
        }
        const uint32_t n = end - begin;
        if (n <= 1) return node;
        const glm::vec3 ext = cb.extent();
        int axis = 0;
        if (ext.y > ext[axis]) axis = 1;
        if (ext.z > ext[axis]) axis = 2;
        uint32_t mid = begin;
        if (ext[axis] <= 0.0f) {
            // All centroids coincide: only a leaf or an arbitrary halving can separate them.
            if (n <= uint32_t(s.maxLeafSize)) return node;
            mid = begin + n / 2;
        } else if (depth >= kMedianDepth) {
            mid = begin + n / 2;
            std::nth_element(refs.begin() + begin, refs.begin() + mid, refs.begin() + end,
                             [&](uint32_t a, uint32_t b) { return centroid[a][axis] < centroid[b][axis]; });
        } else {
            // SAH over bins on all three axes.
            const int nb = std::clamp(s.bins, 2, kMaxBins);
            float bestCost = 1e38f;
            int bestAxis = -1, bestSplit = 0;
            for (int a = 0; a < 3; ++a) {
                if (ext[a] <= 0.0f) continue;
                Bounds3 binBox[kMaxBins];
                uint32_t binCount[kMaxBins] = {};
                const float scale = float(nb) / ext[a];
                for (uint32_t i = begin; i < end; ++i) {
                    const uint32_t r = refs[i];
                    const int b = std::min(nb - 1, int((centroid[r][a] - cb.lo[a]) * scale));
                    binBox[b] = merge(binBox[b], boxes[r]);
                    ++binCount[b];
                }
                float rightArea[kMaxBins];
                uint32_t rightCount[kMaxBins];
                Bounds3 acc;
                uint32_t cnt = 0;
                for (int b = nb - 1; b > 0; --b) {
                    acc = merge(acc, binBox[b]);
                    cnt += binCount[b];
                    rightArea[b] = area(acc);
                    rightCount[b] = cnt;
                }
                acc = Bounds3();
                cnt = 0;
                for (int b = 0; b < nb - 1; ++b) {
                    acc = merge(acc, binBox[b]);
                    cnt += binCount[b];
                    if (cnt == 0 || rightCount[b + 1] == 0) continue;
                    const float cost = area(acc) * blocks(cnt) + rightArea[b + 1] * blocks(rightCount[b + 1]);
                    if (cost < bestCost) {
                        bestCost = cost;
                        bestAxis = a;
                        bestSplit = b;
                    }
                }
            }
            const float leafCost = area(node->bounds) * blocks(n);
            const float splitCost = area(node->bounds) * s.traversalCost + bestCost;
            if (bestAxis < 0 || (n <= uint32_t(s.maxLeafSize) && leafCost <= splitCost)) {
                if (n <= uint32_t(s.maxLeafSize)) return node;
                mid = begin + n / 2;   // cannot separate by bins: halve along the widest axis
                std::nth_element(refs.begin() + begin, refs.begin() + mid, refs.begin() + end,
                                 [&](uint32_t a, uint32_t b) { return centroid[a][axis] < centroid[b][axis]; });
            } else {
                const float scale = float(nb) / ext[bestAxis];
                const float lo = cb.lo[bestAxis];
                auto it = std::partition(refs.begin() + begin, refs.begin() + end, [&](uint32_t r) {
                    return std::min(nb - 1, int((centroid[r][bestAxis] - lo) * scale)) <= bestSplit;
                });
                mid = uint32_t(it - refs.begin());
            }
        }
        if (n > kParallelThreshold) {
            tbb::parallel_invoke([&] { node->child[0] = build(begin, mid, depth + 1); },
                                 [&] { node->child[1] = build(mid, end, depth + 1); });
        } else {
            node->child[0] = build(begin, mid, depth + 1);
            node->child[1] = build(mid, end, depth + 1);
        }
        return node;
    }
};

float surfaceArea(const Bounds3& b)
{
    const glm::vec3 e = b.extent();
    return 2.0f * (e.x * e.y + e.y * e.z + e.z * e.x);
}

template <int W>
void clearNode(BvhNodeW<W>& n)
{
    for (int k = 0; k < W; ++k) {
        n.lox[k] = n.loy[k] = n.loz[k] = 1e30f;
        n.hix[k] = n.hiy[k] = n.hiz[k] = -1e30f;
        n.child[k] = kNoHit;
        n.count[k] = 0;
    }
}

// Writes the (up to W) children of `parent` at nodes[slot]: its two children, with the inner
// child of largest area replaced by its own two children while there is room. Recurses depth-first.
template <int W>
void flatten(const BuildNode* parent, uint32_t slot, std::vector<BvhNodeW<W>>& nodes, int depth, int& maxDepth)
{
    const BuildNode* kids[W] = {parent->child[0].get(), parent->child[1].get()};
    int nk = 2;
    while (nk < W) {
        int best = -1;
        float bestArea = -1.0f;
        for (int k = 0; k < nk; ++k)
            if (!kids[k]->leaf() && surfaceArea(kids[k]->bounds) > bestArea) {
                bestArea = surfaceArea(kids[k]->bounds);
                best = k;
            }
        if (best < 0) break;
        const BuildNode* open = kids[best];
        kids[best] = open->child[0].get();
        kids[nk++] = open->child[1].get();
    }
    clearNode(nodes[slot]);
    for (int k = 0; k < nk; ++k) {
        const BuildNode* c = kids[k];
        BvhNodeW<W>& n = nodes[slot];
        n.lox[k] = c->bounds.lo.x;
        n.loy[k] = c->bounds.lo.y;
        n.loz[k] = c->bounds.lo.z;
        n.hix[k] = c->bounds.hi.x;
        n.hiy[k] = c->bounds.hi.y;
        n.hiz[k] = c->bounds.hi.z;
        n.child[k] = 0;   // set below for inner children
        if (c->leaf()) {
            n.child[k] = c->begin;
            n.count[k] = c->end - c->begin;
            maxDepth = std::max(maxDepth, depth);
        }
    }
    for (int k = 0; k < nk; ++k) {
        const BuildNode* c = kids[k];
        if (c->leaf()) continue;
        const uint32_t childSlot = uint32_t(nodes.size());
        nodes.emplace_back();
        nodes[slot].child[k] = childSlot;
        nodes[slot].count[k] = 0;
        flatten<W>(c, childSlot, nodes, depth + 1, maxDepth);
    }
}

// The tree below `top` at nodes[0] (a single leaf: the root holds it as its first child). Returns the depth.
template <int W>
int flattenTree(const BuildNode* top, uint32_t prims, std::vector<BvhNodeW<W>>& nodes)
{
    nodes.emplace_back();
    clearNode(nodes[0]);
    if (!top) return 0;
    if (top->leaf()) {
        BvhNodeW<W>& root = nodes[0];
        root.lox[0] = top->bounds.lo.x;
        root.loy[0] = top->bounds.lo.y;
        root.loz[0] = top->bounds.lo.z;
        root.hix[0] = top->bounds.hi.x;
        root.hiy[0] = top->bounds.hi.y;
        root.hiz[0] = top->bounds.hi.z;
        root.child[0] = 0;
        root.count[0] = prims;
        return 1;
    }
    int maxDepth = 1;
    flatten<W>(top, 0, nodes, 1, maxDepth);
    return maxDepth;
}

} // namespace

Bvh buildBvh(const std::vector<Bounds3>& primBounds, const BvhBuildSettings& settings)
{
    Builder b{primBounds, {}, {}, settings};
    b.s.maxLeafSize = std::max(1, settings.maxLeafSize);
    b.centroid.assign(primBounds.size(), glm::vec3(0.0f));
    b.refs.reserve(primBounds.size());
    for (uint32_t i = 0; i < primBounds.size(); ++i) {
        if (!primBounds[i].valid()) continue;
        b.centroid[i] = primBounds[i].center();
        b.refs.push_back(i);
    }
    Bvh out;
    std::unique_ptr<BuildNode> top;
    if (!b.refs.empty()) {
        top = b.build(0, uint32_t(b.refs.size()), 0);
        out.bounds = top->bounds;
    }
    out.depth = flattenTree<4>(top.get(), uint32_t(b.refs.size()), out.nodes);
    if (settings.wide) out.wideDepth = flattenTree<8>(top.get(), uint32_t(b.refs.size()), out.wideNodes);
    out.primOrder = std::move(b.refs);
    return out;
}

} // namespace sylva
