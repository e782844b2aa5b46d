// Binned-SAH bounding volume hierarchy over boxes: host build, flat 64-byte nodes, stack traversal (host and device).
#pragma once

#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "core/accel/ray.h"
#include "core/base/defines.h"
#include "core/mesh/triangle_mesh.h"

namespace sylva {

// One node holds the boxes of both its children, so one fetch tests two boxes. A child with
// count == 0 is an inner node at index `index`; count > 0 is a leaf of primitives
// [index, index + count) in the BVH's primitive order; an empty child has an inverted box. 64 bytes.
struct BvhNode {
    glm::vec3 lo0; uint32_t index0;
    glm::vec3 hi0; uint32_t count0;
    glm::vec3 lo1; uint32_t index1;
    glm::vec3 hi1; uint32_t count1;
};
static_assert(sizeof(BvhNode) == 64);

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

inline constexpr int kBvhStackSize = 64;

// Visits, in roughly front-to-back order, every leaf primitive whose leaf box the ray
// [tmin, tmax] enters, calling leaf(slot, tmax) with the primitive's slot in BVH order. The callback
// shrinks tmax when it records a closer hit and returns true to stop at once (any-hit queries).
// Returns true when stopped by the callback.
template <class LeafFn>
SYLVA_HD inline bool traverseBvh(BvhView bvh, const glm::vec3& org, const glm::vec3& dir, float tmin, float& tmax,
                                 LeafFn&& leaf)
{
    const glm::vec3 inv = safeReciprocal(dir);
    uint32_t stackNode[kBvhStackSize];
    float stackDist[kBvhStackSize];
    int sp = 0;
    uint32_t node = 0;
    for (;;) {
        const BvhNode& n = bvh.nodes[node];
        const float d0 = rayBoxEntry(n.lo0, n.hi0, org, inv, tmin, tmax);
        const float d1 = rayBoxEntry(n.lo1, n.hi1, org, inv, tmin, tmax);
        uint32_t next = kNoHit;
        // Leaves are handled at once (they may shrink tmax); inner children continue or are stacked.
        const bool firstIs0 = d0 <= d1;
        for (int k = 0; k < 2; ++k) {
            const bool c0 = (k == 0) == firstIs0;
            const float d = c0 ? d0 : d1;
            if (!(d <= tmax)) continue;
            const uint32_t index = c0 ? n.index0 : n.index1;
            const uint32_t count = c0 ? n.count0 : n.count1;
            if (count > 0) {
                for (uint32_t p = 0; p < count; ++p)
                    if (leaf(index + p, tmax)) return true;
            } else if (next == kNoHit) {
                next = index;
            } else {
                SYLVA_KERNEL_ASSERT(sp < kBvhStackSize);
                stackNode[sp] = index;
                stackDist[sp] = d;
                ++sp;
            }
        }
        if (next != kNoHit) {
            node = next;
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
