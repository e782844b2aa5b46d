// Stochastic pruning: leaf elements by shared vertices, a fixed shuffled order, area-preserving levels.
#include "core/render/prune.h"

#include "core/base/splitmix.h"

#include <algorithm>
#include <cmath>
#include <numeric>

namespace sylva {
namespace {

uint32_t findRoot(std::vector<uint32_t>& parent, uint32_t a)
{
    while (parent[a] != a) {
        parent[a] = parent[parent[a]];
        a = parent[a];
    }
    return a;
}


// ceil(n / 2^level)
size_t keptElements(size_t n, int level) { return (n + (size_t(1) << level) - 1) >> level; }

} // namespace

LeafElements findLeafElements(const TriangleMesh& mesh)
{
    LeafElements e;
    const size_t nv = mesh.positions.size(), nt = mesh.triangles.size();
    std::vector<uint32_t> parent(nv);
    std::iota(parent.begin(), parent.end(), 0u);
    for (size_t t = 0; t < nt; ++t) {
        if (!mesh.isLeafTriangle(t)) continue;
        const glm::uvec3 tri = mesh.triangles[t];
        const uint32_t a = findRoot(parent, tri.x);
        for (uint32_t v : {tri.y, tri.z}) {
            const uint32_t b = findRoot(parent, v);
            if (a != b) parent[b] = a;
        }
    }
    // Elements numbered by their lowest triangle: a root gets its number at its first triangle.
    std::vector<uint32_t> elementOfRoot(nv, UINT32_MAX);
    std::vector<uint32_t> elementOfTri;
    std::vector<uint32_t> leafTris;
    uint32_t count = 0;
    for (size_t t = 0; t < nt; ++t) {
        if (!mesh.isLeafTriangle(t)) continue;
        const uint32_t r = findRoot(parent, mesh.triangles[t].x);
        if (elementOfRoot[r] == UINT32_MAX) elementOfRoot[r] = count++;
        leafTris.push_back(uint32_t(t));
        elementOfTri.push_back(elementOfRoot[r]);
    }
    // Counting sort of the leaf triangles by element (stable: ascending triangle order inside an element).
    e.first.assign(size_t(count) + 1, 0u);
    for (uint32_t el : elementOfTri) ++e.first[size_t(el) + 1];
    for (size_t i = 0; i < count; ++i) e.first[i + 1] += e.first[i];
    e.tris.resize(leafTris.size());
    std::vector<uint32_t> fill(e.first.begin(), e.first.end() - 1);
    for (size_t i = 0; i < leafTris.size(); ++i) e.tris[fill[elementOfTri[i]]++] = leafTris[i];

    e.area.assign(count, 0.0);
    e.centroid.assign(count, glm::dvec3(0.0));
    for (uint32_t el = 0; el < count; ++el) {
        glm::dvec3 weighted(0.0), mean(0.0);
        double area = 0.0;
        for (uint32_t i = e.first[el]; i < e.first[size_t(el) + 1]; ++i) {
            const glm::uvec3 tri = mesh.triangles[e.tris[i]];
            const glm::dvec3 a(mesh.positions[tri.x]), b(mesh.positions[tri.y]), c(mesh.positions[tri.z]);
            const double ta = 0.5 * glm::length(glm::cross(b - a, c - a));
            const glm::dvec3 centre = (a + b + c) / 3.0;
            weighted += ta * centre;
            mean += centre;
            area += ta;
        }
        const double n = double(e.first[size_t(el) + 1] - e.first[el]);
        e.area[el] = area;
        e.centroid[el] = area > 0.0 ? weighted / area : mean / n;
        e.totalArea += area;
    }
    return e;
}

std::vector<uint32_t> pruneOrder(size_t n, uint64_t seed)
{
    std::vector<uint32_t> order(n);
    std::iota(order.begin(), order.end(), 0u);
    SplitMix64 state{seed};
    for (size_t i = n; i > 1; --i) {
        // Unbiased enough for the purpose (bias < i / 2^64), and exactly reproducible.
        const size_t j = size_t((unsigned __int128)state.next() * i >> 64);
        std::swap(order[i - 1], order[j]);
    }
    return order;
}

int pruneLevelCount(const LeafElements& elements)
{
    int levels = 1;
    while (levels < kMaxPruneLevels && keptElements(elements.count(), levels) >= kMinPrunedElements) ++levels;
    return levels;
}

PrunedLevel buildPrunedLevel(const TriangleMesh& mesh, const LeafElements& elements, const std::vector<uint32_t>& order,
                             int level)
{
    PrunedLevel p;
    p.level = level;
    const size_t n = elements.count();
    p.elements = level == 0 ? n : keptElements(n, level);
    std::vector<uint32_t> kept(order.begin(), order.begin() + std::ptrdiff_t(std::min(p.elements, order.size())));
    std::sort(kept.begin(), kept.end());
    double keptArea = 0.0;
    for (uint32_t el : kept) keptArea += elements.area[el];
    p.areaScale = keptArea > 0.0 ? elements.totalArea / keptArea : double(size_t(1) << level);
    const double s = std::sqrt(p.areaScale);

    for (size_t t = 0; t < mesh.triangles.size(); ++t) {
        if (mesh.isLeafTriangle(t)) continue;
        p.tris.push_back(uint32_t(t));
        for (int c = 0; c < 3; ++c) p.corners.push_back(mesh.positions[mesh.triangles[t][c]]);
    }
    for (uint32_t el : kept) {
        const glm::dvec3 centre = elements.centroid[el];
        for (uint32_t i = elements.first[el]; i < elements.first[size_t(el) + 1]; ++i) {
            const uint32_t t = elements.tris[i];
            p.tris.push_back(t);
            for (int c = 0; c < 3; ++c)
                p.corners.push_back(glm::vec3(centre + s * (glm::dvec3(mesh.positions[mesh.triangles[t][c]]) - centre)));
        }
    }
    return p;
}

int pruneLevelFor(double distance, double start, int levels)
{
    if (!(start > 0.0) || levels <= 1 || !(distance > start)) return 0;
    const double z = distance / start;
    const int k = int(std::floor(std::log2(z) + 0.5));
    return std::clamp(k, 0, levels - 1);
}

} // namespace sylva
