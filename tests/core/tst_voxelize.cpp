// Tests of the triangle/box overlap test and the voxelizer against oracles and hand-computed grids.
#include <QTest>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <random>
#include <sstream>
#include <string>
#include <unordered_map>
#include <vector>

#include <tbb/global_control.h>

#include "core/base/error.h"
#include "core/base/progress.h"
#include "core/voxel/tri_box.h"
#include "core/voxel/voxelize.h"
#include "tests/common/files.h"

using namespace sylva;
using test::errorOf;

Q_DECLARE_METATYPE(glm::ivec3)

// Readable QCOMPARE failures for GLM vectors (found by argument-dependent lookup).
namespace glm {
char* toString(const ivec3& v)
{
    return QTest::toString(QString("(%1, %2, %3)").arg(v.x).arg(v.y).arg(v.z));
}
char* toString(const dvec3& v)
{
    return QTest::toString(QString("(%1, %2, %3)").arg(v.x, 0, 'g', 17).arg(v.y, 0, 'g', 17).arg(v.z, 0, 'g', 17));
}
} // namespace glm

namespace {

// ---- oracle for triangle / box overlap: Sutherland-Hodgman clip of the triangle by the 6 slabs ----
// The box is grown by `grow` on every side (negative shrinks); overlap <=> the clipped polygon is not empty.
bool clipOverlap(const glm::dvec3& c, const glm::dvec3& h, const glm::dvec3& v0, const glm::dvec3& v1,
                 const glm::dvec3& v2, double grow)
{
    std::vector<glm::dvec3> poly{v0, v1, v2}, out;
    for (int a = 0; a < 3; ++a)
        for (double side : {1.0, -1.0}) {
            out.clear();
            const size_t n = poly.size();
            for (size_t i = 0; i < n; ++i) {
                const glm::dvec3& cur = poly[i];
                const glm::dvec3& nxt = poly[(i + 1) % n];
                const double dc = side * (cur[a] - c[a]) - (h[a] + grow);
                const double dn = side * (nxt[a] - c[a]) - (h[a] + grow);
                if (dc <= 0.0) out.push_back(cur);
                if ((dc < 0.0 && dn > 0.0) || (dc > 0.0 && dn < 0.0)) out.push_back(cur + (nxt - cur) * (dc / (dc - dn)));
            }
            poly.swap(out);
            if (poly.empty()) return false;
        }
    return true;
}

Material material(const char* name, bool leaf)
{
    Material m;
    m.name = name;
    m.isLeaf = leaf;
    return m;
}

// ---- small meshes ----
struct MeshBuilder {
    TriangleMesh mesh;
    MeshBuilder()
    {
        mesh.materials.push_back(material("bark", false));
        mesh.materials.push_back(material("leaf", true));
    }
    void tri(glm::vec3 a, glm::vec3 b, glm::vec3 c, bool leaf = false)
    {
        const auto base = uint32_t(mesh.positions.size());
        mesh.positions.insert(mesh.positions.end(), {a, b, c});
        mesh.triangles.emplace_back(base, base + 1, base + 2);
        mesh.triangleMaterial.push_back(leaf ? 1u : 0u);
    }
    void quad(glm::vec3 a, glm::vec3 b, glm::vec3 c, glm::vec3 d, bool leaf = false)
    {
        tri(a, b, c, leaf);
        tri(a, c, d, leaf);
    }
    // Closed surface of the box [lo,hi]; woodFaceX0: the face x = lo.x is wood, the rest leaf.
    void box(glm::vec3 lo, glm::vec3 hi, bool woodFaceX0 = false, bool allLeaf = false)
    {
        auto p = [&](int x, int y, int z) { return glm::vec3(x ? hi.x : lo.x, y ? hi.y : lo.y, z ? hi.z : lo.z); };
        const bool leafRest = woodFaceX0 || allLeaf;
        quad(p(0, 0, 0), p(0, 1, 0), p(0, 1, 1), p(0, 0, 1), allLeaf);  // x = lo
        quad(p(1, 0, 0), p(1, 1, 0), p(1, 1, 1), p(1, 0, 1), leafRest);
        quad(p(0, 0, 0), p(1, 0, 0), p(1, 0, 1), p(0, 0, 1), leafRest);
        quad(p(0, 1, 0), p(1, 1, 0), p(1, 1, 1), p(0, 1, 1), leafRest);
        quad(p(0, 0, 0), p(1, 0, 0), p(1, 1, 0), p(0, 1, 0), leafRest);
        quad(p(0, 0, 1), p(1, 0, 1), p(1, 1, 1), p(0, 1, 1), leafRest);
    }
};

VoxelizeSettings explicitDims(glm::ivec3 dims, int subcells)
{
    VoxelizeSettings s;
    s.dims = dims;
    s.subcells = subcells;
    return s;
}

// Expected grid from a predicate over sub-cells (u,v,w) -> flags (1 marked, 2 wood), interior only.
void expectFromSubcells(const DensityGrid& grid, int sc, const std::function<int(int, int, int)>& flags)
{
    const GridGeometry& g = grid.geometry;
    const int sc3 = sc * sc * sc;
    for (int i = 0; i < g.dims.x; ++i)
        for (int j = 0; j < g.dims.y; ++j)
            for (int k = 0; k < g.dims.z; ++k) {
                int marked = 0, wood = 0;
                const bool interior = i > 0 && j > 0 && k > 0 && i < g.dims.x - 1 && j < g.dims.y - 1 && k < g.dims.z - 1;
                if (interior)
                    for (int a = 0; a < sc; ++a)
                        for (int b = 0; b < sc; ++b)
                            for (int c = 0; c < sc; ++c) {
                                const int f = flags(i * sc + a, j * sc + b, k * sc + c);
                                marked += (f & 1);
                                wood += (f & 2) ? 1 : 0;
                            }
                const size_t n = g.index(i, j, k);
                const float expDensity = float(marked) / float(sc3);
                const float expWood = marked ? float(wood) / float(marked) : 0.0f;
                if (grid.density[n] != expDensity || grid.woodFraction[n] != expWood) {
                    const QString msg = QString("node (%1,%2,%3): density %4 (expected %5), wood %6 (expected %7)")
                                            .arg(i).arg(j).arg(k)
                                            .arg(grid.density[n]).arg(expDensity)
                                            .arg(grid.woodFraction[n]).arg(expWood);
                    QFAIL(qPrintable(msg));
                }
            }
}

bool marginEmpty(const DensityGrid& grid)
{
    const GridGeometry& g = grid.geometry;
    for (int i = 0; i < g.dims.x; ++i)
        for (int j = 0; j < g.dims.y; ++j)
            for (int k = 0; k < g.dims.z; ++k) {
                const bool margin = i == 0 || j == 0 || k == 0 || i == g.dims.x - 1 || j == g.dims.y - 1 || k == g.dims.z - 1;
                if (margin && (grid.density[g.index(i, j, k)] != 0.0f || grid.woodFraction[g.index(i, j, k)] != 0.0f))
                    return false;
            }
    return true;
}

bool valuesInUnitRange(const DensityGrid& grid)
{
    for (size_t n = 0; n < grid.density.size(); ++n) {
        if (!(grid.density[n] >= 0.0f && grid.density[n] <= 1.0f)) return false;
        if (!(grid.woodFraction[n] >= 0.0f && grid.woodFraction[n] <= 1.0f)) return false;
        if (grid.density[n] == 0.0f && grid.woodFraction[n] != 0.0f) return false;
    }
    return true;
}

// Random tree-ish mesh: small leaf triangles in a ball, some long wood triangles, some degenerate ones.
TriangleMesh randomMesh(uint32_t seed, int count, int bigEvery = 50)
{
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> u(-1.0f, 1.0f);
    MeshBuilder b;
    for (int t = 0; t < count; ++t) {
        glm::vec3 c(u(rng), u(rng), u(rng));
        c *= 3.0f;
        const float size = (t % bigEvery == 0) ? 2.0f : 0.15f;
        glm::vec3 p1 = c + size * glm::vec3(u(rng), u(rng), u(rng));
        glm::vec3 p2 = c + size * glm::vec3(u(rng), u(rng), u(rng));
        if (t % 97 == 0) p2 = c + 0.3f * (p1 - c);  // collinear
        if (t % 131 == 0) p1 = p2 = c;            // point
        b.tri(c, p1, p2, t % 3 != 0);
    }
    return b.mesh;
}

// Straightforward voxelizer: every triangle against every interior sub-cell of its bounds, one thread.
// Uses the same sub-cell coordinates as voxelize (double from the bounds corner, rounded to float).
DensityGrid naiveVoxelize(const TriangleMesh& mesh, const VoxelizeSettings& settings)
{
    const Bounds3 bounds = meshBounds(mesh);
    DensityGrid grid;
    grid.geometry = gridForMesh(bounds, settings);
    const GridGeometry& g = grid.geometry;
    const int sc = settings.subcells;
    const double scale = double(sc) / g.spacing;
    std::unordered_map<uint64_t, uint8_t> flags;
    const glm::ivec3 nsub = g.dims * sc;
    for (size_t t = 0; t < mesh.triangles.size(); ++t) {
        glm::vec3 p[3];
        for (int c = 0; c < 3; ++c)
            for (int a = 0; a < 3; ++a) {
                const double offset = (double(bounds.lo[a]) - (g.origin[a] - 0.5 * g.spacing)) * scale;
                p[c][a] = float((double(mesh.positions[mesh.triangles[t][c]][a]) - double(bounds.lo[a])) * scale + offset);
            }
        const glm::vec3 bmin = glm::min(p[0], glm::min(p[1], p[2])), bmax = glm::max(p[0], glm::max(p[1], p[2]));
        // floor - 1 (not ceil - 1): one sub-cell more than needed where bmin is not an integer.
        const glm::ivec3 lo = glm::max(glm::ivec3(glm::floor(bmin)) - 1, glm::ivec3(sc));
        const glm::ivec3 hi = glm::min(glm::ivec3(glm::floor(bmax)), nsub - sc - 1);
        const uint8_t bits = mesh.isLeafTriangle(t) ? 1 : 3;
        for (int x = lo.x; x <= hi.x; ++x)
            for (int y = lo.y; y <= hi.y; ++y)
                for (int z = lo.z; z <= hi.z; ++z)
                    if (triBoxOverlap(glm::vec3(x, y, z) + 0.5f, glm::vec3(0.5f), p[0], p[1], p[2]))
                        flags[(uint64_t(x) * uint64_t(nsub.y) + uint64_t(y)) * uint64_t(nsub.z) + uint64_t(z)] |= bits;
    }
    std::vector<int> marked(g.nodeCount(), 0), wood(g.nodeCount(), 0);
    for (const auto& [key, f] : flags) {
        const int z = int(key % uint64_t(nsub.z)), y = int((key / uint64_t(nsub.z)) % uint64_t(nsub.y));
        const int x = int(key / (uint64_t(nsub.z) * uint64_t(nsub.y)));
        const size_t n = g.index(x / sc, y / sc, z / sc);
        marked[n] += f & 1;
        wood[n] += f >> 1;
    }
    grid.density.resize(g.nodeCount());
    grid.woodFraction.resize(g.nodeCount());
    for (size_t n = 0; n < g.nodeCount(); ++n) {
        grid.density[n] = float(marked[n]) / float(sc * sc * sc);
        grid.woodFraction[n] = marked[n] ? float(wood[n]) / float(marked[n]) : 0.0f;
    }
    return grid;
}

// Tiny OBJ reader: v and f lines (v, v/vt, v/vt/vn, v//vn, negative indices), polygons fan-triangulated;
// `usemtl` names containing "leaf"/"leaves" (any case) make leaf triangles, others wood.
bool readObj(const std::string& path, TriangleMesh& mesh)
{
    std::ifstream in(path);
    if (!in) return false;
    mesh = TriangleMesh();
    mesh.materials.push_back(material("wood", false));
    mesh.materials.push_back(material("leaf", true));
    uint32_t currentMaterial = 0;
    std::string line;
    while (std::getline(in, line)) {
        std::istringstream ls(line);
        std::string tag;
        ls >> tag;
        if (tag == "v") {
            glm::vec3 p;
            ls >> p.x >> p.y >> p.z;
            mesh.positions.push_back(p);
        } else if (tag == "usemtl") {
            std::string name;
            ls >> name;
            std::transform(name.begin(), name.end(), name.begin(), [](unsigned char c) { return char(std::tolower(c)); });
            currentMaterial = name.find("lea") != std::string::npos ? 1u : 0u;
        } else if (tag == "f") {
            std::vector<uint32_t> idx;
            std::string tok;
            while (ls >> tok) {
                const long i = std::stol(tok.substr(0, tok.find('/')));
                idx.push_back(uint32_t(i > 0 ? i - 1 : long(mesh.positions.size()) + i));
            }
            for (size_t k = 2; k < idx.size(); ++k) {
                mesh.triangles.emplace_back(idx[0], idx[k - 1], idx[k]);
                mesh.triangleMaterial.push_back(currentMaterial);
            }
        }
    }
    return !mesh.triangles.empty();
}


} // namespace

class TestVoxelize : public QObject {
    Q_OBJECT

private Q_SLOTS:
    void triBoxMatchesClipOracle();
    void triBoxHandCases();
    void triBoxDegenerate();
    void oneTriangleSubcells1();
    void oneTriangleSubcells3();
    void cubeShell();
    void triangleOnCellFace();
    void woodFraction();
    void gridGeometryAuto();
    void gridGeometryExplicit();
    void flatMesh();
    void densityInUnitRange();
    void matchesNaiveVoxelizer_data();
    void matchesNaiveVoxelizer();
    void largeTrianglesNearAxisPlanes();
    void deterministicAcrossThreads();
    void progressAndCancel();
    void badInput();
    void realTree();
};

void TestVoxelize::triBoxMatchesClipOracle()
{
    std::mt19937 rng(12345);
    std::uniform_real_distribution<double> u(-1.0, 1.0), pos(0.0, 1.0);
    int overlaps = 0, separated = 0, ambiguous = 0;
    const int cases = 200000;
    for (int n = 0; n < cases; ++n) {
        const glm::dvec3 c(u(rng), u(rng), u(rng));
        const glm::dvec3 h(0.05 + pos(rng), 0.05 + pos(rng), 0.05 + pos(rng));
        auto rp = [&](double scale) { return c + scale * glm::dvec3(u(rng), u(rng), u(rng)); };
        glm::dvec3 v0, v1, v2;
        switch (n % 6) {
        case 0: v0 = rp(2.5); v1 = rp(2.5); v2 = rp(2.5); break;            // large
        case 1: v0 = rp(1.2); v1 = v0 + 0.3 * glm::dvec3(u(rng), u(rng), u(rng)); v2 = v0 + 0.3 * glm::dvec3(u(rng), u(rng), u(rng)); break;  // small
        case 2: v0 = rp(2.0); v1 = rp(2.0); v2 = v1 + 1e-3 * glm::dvec3(u(rng), u(rng), u(rng)); break;  // sliver
        case 3: v0 = rp(2.0); v1 = rp(2.0); v2 = v0 + pos(rng) * (v1 - v0); break;  // collinear
        case 4: v0 = rp(1.5); v1 = v0; v2 = rp(1.5); break;                // segment with a repeated vertex
        default: v0 = rp(1.0); v1 = v0; v2 = v0; break;                    // point
        }
        // Round the inputs to float first so the oracle sees exactly what tri_box sees.
        const glm::vec3 fc(c), fh(h), f0(v0), f1(v1), f2(v2);
        const glm::dvec3 dc(fc), dh(fh), d0(f0), d1(f1), d2(f2);
        const bool grown = clipOverlap(dc, dh, d0, d1, d2, 1e-4);
        const bool shrunk = clipOverlap(dc, dh, d0, d1, d2, -1e-4);
        if (grown != shrunk) {
            ++ambiguous;
            continue;
        }
        const bool got = triBoxOverlap(fc, fh, f0, f1, f2);
        const bool gotSat = triBoxSatOverlaps(triBoxPrepare(f0, f1, f2, fh), fc);  // untranslated frame
        if (got != grown || gotSat != grown) {
            const QString msg = QString("case %1 (kind %2): oracle %3, triBoxOverlap %4, prepared %5")
                                    .arg(n).arg(n % 6).arg(grown).arg(got).arg(gotSat);
            QFAIL(qPrintable(msg));
        }
        (grown ? overlaps : separated)++;
    }
    qInfo("tri_box vs clip oracle: %d overlapping, %d separated, %d ambiguous (within 1e-4) skipped",
          overlaps, separated, ambiguous);
    QVERIFY(overlaps > cases / 5);
    QVERIFY(separated > cases / 5);
    QVERIFY(ambiguous < cases / 100);
}

void TestVoxelize::triBoxHandCases()
{
    const glm::vec3 c(0.0f), h(1.0f);
    // Closed box: a vertex exactly on a face, an edge on an edge, a triangle in a face plane all overlap.
    QVERIFY(triBoxOverlap(c, h, {1, 0, 0}, {3, 0, 0}, {3, 1, 0}));
    QVERIFY(!triBoxOverlap(c, h, {1.001f, 0, 0}, {3, 0, 0}, {3, 1, 0}));
    QVERIFY(triBoxOverlap(c, h, {1, 1, -3}, {1, 1, 3}, {3, 3, 0}));
    QVERIFY(triBoxOverlap(c, h, {1, -0.5f, -0.5f}, {1, 0.5f, -0.5f}, {1, 0, 0.5f}));
    QVERIFY(!triBoxOverlap(c, h, {1.01f, -0.5f, -0.5f}, {1.01f, 0.5f, -0.5f}, {1.01f, 0, 0.5f}));
    // A large triangle through the box with every vertex outside: only its plane meets the box.
    QVERIFY(triBoxOverlap(c, h, {-10, -10, 0.5f}, {10, -10, 0.5f}, {0, 10, 0.5f}));
    // Bounds overlap but the triangle plane misses the corner: x + y + z = 3.2 (corner at 3).
    QVERIFY(!triBoxOverlap(c, h, {3.2f, 0, 0}, {0, 3.2f, 0}, {0, 0, 3.2f}));
    QVERIFY(triBoxOverlap(c, h, {3.0f, 0, 0}, {0, 3.0f, 0}, {0, 0, 3.0f}));  // touches the corner
    // Bounds and plane overlap, only an edge x axis separates: the triangle passes by an edge of the box.
    // Triangle in the plane z = 0 with edge x + y = 2.1 facing the box corner (1,1).
    QVERIFY(!triBoxOverlap(c, h, {2.1f, 0, 0}, {0, 2.1f, 0}, {5, 5, 0}));
    QVERIFY(triBoxOverlap(c, h, {2.0f, 0, 0}, {0, 2.0f, 0}, {5, 5, 0}));
    // Tilted version: plane through the box, an edge passes the box edge (1,1,z) diagonally.
    QVERIFY(!triBoxOverlap(c, h, {2.1f, 0, -1.5f}, {0, 2.1f, 1.5f}, {5, 5, 0}));
    // Non-cubic box away from the origin.
    QVERIFY(triBoxOverlap({10, 20, 30}, {0.5f, 2, 0.1f}, {10.4f, 18.1f, 30}, {20, 18.1f, 30}, {10.4f, 30, 30}));
    QVERIFY(!triBoxOverlap({10, 20, 30}, {0.5f, 2, 0.1f}, {10.6f, 18.1f, 30}, {20, 18.1f, 30}, {10.6f, 30, 30}));
}

void TestVoxelize::triBoxDegenerate()
{
    const glm::vec3 c(0.0f), h(1.0f);
    // Points.
    QVERIFY(triBoxOverlap(c, h, {0.5f, 0.5f, 0.5f}, {0.5f, 0.5f, 0.5f}, {0.5f, 0.5f, 0.5f}));
    QVERIFY(triBoxOverlap(c, h, {1, 1, 1}, {1, 1, 1}, {1, 1, 1}));
    QVERIFY(!triBoxOverlap(c, h, {1.01f, 0, 0}, {1.01f, 0, 0}, {1.01f, 0, 0}));
    // Segments through the box with both ends outside, and segments that pass a box edge.
    QVERIFY(triBoxOverlap(c, h, {-5, 0.2f, 0.3f}, {5, 0.2f, 0.3f}, {5, 0.2f, 0.3f}));
    QVERIFY(triBoxOverlap(c, h, {-3, -3, -3}, {3, 3, 3}, {0, 0, 0}));
    QVERIFY(!triBoxOverlap(c, h, {2.1f, 0, 0.2f}, {0, 2.1f, 0.2f}, {2.1f, 0, 0.2f}));  // x + y = 2.1 misses (1,1)
    QVERIFY(triBoxOverlap(c, h, {2.0f, 0, 0.2f}, {0, 2.0f, 0.2f}, {1.0f, 1.0f, 0.2f}));
    QVERIFY(!triBoxOverlap(c, h, {3, 0, -0.5f}, {0, 3, 0.5f}, {1.5f, 1.5f, 0}));  // skew segment, misses
}

void TestVoxelize::oneTriangleSubcells1()
{
    // Triangle A=(0,0,0), B=(6,0,0), C=(0,6,6): points (x, y, y) with x, y >= 0 and x + y <= 6.
    // dims 8 -> spacing 1, origin -0.5: node i owns the cell [i-1, i] on each axis. By hand, the
    // cell (i,j,k) meets the triangle iff it holds a point with y = z (|j - k| <= 1) and its lowest
    // x + y, (i - 1) + max(j, k) - 1, is <= 6 (closed cells: touching the edge BC counts).
    MeshBuilder b;
    b.tri({0, 0, 0}, {6, 0, 0}, {0, 6, 6});
    const DensityGrid grid = voxelize(b.mesh, explicitDims({8, 8, 8}, 1));
    QCOMPARE(grid.geometry.spacing, 1.0);
    QCOMPARE(grid.geometry.origin, glm::dvec3(-0.5));
    auto at = [&](int i, int j, int k) { return grid.density[grid.geometry.index(i, j, k)]; };
    QCOMPARE(at(1, 1, 1), 1.0f);
    QCOMPARE(at(1, 1, 2), 1.0f);
    QCOMPARE(at(1, 1, 3), 0.0f);  // |j - k| = 2
    QCOMPARE(at(6, 2, 2), 1.0f);  // touches edge BC at (5,1,1)
    QCOMPARE(at(6, 2, 3), 0.0f);  // lowest x + y is 5 + 2 = 7
    QCOMPARE(at(1, 6, 6), 1.0f);  // contains C
    QCOMPARE(at(6, 1, 1), 1.0f);  // contains B
    int count = 0;
    for (int i = 0; i < 8; ++i)
        for (int j = 0; j < 8; ++j)
            for (int k = 0; k < 8; ++k) {
                const bool inside = i >= 1 && i <= 6 && j >= 1 && j <= 6 && k >= 1 && k <= 6;
                const bool expected = inside && std::abs(j - k) <= 1 && i + std::max(j, k) <= 8;
                QCOMPARE(at(i, j, k), expected ? 1.0f : 0.0f);
                count += expected;
            }
    QCOMPARE(count, 66);
    for (float w : grid.woodFraction) QVERIFY(w == 0.0f || w == 1.0f);  // a wood triangle
}

void TestVoxelize::oneTriangleSubcells3()
{
    // Same triangle with 3x3x3 sub-cells: sub-cell coordinates are (p + 1) * 3, so the triangle is
    // (3,3,3), (21,3,3), (3,21,21) and sub-cell (u,v,w) is marked iff |v - w| <= 1 and u + max(v,w) <= 24,
    // within the interior sub-cells 3..20.
    MeshBuilder b;
    b.tri({0, 0, 0}, {6, 0, 0}, {0, 6, 6});
    const DensityGrid grid = voxelize(b.mesh, explicitDims({8, 8, 8}, 3));
    expectFromSubcells(grid, 3, [](int u, int v, int w) {
        const bool in = u >= 3 && u <= 20 && v >= 3 && v <= 20 && w >= 3 && w <= 20;
        return (in && std::abs(v - w) <= 1 && u + std::max(v, w) <= 24) ? 3 : 0;
    });
    QCOMPARE(grid.density[grid.geometry.index(1, 1, 1)], 21.0f / 27.0f);  // u 3..5, v=w or |v-w|=1 in 3..5: 3 * 7
}

void TestVoxelize::cubeShell()
{
    // Cube surface [0,6]^3, dims 8 -> sub-cell faces at 3 and 21. The faces lie on sub-cell faces; the
    // outer side of each is a margin sub-cell (never marked), so the shell is the one sub-cell layer
    // u, v or w in {3, 20} of the interior sub-cells 3..20, and the interior 4..19 is empty.
    MeshBuilder b;
    b.box({0, 0, 0}, {6, 6, 6});
    const DensityGrid grid = voxelize(b.mesh, explicitDims({8, 8, 8}, 3));
    QVERIFY(marginEmpty(grid));
    auto shell = [](int u, int v, int w) {
        auto in = [](int x) { return x >= 3 && x <= 20; };
        auto face = [](int x) { return x == 3 || x == 20; };
        return (in(u) && in(v) && in(w) && (face(u) || face(v) || face(w))) ? 3 : 0;
    };
    expectFromSubcells(grid, 3, shell);
    const GridGeometry& g = grid.geometry;
    QCOMPARE(grid.density[g.index(1, 3, 3)], 9.0f / 27.0f);   // face
    QCOMPARE(grid.density[g.index(1, 1, 3)], 15.0f / 27.0f);  // edge
    QCOMPARE(grid.density[g.index(1, 1, 1)], 19.0f / 27.0f);  // corner
    QCOMPARE(grid.density[g.index(6, 6, 6)], 19.0f / 27.0f);
    for (int i = 2; i <= 5; ++i)
        for (int j = 2; j <= 5; ++j)
            for (int k = 2; k <= 5; ++k) QCOMPARE(grid.density[g.index(i, j, k)], 0.0f);

    // One sub-cell per cell: the shell is the outer layer of interior nodes.
    const DensityGrid coarse = voxelize(b.mesh, explicitDims({8, 8, 8}, 1));
    for (int i = 1; i <= 6; ++i)
        for (int j = 1; j <= 6; ++j)
            for (int k = 1; k <= 6; ++k) {
                const bool onShell = i == 1 || i == 6 || j == 1 || j == 6 || k == 1 || k == 6;
                QCOMPARE(coarse.density[g.index(i, j, k)], onShell ? 1.0f : 0.0f);
            }
    QVERIFY(marginEmpty(coarse));
}

void TestVoxelize::triangleOnCellFace()
{
    // The cube shell sets the grid (spacing 1, sub-cell coordinate (p + 1) * 3). A square in the plane
    // x = 3 (sub-cell 12, the face shared by the cells of nodes 3 and 4) spanning y, z in [1.5, 4.5]
    // (sub-cells 7..16): closed sub-cells, so both sides u = 11 (node 3) and u = 12 (node 4) are marked.
    MeshBuilder b;
    b.box({0, 0, 0}, {6, 6, 6});
    b.quad({3, 1.5f, 1.5f}, {3, 4.5f, 1.5f}, {3, 4.5f, 4.5f}, {3, 1.5f, 4.5f});
    const DensityGrid grid = voxelize(b.mesh, explicitDims({8, 8, 8}, 3));
    expectFromSubcells(grid, 3, [](int u, int v, int w) {
        auto in = [](int x) { return x >= 3 && x <= 20; };
        auto face = [](int x) { return x == 3 || x == 20; };
        const bool shell = in(u) && in(v) && in(w) && (face(u) || face(v) || face(w));
        const bool square = (u == 11 || u == 12) && v >= 7 && v <= 16 && w >= 7 && w <= 16;
        return (shell || square) ? 3 : 0;
    });
    const GridGeometry& g = grid.geometry;
    QCOMPARE(grid.density[g.index(3, 3, 3)], 9.0f / 27.0f);
    QCOMPARE(grid.density[g.index(4, 3, 3)], 9.0f / 27.0f);
    QCOMPARE(grid.density[g.index(3, 2, 2)], 4.0f / 27.0f);  // v, w in {7, 8}
    QCOMPARE(grid.density[g.index(2, 3, 3)], 0.0f);
    QCOMPARE(grid.density[g.index(5, 3, 3)], 0.0f);

    // With one sub-cell per cell the same face marks whole cells on both sides.
    const DensityGrid coarse = voxelize(b.mesh, explicitDims({8, 8, 8}, 1));
    for (int j = 2; j <= 5; ++j)
        for (int k = 2; k <= 5; ++k) {
            QCOMPARE(coarse.density[g.index(3, j, k)], 1.0f);
            QCOMPARE(coarse.density[g.index(4, j, k)], 1.0f);
            QCOMPARE(coarse.density[g.index(2, j, k)], 0.0f);
        }
}

void TestVoxelize::woodFraction()
{
    // Cube shell whose face x = 0 (sub-cell layer u = 3) is wood and the other faces leaf. A sub-cell
    // on the edge between the wood face and a leaf face is touched by both and counts as wood.
    MeshBuilder b;
    b.box({0, 0, 0}, {6, 6, 6}, /*woodFaceX0=*/true);
    const DensityGrid grid = voxelize(b.mesh, explicitDims({8, 8, 8}, 3));
    expectFromSubcells(grid, 3, [](int u, int v, int w) {
        auto in = [](int x) { return x >= 3 && x <= 20; };
        auto face = [](int x) { return x == 3 || x == 20; };
        if (!(in(u) && in(v) && in(w) && (face(u) || face(v) || face(w)))) return 0;
        return u == 3 ? 3 : 1;
    });
    const GridGeometry& g = grid.geometry;
    QCOMPARE(grid.woodFraction[g.index(1, 3, 3)], 1.0f);           // wood face only
    QCOMPARE(grid.woodFraction[g.index(1, 1, 3)], 9.0f / 15.0f);   // wood face + one leaf face
    QCOMPARE(grid.woodFraction[g.index(1, 1, 1)], 9.0f / 19.0f);   // corner
    QCOMPARE(grid.woodFraction[g.index(2, 1, 3)], 0.0f);           // leaf only
    QCOMPARE(grid.woodFraction[g.index(3, 3, 3)], 0.0f);           // empty
    QCOMPARE(grid.woodFraction[g.index(0, 3, 3)], 0.0f);           // margin

    // A mesh without materials is all wood; an all-leaf mesh has wood fraction 0.
    TriangleMesh plain = b.mesh;
    plain.triangleMaterial.clear();
    plain.materials.clear();
    const DensityGrid plainGrid = voxelize(plain, explicitDims({8, 8, 8}, 3));
    for (size_t n = 0; n < plainGrid.density.size(); ++n)
        QCOMPARE(plainGrid.woodFraction[n], plainGrid.density[n] > 0.0f ? 1.0f : 0.0f);
    MeshBuilder leafy;
    leafy.box({0, 0, 0}, {6, 6, 6}, false, /*allLeaf=*/true);
    const DensityGrid leafGrid = voxelize(leafy.mesh, explicitDims({8, 8, 8}, 3));
    QVERIFY(leafGrid.density == grid.density);
    for (float w : leafGrid.woodFraction) QCOMPARE(w, 0.0f);
}

void TestVoxelize::gridGeometryAuto()
{
    // Box extent (4, 2, 1), "--grid 128": spacing 4/126; y needs ceil(2 / s) = 63 interior nodes,
    // z ceil(1 / s) = 32 (31.5 cells).
    Bounds3 bounds;
    bounds.extend({1, 2, 3});
    bounds.extend({5, 4, 4});
    VoxelizeSettings s;
    GridGeometry g = gridForMesh(bounds, s);
    QCOMPARE(g.dims, glm::ivec3(128, 65, 34));
    QCOMPARE(g.spacing, 4.0 / 126.0);
    const glm::dvec3 centre(3.0, 3.0, 3.5);
    for (int a = 0; a < 3; ++a) {
        QVERIFY(std::abs(g.origin[a] + 0.5 * g.spacing * (g.dims[a] - 1) - centre[a]) < 1e-12);
        // Interior cells cover the bounds (up to rounding); one fewer node would not.
        QVERIFY(g.origin[a] + 0.5 * g.spacing <= double(bounds.lo[a]) + 1e-12);
        QVERIFY(g.origin[a] + (g.dims[a] - 1.5) * g.spacing >= double(bounds.hi[a]) - 1e-12);
        QVERIFY((g.dims[a] - 3) * g.spacing < double(bounds.hi[a] - bounds.lo[a]));
    }
    QCOMPARE(g.origin.x, 1.0 - 0.5 * g.spacing);  // node 1's cell starts at the bounds

    // --grid N for a few N, and a cube, whose three axes all get N.
    s.longestAxisNodes = 3;
    QCOMPARE(gridForMesh(bounds, s).dims, glm::ivec3(3, 3, 3));
    s.longestAxisNodes = 10;
    QCOMPARE(gridForMesh(bounds, s).dims, glm::ivec3(10, 6, 4));  // 8 cells of 0.5: y 4, z 2
    s.longestAxisNodes = 512;
    QCOMPARE(gridForMesh(bounds, s).dims, glm::ivec3(512, 257, 130));
    Bounds3 cube;
    cube.extend({-0.3f, -0.3f, -0.3f});
    cube.extend({0.7f, 0.7f, 0.7f});
    s.longestAxisNodes = 64;
    QCOMPARE(gridForMesh(cube, s).dims, glm::ivec3(64));

    // Voxelized: margins empty, the longest axis filled edge to edge.
    MeshBuilder b;
    b.box({1, 2, 3}, {5, 4, 4});
    s.longestAxisNodes = 32;
    const DensityGrid grid = voxelize(b.mesh, s);
    QCOMPARE(grid.geometry, gridForMesh(meshBounds(b.mesh), s));
    QVERIFY(marginEmpty(grid));
    QVERIFY(grid.density[grid.geometry.index(1, 1, 1)] > 0.0f);
    QVERIFY(grid.density[grid.geometry.index(30, 1, 1)] > 0.0f);
}

void TestVoxelize::gridGeometryExplicit()
{
    // dims 3: one interior node whose cell is the cube; its shell marks 26 of 27 sub-cells.
    MeshBuilder cube;
    cube.box({0, 0, 0}, {6, 6, 6});
    const DensityGrid small = voxelize(cube.mesh, explicitDims({3, 3, 3}, 3));
    QCOMPARE(small.geometry.spacing, 6.0);
    QCOMPARE(small.geometry.origin, glm::dvec3(-3.0));
    QCOMPARE(small.density[small.geometry.index(1, 1, 1)], 26.0f / 27.0f);
    QVERIFY(marginEmpty(small));

    // 512 x 8 x 8 for a rod of extent (10, 1, 1): spacing = max(10/510, 1/6, 1/6) = 1/6, centred.
    MeshBuilder rod;
    rod.box({0, 0, 0}, {10, 1, 1});
    const DensityGrid grid = voxelize(rod.mesh, explicitDims({512, 8, 8}, 3));
    const GridGeometry& g = grid.geometry;
    QCOMPARE(g.dims, glm::ivec3(512, 8, 8));
    QCOMPARE(g.spacing, 1.0 / 6.0);
    QVERIFY(std::abs(g.origin.x - (5.0 - 511.0 / 12.0)) < 1e-12);
    QVERIFY(std::abs(g.origin.y - (0.5 - 7.0 / 12.0)) < 1e-12);
    QVERIFY(marginEmpty(grid));
    QVERIFY(valuesInUnitRange(grid));
    // The rod (60 cells long) sits in the middle of the 510 interior cells along x.
    double mass = 0.0;
    for (int i = 0; i < 512; ++i)
        for (int j = 0; j < 8; ++j)
            for (int k = 0; k < 8; ++k) {
                const float d = grid.density[g.index(i, j, k)];
                mass += d;
                if (d > 0.0f) QVERIFY(i >= 225 && i <= 286);
            }
    QVERIFY(mass > 0.0);
    QCOMPARE(grid.density[g.index(256, 1, 3)], grid.density[g.index(256, 6, 3)]);  // symmetric in y
}

void TestVoxelize::flatMesh()
{
    // A square in the plane z = 0.5 (zero extent in z): 3 nodes along z, the plane through the middle
    // sub-cell layer of node k = 1, so every interior node with k = 1 has density 9/27.
    MeshBuilder b;
    b.quad({0, 0, 0.5f}, {2, 0, 0.5f}, {2, 2, 0.5f}, {0, 2, 0.5f});
    VoxelizeSettings s;
    s.longestAxisNodes = 10;
    const DensityGrid grid = voxelize(b.mesh, s);
    const GridGeometry& g = grid.geometry;
    QCOMPARE(g.dims, glm::ivec3(10, 10, 3));
    QCOMPARE(g.spacing, 0.25);
    QCOMPARE(g.origin.z, 0.25);
    for (int i = 0; i < 10; ++i)
        for (int j = 0; j < 10; ++j)
            for (int k = 0; k < 3; ++k) {
                const bool filled = i >= 1 && i <= 8 && j >= 1 && j <= 8 && k == 1;
                QCOMPARE(grid.density[g.index(i, j, k)], filled ? 9.0f / 27.0f : 0.0f);
            }

    // Flat in x (a single slab of nodes), with 2 sub-cells the plane lies on the sub-cell face in the
    // middle of node i = 1 and marks both sub-cell layers (closed sub-cells): density 1.
    MeshBuilder wall;
    wall.quad({1, 0, 0}, {1, 2, 0}, {1, 2, 2}, {1, 0, 2});
    s.subcells = 2;
    const DensityGrid wallGrid = voxelize(wall.mesh, s);
    QCOMPARE(wallGrid.geometry.dims, glm::ivec3(3, 10, 10));
    QCOMPARE(wallGrid.density[wallGrid.geometry.index(1, 4, 4)], 1.0f);
    QCOMPARE(wallGrid.density[wallGrid.geometry.index(1, 8, 8)], 1.0f);
    QVERIFY(marginEmpty(wallGrid));
}

void TestVoxelize::densityInUnitRange()
{
    const TriangleMesh mesh = randomMesh(7, 20000);
    for (int sc : {1, 3, 5}) {
        VoxelizeSettings s;
        s.longestAxisNodes = 40;
        s.subcells = sc;
        const DensityGrid grid = voxelize(mesh, s);
        QVERIFY(valuesInUnitRange(grid));
        QVERIFY(marginEmpty(grid));
        const float maxDensity = *std::max_element(grid.density.begin(), grid.density.end());
        QVERIFY(maxDensity > 0.5f);
        QVERIFY(maxDensity <= 1.0f);
    }
}

void TestVoxelize::matchesNaiveVoxelizer_data()
{
    QTest::addColumn<int>("triangles");
    QTest::addColumn<int>("subcells");
    QTest::addColumn<glm::ivec3>("dims");
    QTest::addColumn<int>("bigEvery");
    QTest::newRow("auto 24, 1 sub-cell") << 3000 << 1 << glm::ivec3(0) << 50;
    QTest::newRow("auto 24, 3 sub-cells") << 3000 << 3 << glm::ivec3(0) << 50;
    QTest::newRow("explicit 20x9x30, 4 sub-cells") << 1500 << 4 << glm::ivec3(20, 9, 30) << 50;
    // 16^3 sub-cells and 198 interior z nodes: 811 kB of flags per y row, so 16 MB tiles split the 22 y rows.
    QTest::newRow("explicit 6x24x200, 16 sub-cells") << 60 << 16 << glm::ivec3(6, 24, 200) << 50;
    // Only large triangles (ranges of more than 16 sub-cells per axis: the column / plane-interval path).
    QTest::newRow("auto 40, 2 sub-cells, large triangles") << 40 << 2 << glm::ivec3(0) << 1;
}

void TestVoxelize::matchesNaiveVoxelizer()
{
    QFETCH(int, triangles);
    QFETCH(int, subcells);
    QFETCH(glm::ivec3, dims);
    QFETCH(int, bigEvery);
    const TriangleMesh mesh = randomMesh(uint32_t(triangles + subcells), triangles, bigEvery);
    VoxelizeSettings s;
    s.dims = dims;
    s.longestAxisNodes = bigEvery == 1 ? 40 : 24;
    s.subcells = subcells;
    const DensityGrid fast = voxelize(mesh, s);
    const DensityGrid naive = naiveVoxelize(mesh, s);
    QCOMPARE(fast.geometry, naive.geometry);
    QVERIFY(fast.density == naive.density);
    QVERIFY(fast.woodFraction == naive.woodFraction);
    QVERIFY(*std::max_element(fast.density.begin(), fast.density.end()) > 0.0f);
}

void TestVoxelize::largeTrianglesNearAxisPlanes()
{
    // Large triangles whose normals have a zero or tiny z component (the per-column plane interval
    // degenerates), or lie in axis planes, against the straightforward voxelizer. Coordinates are
    // generic so that no exact touching (where rounding may decide either way) occurs.
    MeshBuilder b;
    b.tri({0.113f, 0.271f, 0.05f}, {4.871f, 4.323f, 0.42f}, {0.113f, 0.271f, 4.93f});          // normal.z = 0
    b.tri({0.337f, 4.913f, 0.021f}, {4.957f, 0.291f, 0.021f}, {0.33701f, 4.913f, 4.97f}, true); // tiny normal.z
    b.tri({0.05f, 0.2f, 2.4731f}, {4.97f, 0.23f, 2.4731f}, {0.1f, 4.9f, 2.4731f});            // horizontal
    b.tri({4.6813f, 0.07f, 0.09f}, {4.6813f, 4.93f, 0.11f}, {4.6813f, 0.12f, 4.91f}, true);   // x = const
    b.tri({0.021f, 0.033f, 4.987f}, {4.991f, 3.117f, 4.013f}, {2.019f, 4.977f, 0.017f});      // oblique
    for (int sc : {1, 2, 3}) {
        VoxelizeSettings s;
        s.longestAxisNodes = 40;
        s.subcells = sc;
        const DensityGrid fast = voxelize(b.mesh, s);
        const DensityGrid naive = naiveVoxelize(b.mesh, s);
        QVERIFY(fast.density == naive.density);
        QVERIFY(fast.woodFraction == naive.woodFraction);
        QVERIFY(marginEmpty(fast));
    }
}

void TestVoxelize::deterministicAcrossThreads()
{
    const TriangleMesh mesh = randomMesh(99, 40000);
    VoxelizeSettings s;
    s.longestAxisNodes = 64;
    DensityGrid one, two;
    {
        tbb::global_control limit(tbb::global_control::max_allowed_parallelism, 1);
        one = voxelize(mesh, s);
    }
    {
        tbb::global_control limit(tbb::global_control::max_allowed_parallelism, 2);
        two = voxelize(mesh, s);
    }
    const DensityGrid again = voxelize(mesh, s);
    QVERIFY(one.density == two.density);
    QVERIFY(one.woodFraction == two.woodFraction);
    QVERIFY(one.density == again.density);
    QVERIFY(one.woodFraction == again.woodFraction);
}

void TestVoxelize::progressAndCancel()
{
    const TriangleMesh mesh = randomMesh(5, 20000);
    VoxelizeSettings s;
    s.longestAxisNodes = 64;
    std::vector<double> fractions;
    Progress progress([&](double f, const std::string&) { fractions.push_back(f); });
    voxelize(mesh, s, &progress);
    QVERIFY(fractions.size() >= 5);
    QVERIFY(fractions.size() <= 60);
    QCOMPARE(fractions.front(), 0.0);
    QCOMPARE(fractions.back(), 1.0);
    QVERIFY(std::is_sorted(fractions.begin(), fractions.end()));

    Progress cancelling;
    cancelling.setCallback([&](double f, const std::string&) {
        if (f >= 0.3) cancelling.cancel();
    });
    bool cancelled = false;
    try {
        voxelize(mesh, s, &cancelling);
    } catch (const Cancelled&) {
        cancelled = true;
    }
    QVERIFY(cancelled);
}

void TestVoxelize::badInput()
{
    MeshBuilder b;
    b.box({0, 0, 0}, {1, 2, 3});
    const TriangleMesh good = b.mesh;
    auto expectError = [&](const TriangleMesh& mesh, const VoxelizeSettings& s, const char* fragment) {
        const std::string msg = errorOf([&] { voxelize(mesh, s); });
        if (msg.find(fragment) == std::string::npos)
            QFAIL(qPrintable(QString("expected an error containing '%1', got '%2'").arg(fragment, msg.c_str())));
    };
    expectError(good, explicitDims({2, 8, 8}, 3), "grid size along x is 2, must be in 3..512");
    expectError(good, explicitDims({8, 513, 8}, 3), "grid size along y is 513");
    VoxelizeSettings s;
    s.longestAxisNodes = 2;
    expectError(good, s, "longest axis is 2");
    s.longestAxisNodes = 600;
    expectError(good, s, "longest axis is 600");
    s = VoxelizeSettings();
    s.subcells = 0;
    expectError(good, s, "subcells is 0");
    s.subcells = -2;
    expectError(good, s, "subcells is -2");
    s.subcells = 17;
    expectError(good, s, "subcells is 17");
    s = VoxelizeSettings();

    expectError(TriangleMesh(), s, "no triangles");
    TriangleMesh nan = good;
    nan.positions[5].y = std::numeric_limits<float>::quiet_NaN();
    expectError(nan, s, "vertex 5 has a NaN or infinite coordinate");
    TriangleMesh inf = good;
    inf.positions[0].x = std::numeric_limits<float>::infinity();
    expectError(inf, s, "vertex 0 has a NaN");
    MeshBuilder point;
    point.tri({1, 1, 1}, {1, 1, 1}, {1, 1, 1});
    point.tri({1, 1, 1}, {1, 1, 1}, {1, 1, 1});
    expectError(point.mesh, s, "zero extent along all axes");
    TriangleMesh badIndex = good;
    badIndex.triangles[3].z = 1000;
    expectError(badIndex, s, "triangle 3 uses vertex 1000");
    TriangleMesh badMaterial = good;
    badMaterial.triangleMaterial[2] = 7;
    expectError(badMaterial, s, "triangle 2 uses material 7");
    TriangleMesh badMaterialCount = good;
    badMaterialCount.triangleMaterial.pop_back();
    expectError(badMaterialCount, s, "triangle materials for");

    // gridForMesh on its own.
    const std::string empty = errorOf([] { gridForMesh(Bounds3(), VoxelizeSettings()); });
    QVERIFY(!empty.empty() && empty != test::kNoError);
    Bounds3 nanBounds;
    nanBounds.lo = glm::vec3(std::numeric_limits<float>::quiet_NaN());
    nanBounds.hi = glm::vec3(1.0f);
    QVERIFY(errorOf([&] { gridForMesh(nanBounds, VoxelizeSettings()); }).find("not finite") != std::string::npos);
    // Explicit dims win only when all three are set; a partial set falls back to automatic sizing.
    VoxelizeSettings partial;
    partial.dims = glm::ivec3(10, 0, 10);
    partial.longestAxisNodes = 16;
    QCOMPARE(gridForMesh(meshBounds(good), partial).dims.z, 16);
}

void TestVoxelize::realTree()
{
    const std::string path = std::string(SYLVA_RESOURCES) + "/trees/quaternius/OBJ/Tree_1.obj";
    QVERIFY2(std::filesystem::exists(path), path.c_str());
    TriangleMesh mesh;
    QVERIFY(readObj(path, mesh));
    QVERIFY(mesh.triangleCount() > 300);
    VoxelizeSettings s;
    s.longestAxisNodes = 64;
    const DensityGrid grid = voxelize(mesh, s);
    const GridGeometry& g = grid.geometry;
    QCOMPARE(g.dims.y, 64);  // the tree is y-up and taller than wide
    QVERIFY(valuesInUnitRange(grid));
    QVERIFY(marginEmpty(grid));
    // Mass by height: the crown (upper half) holds more than the trunk (lower half); trunk nodes are wood.
    double lower = 0.0, upper = 0.0, woodLower = 0.0, woodUpper = 0.0;
    size_t marked = 0;
    for (int i = 0; i < g.dims.x; ++i)
        for (int j = 0; j < g.dims.y; ++j)
            for (int k = 0; k < g.dims.z; ++k) {
                const size_t n = g.index(i, j, k);
                const double d = grid.density[n];
                marked += d > 0.0;
                (j < g.dims.y / 2 ? lower : upper) += d;
                (j < g.dims.y / 2 ? woodLower : woodUpper) += d * grid.woodFraction[n];
            }
    qInfo("Tree_1: %zu triangles, grid %dx%dx%d, %zu non-empty nodes, mass lower %.1f upper %.1f", mesh.triangleCount(),
          g.dims.x, g.dims.y, g.dims.z, marked, lower, upper);
    QVERIFY(marked > 500);
    QVERIFY(upper > 2.0 * lower);
    QVERIFY(woodLower / lower > 0.9);          // the trunk
    QVERIFY(woodUpper / upper < 0.5);          // leaves dominate the crown
    // One vs two threads give the same grid on the real tree too.
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, 1);
    const DensityGrid single = voxelize(mesh, s);
    QVERIFY(single.density == grid.density);
    QVERIFY(single.woodFraction == grid.woodFraction);
}

QTEST_APPLESS_MAIN(TestVoxelize)
#include "tst_voxelize.moc"
