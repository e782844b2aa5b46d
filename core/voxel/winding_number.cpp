// Winding numbers: the exact triangle solid angle and the dipole hierarchy over a median-split BVH.
#include "core/voxel/winding_number.h"

#include <algorithm>
#include <cmath>
#include <numeric>

namespace sylva {

namespace {
constexpr double kInv4Pi = 0.25 / 3.14159265358979323846;
constexpr int kLeafSize = 8;
} // namespace

double triangleWindingNumber(const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c)
{
    const double la = glm::length(a), lb = glm::length(b), lc = glm::length(c);
    const double det = glm::dot(a, glm::cross(b, c));
    const double den = la * lb * lc + glm::dot(a, b) * lc + glm::dot(b, c) * la + glm::dot(c, a) * lb;
    return 2.0 * std::atan2(det, den) * kInv4Pi;
}

WindingNumber::WindingNumber(const TriangleMesh& mesh, double beta) : m_beta2(beta * beta)
{
    const size_t n = mesh.triangles.size();
    std::vector<glm::dvec3> centroid(n);
    for (size_t t = 0; t < n; ++t) {
        const glm::uvec3 tri = mesh.triangles[t];
        centroid[t] = (glm::dvec3(mesh.positions[tri[0]]) + glm::dvec3(mesh.positions[tri[1]]) + glm::dvec3(mesh.positions[tri[2]])) / 3.0;
    }
    std::vector<int> order(n);
    std::iota(order.begin(), order.end(), 0);
    m_nodes.reserve(2 * n / kLeafSize + 2);
    // Build top-down; children of an inner node are stored next to each other.
    struct Task { int node, first, count; };
    m_nodes.push_back({});
    std::vector<Task> stack{{0, 0, int(n)}};
    while (!stack.empty()) {
        const Task task = stack.back();
        stack.pop_back();
        glm::dvec3 clo(1e300), chi(-1e300);
        for (int i = task.first; i < task.first + task.count; ++i) {
            clo = glm::min(clo, centroid[size_t(order[size_t(i)])]);
            chi = glm::max(chi, centroid[size_t(order[size_t(i)])]);
        }
        if (task.count <= kLeafSize) {
            m_nodes[size_t(task.node)].first = task.first;
            m_nodes[size_t(task.node)].count = task.count;
            continue;
        }
        const glm::dvec3 ext = chi - clo;
        const int axis = ext.x >= ext.y && ext.x >= ext.z ? 0 : (ext.y >= ext.z ? 1 : 2);
        const int mid = task.first + task.count / 2;
        std::nth_element(order.begin() + task.first, order.begin() + mid, order.begin() + task.first + task.count,
                         [&](int a, int b) {
                             const double ca = centroid[size_t(a)][axis], cb = centroid[size_t(b)][axis];
                             return ca < cb || (ca == cb && a < b);
                         });
        const int child = int(m_nodes.size());
        m_nodes.push_back({});
        m_nodes.push_back({});
        m_nodes[size_t(task.node)].first = child;
        m_nodes[size_t(task.node)].count = 0;
        stack.push_back({child, task.first, mid - task.first});
        stack.push_back({child + 1, mid, task.first + task.count - mid});
    }
    m_tri.resize(3 * n);
    for (size_t i = 0; i < n; ++i) {
        const glm::uvec3 tri = mesh.triangles[size_t(order[i])];
        for (int c = 0; c < 3; ++c) m_tri[3 * i + size_t(c)] = glm::dvec3(mesh.positions[tri[c]]);
    }
    // Bottom-up: boxes, vector areas and centroids (children have larger indices than parents).
    for (size_t ni = m_nodes.size(); ni-- > 0;) {
        Node& node = m_nodes[ni];
        node.lo = glm::dvec3(1e300);
        node.hi = glm::dvec3(-1e300);
        node.area = glm::dvec3(0.0);
        glm::dvec3 weighted(0.0);
        double total = 0.0;
        if (node.count > 0) {
            for (int i = node.first; i < node.first + node.count; ++i) {
                const glm::dvec3 &a = m_tri[3 * size_t(i)], &b = m_tri[3 * size_t(i) + 1], &c = m_tri[3 * size_t(i) + 2];
                node.lo = glm::min(node.lo, glm::min(a, glm::min(b, c)));
                node.hi = glm::max(node.hi, glm::max(a, glm::max(b, c)));
                const glm::dvec3 va = 0.5 * glm::cross(b - a, c - a);
                const double area = glm::length(va);
                node.area += va;
                weighted += area * (a + b + c) / 3.0;
                total += area;
            }
        } else {
            for (int c = 0; c < 2; ++c) {
                const Node& ch = m_nodes[size_t(node.first + c)];
                node.lo = glm::min(node.lo, ch.lo);
                node.hi = glm::max(node.hi, ch.hi);
                node.area += ch.area;
                weighted += ch.areaSum * ch.centre;
                total += ch.areaSum;
            }
        }
        node.areaSum = total;
        node.centre = total > 0.0 ? weighted / total : 0.5 * (node.lo + node.hi);
        double r2 = 0.0;
        for (int corner = 0; corner < 8; ++corner) {
            const glm::dvec3 q((corner & 1) ? node.hi.x : node.lo.x, (corner & 2) ? node.hi.y : node.lo.y,
                               (corner & 4) ? node.hi.z : node.lo.z);
            r2 = std::max(r2, glm::dot(q - node.centre, q - node.centre));
        }
        node.radius2 = r2;
    }
}

double WindingNumber::operator()(const glm::dvec3& p) const
{
    if (m_nodes.empty() || m_tri.empty()) return 0.0;
    double w = 0.0;
    int stack[128];
    int top = 0;
    stack[top++] = 0;
    while (top > 0) {
        const Node& node = m_nodes[size_t(stack[--top])];
        const glm::dvec3 d = node.centre - p;
        const double dist2 = glm::dot(d, d);
        if (dist2 > m_beta2 * node.radius2) {
            w += kInv4Pi * glm::dot(node.area, d) / (dist2 * std::sqrt(dist2));
            continue;
        }
        if (node.count > 0) {
            for (int i = node.first; i < node.first + node.count; ++i)
                w += triangleWindingNumber(m_tri[3 * size_t(i)] - p, m_tri[3 * size_t(i) + 1] - p, m_tri[3 * size_t(i) + 2] - p);
            continue;
        }
        stack[top++] = node.first;
        stack[top++] = node.first + 1;
    }
    return w;
}

double WindingNumber::exact(const glm::dvec3& p) const
{
    double w = 0.0;
    for (size_t i = 0; i < m_tri.size(); i += 3) w += triangleWindingNumber(m_tri[i] - p, m_tri[i + 1] - p, m_tri[i + 2] - p);
    return w;
}

} // namespace sylva
