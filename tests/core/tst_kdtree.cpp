// Tests of the SAH kd-tree (closest and any hits against brute force and the BVH, short vs full stack)
// and of the BVH's 8-wide flattening against its 4-wide one.
#include <QElapsedTimer>
#include <QTest>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <random>
#include <string>
#include <vector>

#include <tbb/global_control.h>
#include <tbb/parallel_for.h>

#include "core/accel/bvh.h"
#include "core/accel/kdtree.h"
#include "core/accel/ray.h"

using namespace sylva;

namespace {

// ---- meshes ----

struct Scene {
    TriangleMesh mesh;
    std::vector<glm::vec3> v0, e1, e2;
    std::vector<Bounds3> boxes;
};

Scene makeScene(TriangleMesh mesh)
{
    Scene s;
    s.mesh = std::move(mesh);
    for (const glm::uvec3& t : s.mesh.triangles) {
        const glm::vec3 a = s.mesh.positions[t.x], b = s.mesh.positions[t.y], c = s.mesh.positions[t.z];
        s.v0.push_back(a);
        s.e1.push_back(b - a);
        s.e2.push_back(c - a);
        Bounds3 box;
        box.extend(a);
        box.extend(b);
        box.extend(c);
        s.boxes.push_back(box);
    }
    return s;
}

void addTri(TriangleMesh& m, glm::vec3 a, glm::vec3 b, glm::vec3 c)
{
    const auto base = uint32_t(m.positions.size());
    m.positions.insert(m.positions.end(), {a, b, c});
    m.triangles.emplace_back(base, base + 1, base + 2);
}

glm::vec3 randIn(std::mt19937& rng, float lo, float hi)
{
    std::uniform_real_distribution<float> u(lo, hi);
    return {u(rng), u(rng), u(rng)};
}

// Triangles of every size in [-1, 1]^3.
TriangleMesh randomSoup(uint32_t seed, int n)
{
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> scale(0.0f, 1.0f);
    TriangleMesh m;
    for (int i = 0; i < n; ++i) {
        const glm::vec3 c = randIn(rng, -1.0f, 1.0f);
        const float s = 0.01f + 0.5f * std::pow(scale(rng), 3.0f);
        addTri(m, c + s * randIn(rng, -1.0f, 1.0f), c + s * randIn(rng, -1.0f, 1.0f), c + s * randIn(rng, -1.0f, 1.0f));
    }
    return m;
}

// Unit squares (two triangles each) lying on the integer planes x, y and z = 0..8 (half of them):
// every triangle is planar on a candidate split plane and shares edges with the planes across.
TriangleMesh planeGrid(uint32_t seed)
{
    std::mt19937 rng(seed);
    std::bernoulli_distribution keep(0.5);
    TriangleMesh m;
    const int g = 8;
    for (int a = 0; a < 3; ++a)
        for (int k = 0; k <= g; ++k)
            for (int i = 0; i < g; ++i)
                for (int j = 0; j < g; ++j) {
                    if (!keep(rng)) continue;
                    auto p = [&](int di, int dj) {
                        glm::vec3 v;
                        v[a] = float(k);
                        v[(a + 1) % 3] = float(i + di);
                        v[(a + 2) % 3] = float(j + dj);
                        return v;
                    };
                    addTri(m, p(0, 0), p(1, 0), p(1, 1));
                    addTri(m, p(0, 0), p(1, 1), p(0, 1));
                }
    return m;
}

// Long thin slivers crossing most of the box in every direction, and some along the axes.
TriangleMesh thinTriangles(uint32_t seed, int n)
{
    std::mt19937 rng(seed);
    TriangleMesh m;
    for (int i = 0; i < n; ++i) {
        const glm::vec3 a = randIn(rng, -1.0f, 1.0f);
        glm::vec3 d = randIn(rng, -1.5f, 1.5f);
        if (i % 4 == 0) d = glm::vec3(0.0f), d[i % 3] = 2.0f;   // axis-aligned needles
        const glm::vec3 b = a + d;
        addTri(m, a, b, b + 1e-3f * randIn(rng, -1.0f, 1.0f));
    }
    return m;
}

// Every triangle repeated up to four times, some with their vertices rotated or reversed.
TriangleMesh duplicates(uint32_t seed, int n)
{
    std::mt19937 rng(seed);
    std::uniform_int_distribution<int> copies(1, 4), order(0, 2);
    const TriangleMesh base = randomSoup(seed + 1, n);
    TriangleMesh m;
    for (const glm::uvec3& t : base.triangles) {
        const glm::vec3 a = base.positions[t.x], b = base.positions[t.y], c = base.positions[t.z];
        const int k = copies(rng);
        for (int r = 0; r < k; ++r) {
            switch (order(rng)) {
            case 0: addTri(m, a, b, c); break;
            case 1: addTri(m, b, c, a); break;
            default: addTri(m, c, b, a); break;
            }
        }
    }
    return m;
}

// Zero-area triangles (collinear, a repeated vertex, a point, axis-aligned segments) among normal ones.
TriangleMesh degenerate(uint32_t seed, int n)
{
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    TriangleMesh m = randomSoup(seed + 7, n / 2);
    for (int i = 0; i < n / 2; ++i) {
        const glm::vec3 a = randIn(rng, -1.0f, 1.0f), b = randIn(rng, -1.0f, 1.0f);
        switch (i % 5) {
        case 0: addTri(m, a, b, a + u(rng) * (b - a)); break;
        case 1: addTri(m, a, a, b); break;
        case 2: addTri(m, a, a, a); break;
        case 3: addTri(m, a, glm::vec3(b.x, a.y, a.z), glm::vec3(0.5f * (a.x + b.x), a.y, a.z)); break;
        default: addTri(m, a, b, randIn(rng, -1.0f, 1.0f)); break;
        }
    }
    return m;
}

// A procedural forest: a height-field terrain and trees with a cylinder trunk and leaf quads.
TriangleMesh forest(uint32_t seed, int terrainCells, int trees)
{
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    TriangleMesh m;
    const float size = 100.0f;
    auto height = [&](float x, float z) {
        return 2.0f * std::sin(0.1f * x) * std::cos(0.13f * z) + 0.5f * std::sin(0.5f * x + 0.3f * z);
    };
    const int g = terrainCells;
    for (int i = 0; i <= g; ++i)
        for (int j = 0; j <= g; ++j) {
            const float x = size * float(i) / float(g), z = size * float(j) / float(g);
            m.positions.emplace_back(x, height(x, z), z);
        }
    auto vid = [&](int i, int j) { return uint32_t(i * (g + 1) + j); };
    for (int i = 0; i < g; ++i)
        for (int j = 0; j < g; ++j) {
            m.triangles.emplace_back(vid(i, j), vid(i + 1, j), vid(i + 1, j + 1));
            m.triangles.emplace_back(vid(i, j), vid(i + 1, j + 1), vid(i, j + 1));
        }
    const float twoPi = 6.2831853f;
    for (int t = 0; t < trees; ++t) {
        const float x = 5.0f + 90.0f * u(rng), z = 5.0f + 90.0f * u(rng);
        const float y0 = height(x, z) - 0.2f, tall = 8.0f + 6.0f * u(rng), r = 0.2f + 0.2f * u(rng);
        const int seg = 12, rings = 8;
        for (int k = 0; k < rings; ++k)
            for (int s = 0; s < seg; ++s) {
                auto p = [&](int kk, int ss) {
                    const float ang = twoPi * float(ss) / float(seg);
                    const float rr = r * (1.0f - 0.7f * float(kk) / float(rings));
                    const float y = y0 + tall * float(kk) / float(rings);
                    return glm::vec3(x + rr * std::cos(ang), y, z + rr * std::sin(ang));
                };
                addTri(m, p(k, s), p(k + 1, s), p(k + 1, s + 1));
                addTri(m, p(k, s), p(k + 1, s + 1), p(k, s + 1));
            }
        for (int l = 0; l < 700; ++l) {
            const float cx = x + 3.0f * (2.0f * u(rng) - 1.0f), cy = y0 + tall * (0.4f + 0.6f * u(rng));
            const glm::vec3 c(cx, cy, z + 3.0f * (2.0f * u(rng) - 1.0f));
            const glm::vec3 a = 0.15f * glm::normalize(randIn(rng, -1.0f, 1.0f) + glm::vec3(1e-3f));
            const glm::vec3 b = 0.1f * glm::normalize(randIn(rng, -1.0f, 1.0f) + glm::vec3(1e-3f));
            addTri(m, c - a - b, c + a - b, c + a + b);
            addTri(m, c - a - b, c + a + b, c - a + b);
        }
    }
    return m;
}

// The meshes the brute-force comparisons run on: 0 random soup, 1 plane grid, 2 thin triangles,
// 3 duplicates, 4 degenerate, 5 a small forest.
TriangleMesh testMesh(int kind)
{
    switch (kind) {
    case 0: return randomSoup(11, 3000);
    case 1: return planeGrid(12);
    case 2: return thinTriangles(13, 1500);
    case 3: return duplicates(14, 800);
    case 4: return degenerate(15, 2000);
    default: return forest(21, 120, 30);
    }
}

// ---- rays ----

struct TestRay {
    glm::vec3 org, dir;
    float tmin, tmax;
};

// Origins inside and outside the box, on vertex coordinates (so rays lie in split planes);
// directions random, axis-parallel, or with one zero component; some rays with a finite tmax.
std::vector<TestRay> makeRays(const Scene& s, uint32_t seed, int n)
{
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    std::uniform_int_distribution<int> axis(0, 2);
    std::uniform_int_distribution<size_t> vertex(0, s.mesh.positions.size() - 1), tri(0, s.v0.size() - 1);
    Bounds3 box;
    for (const glm::vec3& p : s.mesh.positions) box.extend(p);
    const glm::vec3 ext = box.extent(), c = box.center();
    const float radius = glm::length(ext);
    std::vector<TestRay> rays(static_cast<size_t>(n));
    for (TestRay& r : rays) {
        const int kind = int(u(rng) * 10.0f);
        if (kind < 4) r.org = box.lo + ext * glm::vec3(u(rng), u(rng), u(rng)) * 1.1f - 0.05f * ext;
        else if (kind < 8)
            r.org = c + radius * (1.0f + u(rng)) * glm::normalize(randIn(rng, -1.0f, 1.0f) + glm::vec3(1e-4f));
        else r.org = s.mesh.positions[vertex(rng)] + glm::vec3(0.1f) * randIn(rng, -1.0f, 1.0f);
        // Towards a random triangle's centre half of the time, else a random direction.
        const size_t t = tri(rng);
        const glm::vec3 target = s.v0[t] + (s.e1[t] + s.e2[t]) * (1.0f / 3.0f);
        glm::vec3 d = u(rng) < 0.5f ? target - r.org : randIn(rng, -1.0f, 1.0f);
        const int dk = int(u(rng) * 10.0f);
        if (dk < 2) {
            // Exactly axis-parallel; the other two origin coordinates on a vertex half of the time.
            const int a = axis(rng);
            const float sign = d[a] < 0.0f ? -1.0f : 1.0f;
            d = glm::vec3(0.0f);
            d[a] = sign * (0.5f + u(rng));
            if (u(rng) < 0.5f) {
                const glm::vec3 v = s.mesh.positions[vertex(rng)];
                r.org[(a + 1) % 3] = v[(a + 1) % 3];
                r.org[(a + 2) % 3] = v[(a + 2) % 3];
            }
        } else if (dk < 4) {
            // One zero component (+0 or -0); the origin on a vertex plane half of the time.
            const int a = axis(rng);
            d[a] = u(rng) < 0.5f ? 0.0f : -0.0f;
            if (u(rng) < 0.5f) r.org[a] = s.mesh.positions[vertex(rng)][a];
        }
        if (d == glm::vec3(0.0f)) d = glm::vec3(0.0f, 1.0f, 0.0f);
        r.dir = d;
        r.tmin = u(rng) < 0.2f ? 0.1f * u(rng) * radius / glm::length(d) : 0.0f;
        r.tmax = u(rng) < 0.3f ? r.tmin + 1.5f * u(rng) * radius / glm::length(d) : INFINITY;
    }
    return rays;
}

// ---- queries ----

// Distance from p to triangle (a, b, c) in double precision (zero-area triangles too).
double distanceToTriangle(const glm::dvec3& p, const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c)
{
    auto seg = [&](const glm::dvec3& x, const glm::dvec3& y) {
        const glm::dvec3 xy = y - x;
        const double len2 = glm::dot(xy, xy);
        const double t = len2 > 0.0 ? std::clamp(glm::dot(p - x, xy) / len2, 0.0, 1.0) : 0.0;
        return glm::length(p - (x + t * xy));
    };
    double d = std::min({seg(a, b), seg(b, c), seg(c, a)});
    const glm::dvec3 n = glm::cross(b - a, c - a);
    const double nn = glm::dot(n, n);
    if (nn > 0.0 && glm::dot(glm::cross(b - a, p - a), n) >= 0.0 && glm::dot(glm::cross(c - b, p - b), n) >= 0.0 &&
        glm::dot(glm::cross(a - c, p - c), n) >= 0.0)
        d = std::min(d, std::fabs(glm::dot(p - a, n)) / std::sqrt(nn));
    return d;
}

// intersectTriangle, minus its numerical artefacts: on nearly collinear triangles (det ~ 0) it can
// report "hits" far from the triangle (0.1 to 10 units here), which no spatial index can (or
// should) reproduce. A hit counts only when its point org + t dir lies within 1e-3 (relative) of the
// triangle, which keeps the imprecise but genuine hits on slivers; the same test serves brute force,
// the kd-tree and the BVH.
std::atomic<uint64_t> g_spurious{0};

bool hitTriangle(const Scene& s, uint32_t p, const TestRay& r, float tmax, float& t)
{
    float u, v;
    if (!intersectTriangle(r.org, r.dir, s.v0[p], s.e1[p], s.e2[p], r.tmin, tmax, t, u, v)) return false;
    const glm::dvec3 h = glm::dvec3(r.org) + double(t) * glm::dvec3(r.dir);
    const glm::uvec3 tri = s.mesh.triangles[p];
    const double d = distanceToTriangle(h, s.mesh.positions[tri.x], s.mesh.positions[tri.y], s.mesh.positions[tri.z]);
    if (d <= 1e-3 * std::max({1.0, std::fabs(h.x), std::fabs(h.y), std::fabs(h.z)})) return true;
    ++g_spurious;
    return false;
}

struct Result {
    float t = INFINITY;
    uint32_t prim = kNoHit;
};

Result bruteClosest(const Scene& s, const TestRay& r)
{
    Result res;
    res.t = r.tmax;
    for (uint32_t p = 0; p < s.v0.size(); ++p) {
        float t;
        if (hitTriangle(s, p, r, res.t, t)) {
            res.t = t;
            res.prim = p;
        }
    }
    return res;
}

bool bruteAny(const Scene& s, const TestRay& r)
{
    for (uint32_t p = 0; p < s.v0.size(); ++p) {
        float t;
        if (hitTriangle(s, p, r, r.tmax, t)) return true;
    }
    return false;
}

template <bool kFull>
Result kdClosest(const Scene& s, KdView view, const TestRay& r, KdTraversalStats* stats)
{
    Result res;
    float tmax = r.tmax;
    auto leaf = [&](uint32_t p, float& tm) {
        float t;
        if (hitTriangle(s, p, r, tm, t)) {
            tm = t;
            res.prim = p;
        }
        return false;
    };
    if constexpr (kFull) traverseKdFullStack(view, r.org, r.dir, r.tmin, tmax, leaf, stats);
    else traverseKd(view, r.org, r.dir, r.tmin, tmax, leaf, stats);
    res.t = res.prim == kNoHit ? r.tmax : tmax;
    return res;
}

template <bool kFull>
bool kdAny(const Scene& s, KdView view, const TestRay& r, KdTraversalStats* stats)
{
    float tmax = r.tmax;
    auto leaf = [&](uint32_t p, float& tm) {
        float t;
        return hitTriangle(s, p, r, tm, t);
    };
    if constexpr (kFull) return traverseKdFullStack(view, r.org, r.dir, r.tmin, tmax, leaf, stats);
    else return traverseKd(view, r.org, r.dir, r.tmin, tmax, leaf, stats);
}

// The BVH is queried with tmax <= 1e30: its "missed" entry distance is 1e38, which is not beyond an
// infinite tmax (every box would count as entered and every leaf be visited).
constexpr float kBvhMaxT = 1e30f;

template <int W>
Result bvhClosest(const Scene& s, BvhViewT<BvhNodeW<W>> view, const Bvh& bvh, const TestRay& r)
{
    Result res;
    float tmax = std::min(r.tmax, kBvhMaxT);
    traverseBvh(view, r.org, r.dir, r.tmin, tmax, [&](uint32_t slot, float& tm) {
        const uint32_t p = bvh.primOrder[slot];
        float t;
        if (hitTriangle(s, p, r, tm, t)) {
            tm = t;
            res.prim = p;
        }
        return false;
    });
    res.t = res.prim == kNoHit ? r.tmax : tmax;
    return res;
}

template <int W>
bool bvhAny(const Scene& s, BvhViewT<BvhNodeW<W>> view, const Bvh& bvh, const TestRay& r)
{
    float tmax = std::min(r.tmax, kBvhMaxT);
    return traverseBvh(view, r.org, r.dir, r.tmin, tmax, [&](uint32_t slot, float& tm) {
        const uint32_t p = bvh.primOrder[slot];
        float t;
        return hitTriangle(s, p, r, tm, t);
    });
}

Result bvhClosest(const Scene& s, const Bvh& bvh, const TestRay& r) { return bvhClosest(s, BvhView{bvh.nodes.data()}, bvh, r); }
bool bvhAny(const Scene& s, const Bvh& bvh, const TestRay& r) { return bvhAny(s, BvhView{bvh.nodes.data()}, bvh, r); }

// Leaves (first slot, count) of a flattening, sorted, and the box of everything below each child
// checked against the child's box (every box encloses its subtree's primitive boxes).
template <int W>
std::vector<std::pair<uint32_t, uint32_t>> leavesOf(const std::vector<BvhNodeW<W>>& nodes, const Bvh& bvh,
                                                   const std::vector<Bounds3>& primBoxes, bool& enclosed)
{
    std::vector<std::pair<uint32_t, uint32_t>> leaves;
    enclosed = true;
    auto walk = [&](auto&& self, uint32_t index) -> Bounds3 {
        const BvhNodeW<W>& n = nodes[index];
        Bounds3 all;
        for (int k = 0; k < W; ++k) {
            if (n.child[k] == kNoHit) continue;
            Bounds3 below;
            if (n.count[k] > 0) {
                leaves.emplace_back(n.child[k], n.count[k]);
                for (uint32_t p = 0; p < n.count[k]; ++p) {
                    const Bounds3& b = primBoxes[bvh.primOrder[n.child[k] + p]];
                    below.extend(b.lo);
                    below.extend(b.hi);
                }
            } else {
                below = self(self, n.child[k]);
            }
            const glm::vec3 lo(n.lox[k], n.loy[k], n.loz[k]), hi(n.hix[k], n.hiy[k], n.hiz[k]);
            if (glm::any(glm::lessThan(below.lo, lo)) || glm::any(glm::greaterThan(below.hi, hi))) enclosed = false;
            all.extend(below.lo);
            all.extend(below.hi);
        }
        return all;
    };
    if (!nodes.empty()) walk(walk, 0);
    std::sort(leaves.begin(), leaves.end());
    return leaves;
}

// Same hit: both miss, or t within 1e-5 relative (a different triangle only at such a tie).
bool sameHit(const Result& a, const Result& b)
{
    if (a.prim == kNoHit || b.prim == kNoHit) return a.prim == b.prim;
    return std::fabs(a.t - b.t) <= 1e-5f * std::max(1.0f, std::fabs(b.t));
}

struct Counts {
    std::atomic<uint64_t> hits{0}, kdMismatch{0}, kdAnyMismatch{0}, bvhMismatch{0}, bvhAnyMismatch{0};
    std::atomic<uint64_t> bvhBruteMismatch{0}, bvhBruteAnyMismatch{0};
    std::atomic<uint64_t> shortVsFull{0}, otherTriangle{0}, leavesShort{0}, leavesFull{0}, restarts{0}, tiePasses{0};
    std::atomic<uint64_t> innerShort{0}, innerFull{0};
    std::atomic<uint64_t> restartedRays{0};
    std::atomic<int> firstBad{-1};
};

QString rayText(const TestRay& r)
{
    return QString("org (%1, %2, %3) dir (%4, %5, %6) t [%7, %8]")
        .arg(double(r.org.x), 0, 'g', 9).arg(double(r.org.y), 0, 'g', 9).arg(double(r.org.z), 0, 'g', 9)
        .arg(double(r.dir.x), 0, 'g', 9).arg(double(r.dir.y), 0, 'g', 9).arg(double(r.dir.z), 0, 'g', 9)
        .arg(double(r.tmin), 0, 'g', 9).arg(double(r.tmax), 0, 'g', 9);
}

// Runs every query on every ray; brute force on the first `bruteRays` rays (the BVH on all).
void compareAll(const Scene& s, const KdTree& kd, const Bvh& bvh, const std::vector<TestRay>& rays, size_t bruteRays,
                Counts& c)
{
    const KdView view = kdView(kd);
    tbb::parallel_for(tbb::blocked_range<size_t>(0, rays.size(), 256), [&](const tbb::blocked_range<size_t>& range) {
        KdTraversalStats ss, fs;
        for (size_t i = range.begin(); i < range.end(); ++i) {
            const TestRay& r = rays[i];
            const uint32_t restartsBefore = ss.restarts;
            const Result ks = kdClosest<false>(s, view, r, &ss);
            const Result kf = kdClosest<true>(s, view, r, &fs);
            const bool as = kdAny<false>(s, view, r, nullptr);
            const bool af = kdAny<true>(s, view, r, nullptr);
            const Result bv = bvhClosest(s, bvh, r);
            const bool ab = bvhAny(s, bvh, r);
            bool bad = false;
            if (ss.restarts != restartsBefore) ++c.restartedRays;
            if (std::memcmp(&ks.t, &kf.t, 4) != 0 || ks.prim != kf.prim || as != af) ++c.shortVsFull, bad = true;
            c.hits += ks.prim != kNoHit;
            if (i < bruteRays) {
                const Result bf = bruteClosest(s, r);
                const bool ba = bruteAny(s, r);
                if (!sameHit(ks, bf)) ++c.kdMismatch, bad = true;
                else if (ks.prim != bf.prim) ++c.otherTriangle;
                if (as != ba) ++c.kdAnyMismatch, bad = true;
                if (!sameHit(bv, bf)) ++c.bvhBruteMismatch;
                if (ab != ba) ++c.bvhBruteAnyMismatch;
            }
            if (!sameHit(ks, bv)) ++c.bvhMismatch;
            if (as != ab) ++c.bvhAnyMismatch;
            if (bad) {
                int expected = -1;
                c.firstBad.compare_exchange_strong(expected, int(i));
            }
        }
        c.innerShort += ss.innerNodes;
        c.innerFull += fs.innerNodes;
        c.leavesShort += ss.leaves;
        c.leavesFull += fs.leaves;
        c.restarts += ss.restarts;
        c.tiePasses += fs.tiePasses;
    });
}

void report(const char* name, const KdTree& kd, const std::vector<TestRay>& rays, const Counts& c, double buildMs)
{
    const KdTreeStats& st = kd.stats;
    qInfo("%s: %u nodes (%u leaves, %u empty), %zu refs, depth %d (limit %d, mean leaf %.1f), max leaf %u, SAH %.1f, "
          "build %.0f ms",
          name, st.innerNodes + st.leaves, st.leaves, st.emptyLeaves, kd.primRefs.size(), st.depth, st.depthLimit,
          st.meanLeafDepth, st.maxLeafPrims, st.sahCost, buildMs);
    const double n = double(rays.size());
    qInfo("  %zu rays: %llu hits; per ray: inner nodes short %.2f full %.2f, leaves short %.2f full %.2f; "
          "restarts %llu (%.3f/ray, %llu rays); tie passes %llu; ties with another triangle %llu; "
          "intersectTriangle artefacts rejected %llu",
          rays.size(), (unsigned long long)c.hits.load(), double(c.innerShort) / n, double(c.innerFull) / n,
          double(c.leavesShort) / n, double(c.leavesFull) / n,
          (unsigned long long)c.restarts.load(), double(c.restarts) / n, (unsigned long long)c.restartedRays.load(),
          (unsigned long long)c.tiePasses.load(), (unsigned long long)c.otherTriangle.load(),
          (unsigned long long)g_spurious.load());
}

// The kd-tree must agree with brute force everywhere and the short stack with the full stack
// bit for bit. The BVH is compared for information only: it misses hits of rays lying exactly in a
// face of a node box (a slab with dir 0 and 0 * 1e30 = 0) and is not what this test is about.
void checkCounts(const Counts& c, const std::vector<TestRay>& rays)
{
    if (c.firstBad >= 0)
        qWarning("first bad ray %d: %s", c.firstBad.load(), qPrintable(rayText(rays[size_t(c.firstBad)])));
    QCOMPARE(c.kdMismatch.load(), uint64_t(0));
    QCOMPARE(c.kdAnyMismatch.load(), uint64_t(0));
    QCOMPARE(c.shortVsFull.load(), uint64_t(0));
    qInfo("  BVH: %llu closest / %llu any-hit differ from the kd-tree, %llu / %llu from brute force",
          (unsigned long long)c.bvhMismatch.load(), (unsigned long long)c.bvhAnyMismatch.load(),
          (unsigned long long)c.bvhBruteMismatch.load(), (unsigned long long)c.bvhBruteAnyMismatch.load());
}

bool sameTree(const KdTree& a, const KdTree& b)
{
    return a.nodes.size() == b.nodes.size() && a.primRefs == b.primRefs &&
           std::memcmp(a.nodes.data(), b.nodes.data(), a.nodes.size() * sizeof(KdNode)) == 0;
}

// The kd-tree of s's boxes (clipped to their triangles when `clip`); *ms: its build time.
KdTree timedBuild(const Scene& s, bool clip, double* ms)
{
    KdBuildSettings settings;
    if (clip) settings.clip = kdTriangleClipper(s.mesh);
    QElapsedTimer timer;
    timer.start();
    KdTree kd = buildKdTree(s.boxes, settings);
    *ms = double(timer.nsecsElapsed()) * 1e-6;
    return kd;
}

// Structural checks: children in range, every leaf range inside primRefs, references valid.
void checkStructure(const KdTree& kd, size_t prims)
{
    QVERIFY(!kd.nodes.empty());
    for (size_t i = 0; i < kd.nodes.size(); ++i) {
        const KdNode& n = kd.nodes[i];
        if (n.isLeaf()) {
            QVERIFY(size_t(n.primOffset) + n.primCount() <= kd.primRefs.size());
        } else {
            QVERIFY(i + 1 < kd.nodes.size());
            QVERIFY(n.aboveChild() > i + 1 && n.aboveChild() < kd.nodes.size());
        }
    }
    for (uint32_t p : kd.primRefs) QVERIFY(p < prims);
    QVERIFY(kd.stats.depth <= kd.stats.depthLimit);
}

} // namespace

class TestKdTree : public QObject {
    Q_OBJECT

private Q_SLOTS:
    void nodeLayout();
    void emptyAndInvalid();
    void clipTriangle();
    void matchesBruteForce_data();
    void matchesBruteForce();
    void largeForest();
    void deterministicAcrossThreads();
    void wideBvhMatchesFourWide_data();
    void wideBvhMatchesFourWide();
};

void TestKdTree::nodeLayout()
{
    QCOMPARE(sizeof(KdNode), size_t(8));
    KdNode n{};
    n.split = 1.5f;
    n.bits = (7u << 2) | 2u;
    QVERIFY(!n.isLeaf());
    QCOMPARE(n.axis(), 2u);
    QCOMPARE(n.aboveChild(), 7u);
    n.primOffset = 11;
    n.bits = (5u << 2) | 3u;
    QVERIFY(n.isLeaf());
    QCOMPARE(n.primCount(), 5u);
}

void TestKdTree::emptyAndInvalid()
{
    // Nothing valid: one empty leaf, no callback, no hit.
    const KdTree empty = buildKdTree({});
    QCOMPARE(empty.nodes.size(), size_t(1));
    QVERIFY(empty.primRefs.empty());
    float tmax = INFINITY;
    int calls = 0;
    QVERIFY(!traverseKd(kdView(empty), glm::vec3(0.0f), glm::vec3(1.0f, 0.0f, 0.0f), 0.0f, tmax,
                        [&](uint32_t, float&) { return ++calls, false; }));
    QCOMPARE(calls, 0);

    // Invalid (inverted, NaN) boxes among valid ones are in no leaf.
    Scene s = makeScene(randomSoup(3, 500));
    std::vector<Bounds3> boxes = s.boxes;
    for (size_t i = 0; i < boxes.size(); i += 7) boxes[i] = Bounds3();
    boxes[3].lo.x = NAN;
    for (bool clip : {false, true}) {
        KdBuildSettings settings;
        if (clip) settings.clip = kdTriangleClipper(s.mesh);
        const KdTree kd = buildKdTree(boxes, settings);
        checkStructure(kd, boxes.size());
        for (uint32_t p : kd.primRefs) {
            QVERIFY(p % 7 != 0);
            QVERIFY(p != 3);
        }
        // Every valid primitive is referenced.
        std::vector<char> seen(boxes.size(), 0);
        for (uint32_t p : kd.primRefs) seen[p] = 1;
        for (size_t i = 0; i < boxes.size(); ++i) QCOMPARE(bool(seen[i]), i % 7 != 0 && i != 3);
    }
}

void TestKdTree::clipTriangle()
{
    Bounds3 box;
    box.lo = glm::vec3(0.0f);
    box.hi = glm::vec3(1.0f);
    // Inside: its own bounds.
    Bounds3 b = clipTriangleToBox({0.1f, 0.2f, 0.3f}, {0.9f, 0.2f, 0.3f}, {0.5f, 0.8f, 0.6f}, box);
    QVERIFY(b.valid());
    QCOMPARE(b.lo, glm::vec3(0.1f, 0.2f, 0.3f));
    QCOMPARE(b.hi, glm::vec3(0.9f, 0.8f, 0.6f));
    // Missing the box (its bounding box overlaps it).
    b = clipTriangleToBox({1.2f, -0.5f, 0.5f}, {2.5f, 1.5f, 0.5f}, {2.5f, -0.5f, 0.5f}, box);
    QVERIFY(!b.valid());
    // Crossing a corner: bounds of the part inside, conservative.
    b = clipTriangleToBox({0.5f, 0.5f, 0.5f}, {1.5f, 0.5f, 0.5f}, {0.5f, 1.5f, 0.5f}, box);
    QVERIFY(b.valid());
    QVERIFY(b.lo.x <= 0.5f && b.lo.y <= 0.5f && b.hi.x == 1.0f && b.hi.y == 1.0f);
    QVERIFY(b.lo.z <= 0.5f && b.hi.z >= 0.5f && b.hi.z - b.lo.z < 1e-6f);
    // Touching a face only: kept (flat at the face).
    b = clipTriangleToBox({1.0f, 0.2f, 0.2f}, {2.0f, 0.5f, 0.2f}, {2.0f, 0.2f, 0.7f}, box);
    QVERIFY(b.valid());
    QCOMPARE(b.hi.x, 1.0f);
}

void TestKdTree::matchesBruteForce_data()
{
    QTest::addColumn<int>("mesh");
    QTest::addColumn<bool>("clip");
    const char* names[] = {"random soup", "plane grid", "thin triangles", "duplicates", "degenerate"};
    for (int m = 0; m < 5; ++m)
        for (bool clip : {false, true})
            QTest::newRow(qPrintable(QString("%1, %2").arg(names[m], clip ? "clipped" : "boxes"))) << m << clip;
}

void TestKdTree::matchesBruteForce()
{
    QFETCH(int, mesh);
    QFETCH(bool, clip);
    const Scene s = makeScene(testMesh(mesh));
    double ms = 0.0;
    const KdTree kd = timedBuild(s, clip, &ms);
    checkStructure(kd, s.boxes.size());
    const Bvh bvh = buildBvh(s.boxes);
    const std::vector<TestRay> rays = makeRays(s, 100u + uint32_t(mesh), 100000);
    Counts c;
    g_spurious = 0;
    compareAll(s, kd, bvh, rays, rays.size(), c);
    report(QTest::currentDataTag(), kd, rays, c, ms);
    checkCounts(c, rays);
    QVERIFY(c.hits > rays.size() / 10);
    if (mesh == 1) QVERIFY(c.tiePasses > 0);   // rays in the grid's planes took the second pass
}

void TestKdTree::largeForest()
{
    const Scene s = makeScene(forest(21, 220, 60));
    QVERIFY(s.boxes.size() >= 100000);
    const Bvh bvh = buildBvh(s.boxes);
    const std::vector<TestRay> rays = makeRays(s, 200, 100000);
    for (bool clip : {false, true}) {
        double ms = 0.0;
        const KdTree kd = timedBuild(s, clip, &ms);
        checkStructure(kd, s.boxes.size());
        Counts c;
        g_spurious = 0;
        compareAll(s, kd, bvh, rays, 3000, c);   // brute force on the first 3000 rays, the BVH on all
        const std::string name = std::to_string(s.boxes.size()) + "-triangle forest, " + (clip ? "clipped" : "boxes");
        report(name.c_str(), kd, rays, c, ms);
        checkCounts(c, rays);
        QVERIFY(c.hits > rays.size() / 10);
        QVERIFY(c.restarts > 0);   // the short stack's restart path was exercised
    }
}

void TestKdTree::deterministicAcrossThreads()
{
    const Scene s = makeScene(forest(5, 120, 20));
    for (bool clip : {false, true}) {
        KdBuildSettings settings;
        if (clip) settings.clip = kdTriangleClipper(s.mesh);
        const KdTree a = buildKdTree(s.boxes, settings);
        const KdTree b = buildKdTree(s.boxes, settings);
        QVERIFY(sameTree(a, b));
        tbb::global_control limit(tbb::global_control::max_allowed_parallelism, 1);
        const KdTree single = buildKdTree(s.boxes, settings);
        QVERIFY(sameTree(a, single));
    }
}

void TestKdTree::wideBvhMatchesFourWide_data()
{
    QTest::addColumn<int>("mesh");
    const char* names[] = {"random soup", "plane grid", "thin triangles", "duplicates", "degenerate", "forest"};
    for (int m = 0; m < 6; ++m) QTest::newRow(names[m]) << m;
}

// The 8-wide flattening (the host renderer's) holds the same leaves under boxes that enclose them,
// in fewer levels, and finds the same closest hit and the same any-hit answer as the 4-wide one on
// every ray. Closest hits compare as sameHit does: where two triangles lie within float rounding of
// each other on a box face, which one the traversal meets first decides whether the other's box is
// still entered (a hit can round below its box's entry distance), so t may differ in the last bits.
void TestKdTree::wideBvhMatchesFourWide()
{
    QFETCH(int, mesh);
    const Scene s = makeScene(testMesh(mesh));
    for (int leafBlock : {1, 4}) {
        BvhBuildSettings settings;
        settings.wide = true;
        settings.leafBlock = leafBlock;
        settings.maxLeafSize = leafBlock == 4 ? 4 : 8;   // the renderer's species settings, and the defaults
        const Bvh bvh = buildBvh(s.boxes, settings);
        QVERIFY(!bvh.wideNodes.empty());
        bool enclosed4 = false, enclosed8 = false;
        const auto leaves4 = leavesOf(bvh.nodes, bvh, s.boxes, enclosed4);
        const auto leaves8 = leavesOf(bvh.wideNodes, bvh, s.boxes, enclosed8);
        QVERIFY(enclosed4);
        QVERIFY(enclosed8);
        QVERIFY(leaves4 == leaves8);
        uint32_t covered = 0;
        for (const auto& l : leaves8) {   // every slot in exactly one leaf
            QCOMPARE(l.first, covered);
            covered += l.second;
        }
        QCOMPARE(size_t(covered), bvh.primOrder.size());
        QVERIFY(bvh.wideDepth <= bvh.depth);
        if (s.boxes.size() > 1000) QVERIFY(bvh.wideDepth < bvh.depth);
        size_t inner = 0, used = 0;
        for (const BvhNode8& n : bvh.wideNodes) {
            ++inner;
            for (int k = 0; k < 8; ++k) used += n.child[k] != kNoHit;
        }

        const std::vector<TestRay> rays = makeRays(s, 300u + uint32_t(mesh), 50000);
        std::atomic<uint64_t> tDiffer{0}, tRounding{0}, anyDiffer{0}, otherTriangle{0}, hits{0};
        std::atomic<int> firstBad{-1};
        tbb::parallel_for(tbb::blocked_range<size_t>(0, rays.size(), 256), [&](const tbb::blocked_range<size_t>& range) {
            for (size_t i = range.begin(); i < range.end(); ++i) {
                const TestRay& r = rays[i];
                const Result a = bvhClosest(s, BvhView{bvh.nodes.data()}, bvh, r);
                const Result b = bvhClosest(s, BvhView8{bvh.wideNodes.data()}, bvh, r);
                const bool aa = bvhAny(s, BvhView{bvh.nodes.data()}, bvh, r);
                const bool ab = bvhAny(s, BvhView8{bvh.wideNodes.data()}, bvh, r);
                hits += a.prim != kNoHit;
                bool bad = false;
                if (!sameHit(a, b)) ++tDiffer, bad = true;
                else if (a.prim != b.prim) ++otherTriangle;
                if (std::memcmp(&a.t, &b.t, 4) != 0) ++tRounding;
                if (aa != ab) ++anyDiffer, bad = true;
                int expected = -1;
                if (bad) firstBad.compare_exchange_strong(expected, int(i));
            }
        });
        qInfo("%s, leaf block %d: %zu leaves; depth 4-wide %d, 8-wide %d; %zu 8-wide nodes, %.2f children each; "
              "%llu of %zu rays hit, %llu ties won by another triangle (%llu closest t differ in the last bits)",
              QTest::currentDataTag(), leafBlock, leaves8.size(), bvh.depth, bvh.wideDepth, inner,
              double(used) / double(std::max<size_t>(1, inner)), (unsigned long long)hits.load(), rays.size(),
              (unsigned long long)otherTriangle.load(), (unsigned long long)tRounding.load());
        if (firstBad >= 0) {
            qWarning("first differing ray %d: %s", firstBad.load(), qPrintable(rayText(rays[size_t(firstBad)])));
            const TestRay& r = rays[size_t(firstBad)];
            const Result a = bvhClosest(s, BvhView{bvh.nodes.data()}, bvh, r);
            const Result b = bvhClosest(s, BvhView8{bvh.wideNodes.data()}, bvh, r);
            const Result c = bruteClosest(s, r);
            qWarning("4-wide t %.9g prim %u; 8-wide t %.9g prim %u; brute t %.9g prim %u", a.t, a.prim, b.t, b.prim, c.t, c.prim);
        }
        QCOMPARE(tDiffer.load(), uint64_t(0));
        QCOMPARE(anyDiffer.load(), uint64_t(0));
        QVERIFY(hits > rays.size() / 10);
    }
}

QTEST_APPLESS_MAIN(TestKdTree)
#include "tst_kdtree.moc"
