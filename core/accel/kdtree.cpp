// SAH kd-tree build (Wald & Havran event sweep, O(n log n)): per-axis sorted event lists split in
// linear time; the top levels fork oneTBB tasks whose subtrees are built straight into flat 8-byte
// nodes, then concatenated depth-first.
#include "core/accel/kdtree.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <memory>
#include <stdexcept>

#include <tbb/parallel_for.h>
#include <tbb/parallel_invoke.h>
#include <tbb/parallel_sort.h>

namespace sylva {
namespace {

constexpr size_t kParallelSubtree = 4096;     // subtrees with more references become tasks
constexpr size_t kParallelAxes = 1u << 15;    // nodes with more references sweep/split axes in parallel

// An event is one 64-bit sort key: [63:32] the position's float bits mapped to unsigned order,
// [31:30] the type (end < planar < start at equal positions), [29:0] the node-local primitive index.
using Event = uint64_t;
constexpr uint32_t kEnd = 0, kPlanar = 1, kStart = 2;

uint32_t orderedBits(float f)
{
    f += 0.0f;   // -0 -> +0: equal floats give equal keys
    uint32_t u;
    std::memcpy(&u, &f, 4);
    return (u & 0x80000000u) ? ~u : (u | 0x80000000u);
}

float fromOrdered(uint32_t u)
{
    u = (u & 0x80000000u) ? (u & 0x7fffffffu) : ~u;
    float f;
    std::memcpy(&f, &u, 4);
    return f;
}

Event makeEvent(float pos, uint32_t type, uint32_t local)
{
    return (uint64_t(orderedBits(pos)) << 32) | (uint64_t(type) << 30) | local;
}
uint32_t evKey(Event e) { return uint32_t(e >> 32); }
uint32_t evType(Event e) { return uint32_t(e >> 30) & 3u; }
uint32_t evIndex(Event e) { return uint32_t(e) & kKdMaxCount; }
Event withIndex(Event e, uint32_t local) { return (e & ~uint64_t(kKdMaxCount)) | local; }

// Appends the events of box b on axis a for local primitive i.
void pushEvents(std::vector<Event>& out, const Bounds3& b, int a, uint32_t i)
{
    if (b.lo[a] == b.hi[a]) {
        out.push_back(makeEvent(b.lo[a], kPlanar, i));
    } else {
        out.push_back(makeEvent(b.lo[a], kStart, i));
        out.push_back(makeEvent(b.hi[a], kEnd, i));
    }
}

float halfArea(const glm::vec3& e) { return e.x * e.y + e.y * e.z + e.z * e.x; }

// References of one node: input primitive per local index, the primitive's part inside the node
// (clipped bounds) and per axis the sorted events of those parts.
struct NodeRefs {
    std::vector<uint32_t> prims;
    std::vector<Bounds3> boxes;
    std::vector<Event> events[3];
};

// A subtree built by one task, already flat: depth-first nodes with subtree-local child and
// reference offsets, its references, and its share of the statistics.
struct Subtree {
    std::vector<KdNode> nodes;
    std::vector<uint32_t> refs;
    KdTreeStats stats;
    double leafDepthSum = 0.0;
    double cost = 0.0;                    // SAH cost times the scene box's half area
};

// The top of the tree (nodes with more than kParallelSubtree references) as linked nodes.
struct BuildNode {
    int axis = -1;                        // -1: the flat subtree below
    float split = 0.0f;
    std::unique_ptr<BuildNode> child[2];  // below, above
    Subtree flat;
};

// A chosen split and the references of both sides.
struct Split {
    int axis = -1;
    float pos = 0.0f;
    Bounds3 boxL, boxR;
    NodeRefs left, right;
};

struct Plane {
    float cost = INFINITY;
    float pos = 0.0f;
    int axis = -1;
    bool planarLeft = true;   // primitives lying in the plane go below
};

enum : uint8_t { kLeftOnly = 1, kRightOnly = 2, kBoth = 3 };

struct Builder {
    KdBuildSettings s;

    float cost(float pl, float pr, size_t nl, size_t nr) const
    {
        const float c = s.traversalCost + s.intersectionCost * (pl * float(nl) + pr * float(nr));
        return (nl == 0 || nr == 0) ? s.emptySpaceFactor * c : c;
    }

    // The best plane on axis a strictly inside the node box.
    Plane sweep(const NodeRefs& r, const Bounds3& box, int a) const
    {
        Plane best;
        const glm::vec3 ext = box.extent();
        const float invArea = 1.0f / halfArea(ext);
        const std::vector<Event>& ev = r.events[a];
        const size_t n = r.prims.size();
        size_t nl = 0, nr = n;
        for (size_t i = 0; i < ev.size();) {
            const uint32_t key = evKey(ev[i]);
            size_t pe = 0, pp = 0, ps = 0;
            while (i < ev.size() && evKey(ev[i]) == key && evType(ev[i]) == kEnd) ++pe, ++i;
            while (i < ev.size() && evKey(ev[i]) == key && evType(ev[i]) == kPlanar) ++pp, ++i;
            while (i < ev.size() && evKey(ev[i]) == key && evType(ev[i]) == kStart) ++ps, ++i;
            nr -= pe + pp;
            const float p = fromOrdered(key);
            if (p > box.lo[a] && p < box.hi[a]) {
                glm::vec3 el = ext, er = ext;
                el[a] = p - box.lo[a];
                er[a] = box.hi[a] - p;
                const float pl = halfArea(el) * invArea, pr = halfArea(er) * invArea;
                const float costL = cost(pl, pr, nl + pp, nr);
                const float costR = cost(pl, pr, nl, nr + pp);
                const float c = std::min(costL, costR);
                if (c < best.cost) {
                    best.cost = c;
                    best.pos = p;
                    best.axis = a;
                    best.planarLeft = costL <= costR;
                }
            }
            nl += ps + pp;
        }
        return best;
    }

    // Finds the best SAH plane and splits the references (consuming r); false: make a leaf.
    bool findSplit(NodeRefs& r, const Bounds3& box, int depth, Split& out) const
    {
        const size_t n = r.prims.size();
        if (n == 0 || depth >= s.maxDepth || !(halfArea(box.extent()) > 0.0f)) return false;
        const bool par = n > kParallelAxes;

        Plane best[3];
        auto sweepAxis = [&](int a) { best[a] = sweep(r, box, a); };
        if (par)
            tbb::parallel_invoke([&] { sweepAxis(0); }, [&] { sweepAxis(1); }, [&] { sweepAxis(2); });
        else
            for (int a = 0; a < 3; ++a) sweepAxis(a);
        Plane plane = best[0];
        for (int a = 1; a < 3; ++a)
            if (best[a].cost < plane.cost) plane = best[a];
        if (plane.axis < 0 || !(plane.cost < s.intersectionCost * float(n))) return false;

        const int k = plane.axis;
        const float sp = plane.pos;
        Bounds3 boxL = box, boxR = box;
        boxL.hi[k] = sp;
        boxR.lo[k] = sp;

        // Classify: parts entirely below / above the plane, planar parts by the chosen side, the rest both.
        // (Keys order like the positions they encode.)
        std::vector<uint8_t> cls(n, kBoth);
        const uint32_t spKey = orderedBits(sp);
        for (const Event e : r.events[k]) {
            const uint32_t p = evKey(e), t = evType(e), i = evIndex(e);
            if (t == kEnd && p <= spKey) cls[i] = kLeftOnly;
            else if (t == kStart && p >= spKey) cls[i] = kRightOnly;
            else if (t == kPlanar) cls[i] = (p < spKey || (p == spKey && plane.planarLeft)) ? kLeftOnly : kRightOnly;
        }
        // Straddling parts are clipped to each side; a side they miss (perfect splits) drops them.
        std::vector<uint32_t> straddle;
        for (uint32_t i = 0; i < n; ++i)
            if (cls[i] == kBoth) straddle.push_back(i);
        std::vector<Bounds3> clipL(straddle.size()), clipR(straddle.size());
        auto clipOne = [&](size_t j) {
            const uint32_t i = straddle[j];
            const Bounds3& b = r.boxes[i];
            Bounds3 l = b, rr = b;
            l.hi[k] = sp;
            rr.lo[k] = sp;
            if (s.clip) {
                auto tighten = [&](Bounds3 c, const Bounds3& side) {
                    c.lo = glm::max(c.lo, side.lo);
                    c.hi = glm::min(c.hi, side.hi);
                    return c;
                };
                l = tighten(s.clip(r.prims[i], boxL), l);
                rr = tighten(s.clip(r.prims[i], boxR), rr);
            }
            clipL[j] = l;
            clipR[j] = rr;
        };
        if (straddle.size() > 256)
            tbb::parallel_for(size_t(0), straddle.size(), clipOne);
        else
            for (size_t j = 0; j < straddle.size(); ++j) clipOne(j);

        // Local indices of the children and whether a straddler's part changed on an axis.
        constexpr uint32_t kNone = 0xffffffffu;
        std::vector<uint32_t> idxL(n, kNone), idxR(n, kNone), slot(n, kNone);
        for (size_t j = 0; j < straddle.size(); ++j) slot[straddle[j]] = uint32_t(j);
        auto inL = [&](uint32_t i) { return cls[i] == kLeftOnly || (cls[i] == kBoth && clipL[slot[i]].valid()); };
        auto inR = [&](uint32_t i) { return cls[i] == kRightOnly || (cls[i] == kBoth && clipR[slot[i]].valid()); };
        size_t countL = 0, countR = 0;
        for (uint32_t i = 0; i < n; ++i) {
            countL += inL(i);
            countR += inR(i);
        }
        NodeRefs left, right;
        left.prims.reserve(countL);
        left.boxes.reserve(countL);
        right.prims.reserve(countR);
        right.boxes.reserve(countR);
        for (uint32_t i = 0; i < n; ++i) {
            const uint32_t j = slot[i];
            if (inL(i)) {
                idxL[i] = uint32_t(left.prims.size());
                left.prims.push_back(r.prims[i]);
                left.boxes.push_back(cls[i] == kBoth ? clipL[j] : r.boxes[i]);
            }
            if (inR(i)) {
                idxR[i] = uint32_t(right.prims.size());
                right.prims.push_back(r.prims[i]);
                right.boxes.push_back(cls[i] == kBoth ? clipR[j] : r.boxes[i]);
            }
        }
        auto same = [](const Bounds3& x, const Bounds3& y, int a) { return x.lo[a] == y.lo[a] && x.hi[a] == y.hi[a]; };
        auto splitAxis = [&](int a) {
            // New events of straddlers whose part changed on this axis, then the kept events in order.
            std::vector<Event> newL, newR;
            for (size_t j = 0; j < straddle.size(); ++j) {
                const uint32_t i = straddle[j];
                if (idxL[i] != kNone && !same(clipL[j], r.boxes[i], a)) pushEvents(newL, clipL[j], a, idxL[i]);
                if (idxR[i] != kNone && !same(clipR[j], r.boxes[i], a)) pushEvents(newR, clipR[j], a, idxR[i]);
            }
            std::vector<Event>& src = r.events[a];
            auto keepL = [&](uint32_t i) {
                if (cls[i] != kBoth) return cls[i] == kLeftOnly;
                return idxL[i] != kNone && same(clipL[slot[i]], r.boxes[i], a);
            };
            auto keepR = [&](uint32_t i) {
                if (cls[i] != kBoth) return cls[i] == kRightOnly;
                return idxR[i] != kNone && same(clipR[slot[i]], r.boxes[i], a);
            };
            size_t keptL = 0, keptR = 0;
            for (const Event e : src) {
                keptL += keepL(evIndex(e));
                keptR += keepR(evIndex(e));
            }
            std::vector<Event> l, rr;
            l.reserve(keptL + newL.size());
            rr.reserve(keptR + newR.size());
            for (const Event e : src) {
                const uint32_t i = evIndex(e);
                if (keepL(i)) l.push_back(withIndex(e, idxL[i]));
                if (keepR(i)) rr.push_back(withIndex(e, idxR[i]));
            }
            std::vector<Event>().swap(src);
            auto mergeInto = [](std::vector<Event>& dst, std::vector<Event>& add) {
                if (add.empty()) return;
                std::sort(add.begin(), add.end());
                const size_t mid = dst.size();
                dst.insert(dst.end(), add.begin(), add.end());
                std::inplace_merge(dst.begin(), dst.begin() + std::ptrdiff_t(mid), dst.end());
            };
            mergeInto(l, newL);
            mergeInto(rr, newR);
            left.events[a] = std::move(l);
            right.events[a] = std::move(rr);
        };
        if (par)
            tbb::parallel_invoke([&] { splitAxis(0); }, [&] { splitAxis(1); }, [&] { splitAxis(2); });
        else
            for (int a = 0; a < 3; ++a) splitAxis(a);
        // Free this node's references before descending.
        { NodeRefs gone = std::move(r); }
        std::vector<uint8_t>().swap(cls);
        std::vector<uint32_t>().swap(idxL);
        std::vector<uint32_t>().swap(idxR);
        std::vector<uint32_t>().swap(slot);
        std::vector<Bounds3>().swap(clipL);
        std::vector<Bounds3>().swap(clipR);

        out.axis = k;
        out.pos = sp;
        out.boxL = boxL;
        out.boxR = boxR;
        out.left = std::move(left);
        out.right = std::move(right);
        return true;
    }

    void writeLeaf(NodeRefs&& r, const Bounds3& box, int depth, Subtree& t) const
    {
        const size_t count = r.prims.size();
        KdNode& nd = t.nodes.back();
        nd.primOffset = uint32_t(t.refs.size());   // subtree-local; rebased when flattened
        nd.bits = (uint32_t(std::min<size_t>(count, kKdMaxCount)) << 2) | 3u;
        t.refs.insert(t.refs.end(), r.prims.begin(), r.prims.end());
        ++t.stats.leaves;
        if (count == 0) {
            ++t.stats.emptyLeaves;
        } else {
            t.leafDepthSum += depth;
            t.stats.maxLeafPrims = std::max(t.stats.maxLeafPrims, uint32_t(std::min<size_t>(count, kKdMaxCount)));
        }
        t.stats.depth = std::max(t.stats.depth, depth);
        t.cost += double(halfArea(box.extent())) * double(s.intersectionCost) * double(count);
    }

    // Builds a subtree sequentially, depth-first, straight into flat nodes.
    void buildFlat(NodeRefs&& r, const Bounds3& box, int depth, Subtree& t) const
    {
        const size_t index = t.nodes.size();
        t.nodes.emplace_back();
        Split sp;
        if (!findSplit(r, box, depth, sp)) {
            writeLeaf(std::move(r), box, depth, t);
            return;
        }
        ++t.stats.innerNodes;
        t.cost += double(halfArea(box.extent())) * double(s.traversalCost);
        buildFlat(std::move(sp.left), sp.boxL, depth + 1, t);
        const size_t above = t.nodes.size();
        buildFlat(std::move(sp.right), sp.boxR, depth + 1, t);
        KdNode& nd = t.nodes[index];
        nd.split = sp.pos;
        nd.bits = (uint32_t(std::min<size_t>(above, kKdMaxCount)) << 2) | uint32_t(sp.axis);
    }

    // The top levels: linked nodes whose subtrees are built as parallel tasks.
    std::unique_ptr<BuildNode> build(NodeRefs&& r, const Bounds3& box, int depth) const
    {
        auto node = std::make_unique<BuildNode>();
        Split sp;
        if (r.prims.size() <= kParallelSubtree || !findSplit(r, box, depth, sp)) {
            buildFlat(std::move(r), box, depth, node->flat);
            return node;
        }
        node->axis = sp.axis;
        node->split = sp.pos;
        tbb::parallel_invoke([&] { node->child[0] = build(std::move(sp.left), sp.boxL, depth + 1); },
                             [&] { node->child[1] = build(std::move(sp.right), sp.boxR, depth + 1); });
        return node;
    }
};

// Appends the top nodes and the flat subtrees depth-first, rebasing subtree-local offsets.
struct Flattener {
    KdTree& out;
    const KdBuildSettings& s;
    double leafDepthSum = 0.0;
    double cost = 0.0;

    static void count(const BuildNode* b, size_t& nodes, size_t& refs)
    {
        if (b->axis < 0) {
            nodes += b->flat.nodes.size();
            refs += b->flat.refs.size();
            return;
        }
        ++nodes;
        count(b->child[0].get(), nodes, refs);
        count(b->child[1].get(), nodes, refs);
    }

    // Consumes the subtrees as it goes (peak memory stays near one copy of the nodes).
    void flatten(BuildNode* b, const Bounds3& box)
    {
        KdTreeStats& st = out.stats;
        if (b->axis < 0) {
            Subtree& t = b->flat;
            const size_t base = out.nodes.size(), refBase = out.primRefs.size();
            for (KdNode n : t.nodes) {
                if (n.isLeaf()) n.primOffset += uint32_t(refBase);
                else n.bits += uint32_t(base) << 2;
                out.nodes.push_back(n);
            }
            out.primRefs.insert(out.primRefs.end(), t.refs.begin(), t.refs.end());
            st.depth = std::max(st.depth, t.stats.depth);
            st.innerNodes += t.stats.innerNodes;
            st.leaves += t.stats.leaves;
            st.emptyLeaves += t.stats.emptyLeaves;
            st.maxLeafPrims = std::max(st.maxLeafPrims, t.stats.maxLeafPrims);
            leafDepthSum += t.leafDepthSum;
            cost += t.cost;
            std::vector<KdNode>().swap(t.nodes);
            std::vector<uint32_t>().swap(t.refs);
            return;
        }
        const size_t index = out.nodes.size();
        out.nodes.emplace_back();
        ++st.innerNodes;
        cost += double(halfArea(box.extent())) * double(s.traversalCost);
        Bounds3 boxL = box, boxR = box;
        boxL.hi[b->axis] = b->split;
        boxR.lo[b->axis] = b->split;
        flatten(b->child[0].get(), boxL);
        const size_t above = out.nodes.size();
        flatten(b->child[1].get(), boxR);
        KdNode& nd = out.nodes[index];
        nd.split = b->split;
        nd.bits = (uint32_t(std::min<size_t>(above, kKdMaxCount)) << 2) | uint32_t(b->axis);
    }
};

// Sutherland-Hodgman clip of a convex polygon (at most 9 vertices) against one axis-aligned plane.
int clipPolygon(const glm::dvec3* in, int n, glm::dvec3* out, int a, double bound, bool keepBelow)
{
    int m = 0;
    for (int i = 0; i < n; ++i) {
        const glm::dvec3& cur = in[i];
        const glm::dvec3& nxt = in[(i + 1) % n];
        const double dc = keepBelow ? cur[a] - bound : bound - cur[a];
        const double dn = keepBelow ? nxt[a] - bound : bound - nxt[a];
        if (dc <= 0.0) out[m++] = cur;
        if ((dc < 0.0 && dn > 0.0) || (dc > 0.0 && dn < 0.0)) {
            glm::dvec3 p = cur + (nxt - cur) * (dc / (dc - dn));
            p[a] = bound;
            out[m++] = p;
        }
    }
    return m;
}

} // namespace

Bounds3 clipTriangleToBox(const glm::vec3& a, const glm::vec3& b, const glm::vec3& c, const Bounds3& box)
{
    Bounds3 none;
    if (!box.valid()) return none;
    // Clip against the box grown by a relative tolerance, so touching and rounding never lose a part.
    const glm::vec3 mag = glm::max(glm::abs(box.lo), glm::abs(box.hi));
    const double tol = 1e-6 * double(std::max({mag.x, mag.y, mag.z, 1e-30f}));
    glm::dvec3 buf0[9], buf1[9];
    buf0[0] = glm::dvec3(a);
    buf0[1] = glm::dvec3(b);
    buf0[2] = glm::dvec3(c);
    int n = 3;
    glm::dvec3* in = buf0;
    glm::dvec3* out = buf1;
    for (int ax = 0; ax < 3 && n > 0; ++ax) {
        n = clipPolygon(in, n, out, ax, double(box.hi[ax]) + tol, true);
        std::swap(in, out);
        if (n == 0) break;
        n = clipPolygon(in, n, out, ax, double(box.lo[ax]) - tol, false);
        std::swap(in, out);
    }
    if (n == 0) return none;
    glm::dvec3 lo(in[0]), hi(in[0]);
    for (int i = 1; i < n; ++i) {
        lo = glm::min(lo, in[i]);
        hi = glm::max(hi, in[i]);
    }
    Bounds3 r;
    for (int ax = 0; ax < 3; ++ax) {
        float l = float(lo[ax]), h = float(hi[ax]);
        if (double(l) > lo[ax]) l = std::nextafter(l, -INFINITY);
        if (double(h) < hi[ax]) h = std::nextafter(h, INFINITY);
        r.lo[ax] = std::max(l, box.lo[ax]);
        r.hi[ax] = std::min(h, box.hi[ax]);
    }
    return r.valid() ? r : none;
}

KdClipFn kdTriangleClipper(const TriangleMesh& mesh)
{
    return [&mesh](uint32_t prim, const Bounds3& box) {
        const glm::uvec3 t = mesh.triangles[prim];
        return clipTriangleToBox(mesh.positions[t.x], mesh.positions[t.y], mesh.positions[t.z], box);
    };
}

KdTree buildKdTree(const std::vector<Bounds3>& primBounds, const KdBuildSettings& settings)
{
    if (primBounds.size() > kKdMaxCount) throw std::length_error("buildKdTree: too many primitives");
    KdTree out;
    NodeRefs root;
    root.prims.reserve(primBounds.size());
    root.boxes.reserve(primBounds.size());
    for (uint32_t i = 0; i < primBounds.size(); ++i) {
        const Bounds3& b = primBounds[i];
        bool finite = b.valid();
        for (int a = 0; a < 3; ++a) finite = finite && std::isfinite(b.lo[a]) && std::isfinite(b.hi[a]);
        if (!finite) continue;
        root.prims.push_back(i);
        root.boxes.push_back(b);
        out.bounds.extend(b.lo);
        out.bounds.extend(b.hi);
    }
    Builder builder{settings};
    const size_t n = root.prims.size();
    if (builder.s.maxDepth <= 0)
        builder.s.maxDepth = int(std::lround(8.0 + 1.3 * std::log2(double(std::max<size_t>(n, 1)))));
    builder.s.maxDepth = std::clamp(builder.s.maxDepth, 0, kKdMaxDepth);
    out.stats.depthLimit = builder.s.maxDepth;

    auto makeEvents = [&](int a) {
        std::vector<Event>& ev = root.events[a];
        ev.reserve(2 * n);
        for (uint32_t i = 0; i < n; ++i) pushEvents(ev, root.boxes[i], a, i);
        tbb::parallel_sort(ev.begin(), ev.end());   // keys are unique: the order is deterministic
    };
    tbb::parallel_invoke([&] { makeEvents(0); }, [&] { makeEvents(1); }, [&] { makeEvents(2); });

    const Bounds3 box = out.bounds;
    std::unique_ptr<BuildNode> top = builder.build(std::move(root), box, 0);
    Flattener f{out, builder.s};
    size_t nodeCount = 0, refCount = 0;
    Flattener::count(top.get(), nodeCount, refCount);
    if (nodeCount > kKdMaxCount || refCount > kKdMaxCount)
        throw std::length_error("buildKdTree: more than 2^30 nodes or references");
    out.nodes.reserve(nodeCount);
    out.primRefs.reserve(refCount);
    f.flatten(top.get(), box);
    const double area = box.valid() ? halfArea(box.extent()) : 0.0;
    out.stats.sahCost = area > 0.0 ? f.cost / area : 0.0;
    const uint32_t full = out.stats.leaves - out.stats.emptyLeaves;
    out.stats.meanLeafDepth = full ? f.leafDepthSum / full : 0.0;
    return out;
}

} // namespace sylva
