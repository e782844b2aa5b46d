// Benchmark: voxelize a 500k-triangle synthetic tree into 128^3, against a naive single-threaded peer.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <random>
#include <vector>

#include <tbb/global_control.h>
#include <tbb/info.h>

#include "core/voxel/tri_box.h"
#include "core/voxel/voxelize.h"
#include "pipeline/grow/tree_grower.h"

using namespace sylva;

namespace {

using Clock = std::chrono::steady_clock;

double seconds(Clock::time_point a, Clock::time_point b) { return std::chrono::duration<double>(b - a).count(); }

double median(std::vector<double> v)
{
    std::sort(v.begin(), v.end());
    return v.size() % 2 ? v[v.size() / 2] : 0.5 * (v[v.size() / 2 - 1] + v[v.size() / 2]);
}

// Open cylinder from a to b: `around` segments, `along` rings, 2 * around * along triangles (wood).
void addCylinder(TriangleMesh& m, glm::vec3 a, glm::vec3 b, float r0, float r1, int around, int along)
{
    const glm::vec3 axis = glm::normalize(b - a);
    const glm::vec3 helper = std::abs(axis.y) < 0.9f ? glm::vec3(0, 1, 0) : glm::vec3(1, 0, 0);
    const glm::vec3 u = glm::normalize(glm::cross(axis, helper)), w = glm::cross(axis, u);
    const auto base = uint32_t(m.positions.size());
    for (int l = 0; l <= along; ++l) {
        const float t = float(l) / float(along);
        const float r = r0 + (r1 - r0) * t;
        for (int s = 0; s < around; ++s) {
            const float phi = 6.2831853f * float(s) / float(around);
            m.positions.push_back(a + t * (b - a) + r * (std::cos(phi) * u + std::sin(phi) * w));
        }
    }
    for (int l = 0; l < along; ++l)
        for (int s = 0; s < around; ++s) {
            const uint32_t i00 = base + uint32_t(l * around + s), i01 = base + uint32_t(l * around + (s + 1) % around);
            const uint32_t i10 = i00 + uint32_t(around), i11 = i01 + uint32_t(around);
            m.triangles.emplace_back(i00, i01, i11);
            m.triangles.emplace_back(i00, i11, i10);
            m.triangleMaterial.push_back(0);
            m.triangleMaterial.push_back(0);
        }
}

// A tree 10.5 m tall: trunk and 40 branches (wood), leaf quads of 4-8 cm in an ellipsoid crown.
TriangleMesh syntheticTree(size_t targetTriangles)
{
    TriangleMesh m;
    Material bark, leaf;
    bark.name = "bark";
    leaf.name = "leaf";
    leaf.isLeaf = true;
    m.materials = {bark, leaf};
    std::mt19937 rng(2024);
    std::uniform_real_distribution<float> uni(-1.0f, 1.0f), unit(0.0f, 1.0f);
    const glm::vec3 crownCentre(0.0f, 7.0f, 0.0f), crownRadius(3.0f, 3.5f, 3.0f);

    addCylinder(m, {0, 0, 0}, {0, 7.5f, 0}, 0.30f, 0.12f, 32, 96);
    for (int b = 0; b < 40; ++b) {
        const float y = 4.0f + 4.0f * unit(rng);
        glm::vec3 dir(uni(rng), 0.3f + 0.5f * unit(rng), uni(rng));
        dir = glm::normalize(dir);
        addCylinder(m, {0, y, 0}, glm::vec3(0, y, 0) + 2.5f * dir, 0.07f, 0.02f, 12, 32);
    }
    while (m.triangles.size() + 2 <= targetTriangles) {
        glm::vec3 p;
        do p = glm::vec3(uni(rng), uni(rng), uni(rng));
        while (glm::dot(p, p) > 1.0f);
        const glm::vec3 c = crownCentre + p * crownRadius;
        glm::vec3 n = glm::normalize(glm::vec3(uni(rng), uni(rng), uni(rng)) + glm::vec3(0, 0.01f, 0));
        const glm::vec3 t = glm::normalize(glm::cross(n, std::abs(n.y) < 0.9f ? glm::vec3(0, 1, 0) : glm::vec3(1, 0, 0)));
        const glm::vec3 s = glm::cross(n, t);
        const float half = 0.02f + 0.02f * unit(rng);
        const auto base = uint32_t(m.positions.size());
        m.positions.push_back(c - half * t - half * s);
        m.positions.push_back(c + half * t - half * s);
        m.positions.push_back(c + half * t + half * s);
        m.positions.push_back(c - half * t + half * s);
        m.triangles.emplace_back(base, base + 1, base + 2);
        m.triangles.emplace_back(base, base + 2, base + 3);
        m.triangleMaterial.push_back(1);
        m.triangleMaterial.push_back(1);
    }
    return m;
}

// Naive peer: one thread, every triangle against every interior sub-cell of its closed bounds with
// the full 13-axis test, no early-outs, flags for the whole sub-cell grid, then counts per node.
DensityGrid naiveVoxelize(const TriangleMesh& mesh, const VoxelizeSettings& settings)
{
    const Bounds3 bounds = meshBounds(mesh);
    DensityGrid grid;
    grid.geometry = gridForMesh(bounds, settings);
    const GridGeometry& g = grid.geometry;
    const int sc = settings.subcells;
    const glm::ivec3 n = g.dims * sc;
    const double scale = double(sc) / g.spacing;
    glm::dvec3 offset;
    for (int a = 0; a < 3; ++a) offset[a] = (double(bounds.lo[a]) - (g.origin[a] - 0.5 * g.spacing)) * scale;
    std::vector<uint8_t> flags(size_t(n.x) * size_t(n.y) * size_t(n.z), 0);
    for (size_t t = 0; t < mesh.triangles.size(); ++t) {
        glm::vec3 p[3];
        for (int c = 0; c < 3; ++c)
            for (int a = 0; a < 3; ++a)
                p[c][a] = float((double(mesh.positions[mesh.triangles[t][c]][a]) - double(bounds.lo[a])) * scale + offset[a]);
        const glm::vec3 bmin = glm::min(p[0], glm::min(p[1], p[2])), bmax = glm::max(p[0], glm::max(p[1], p[2]));
        const glm::ivec3 lo = glm::max(glm::ivec3(glm::ceil(bmin)) - 1, glm::ivec3(sc));
        const glm::ivec3 hi = glm::min(glm::ivec3(glm::floor(bmax)), n - sc - 1);
        const uint8_t bits = mesh.isLeafTriangle(t) ? 1 : 3;
        for (int x = lo.x; x <= hi.x; ++x)
            for (int y = lo.y; y <= hi.y; ++y)
                for (int z = lo.z; z <= hi.z; ++z)
                    if (triBoxOverlap(glm::vec3(x, y, z) + 0.5f, glm::vec3(0.5f), p[0], p[1], p[2]))
                        flags[(size_t(x) * size_t(n.y) + size_t(y)) * size_t(n.z) + size_t(z)] |= bits;
    }
    grid.density.assign(g.nodeCount(), 0.0f);
    grid.woodFraction.assign(g.nodeCount(), 0.0f);
    for (int i = 0; i < g.dims.x; ++i)
        for (int j = 0; j < g.dims.y; ++j)
            for (int k = 0; k < g.dims.z; ++k) {
                int marked = 0, wood = 0;
                for (int a = 0; a < sc; ++a)
                    for (int b = 0; b < sc; ++b)
                        for (int c = 0; c < sc; ++c) {
                            const uint8_t f = flags[(size_t(i * sc + a) * size_t(n.y) + size_t(j * sc + b)) * size_t(n.z) + size_t(k * sc + c)];
                            marked += f & 1;
                            wood += f >> 1;
                        }
                grid.density[g.index(i, j, k)] = float(marked) / float(sc * sc * sc);
                grid.woodFraction[g.index(i, j, k)] = marked ? float(wood) / float(marked) : 0.0f;
            }
    return grid;
}

} // namespace

int main()
{
    const size_t triangles = 500000;
    const int runs = 7, naiveRuns = 3;
    auto t0 = Clock::now();
    const TriangleMesh mesh = syntheticTree(triangles);
    auto t1 = Clock::now();
    VoxelizeSettings settings;  // longest axis 128 nodes, 3x3x3 sub-cells
    const GridGeometry g = gridForMesh(meshBounds(mesh), settings);
    std::printf("synthetic tree: %zu triangles, %zu vertices (built in %.2f s)\n", mesh.triangleCount(),
                mesh.positions.size(), seconds(t0, t1));
    std::printf("grid %d x %d x %d, spacing %.4f m, %d^3 sub-cells per cell, %d threads available\n", g.dims.x,
                g.dims.y, g.dims.z, g.spacing, settings.subcells, tbb::info::default_concurrency());

    DensityGrid fast;
    std::vector<double> times;
    for (int r = 0; r < runs; ++r) {
        t0 = Clock::now();
        fast = voxelize(mesh, settings);
        times.push_back(seconds(t0, Clock::now()));
    }
    std::vector<double> single;
    {
        tbb::global_control limit(tbb::global_control::max_allowed_parallelism, 1);
        for (int r = 0; r < 3; ++r) {
            t0 = Clock::now();
            const DensityGrid one = voxelize(mesh, settings);
            single.push_back(seconds(t0, Clock::now()));
            if (one.density != fast.density || one.woodFraction != fast.woodFraction)
                std::printf("WARNING: 1-thread output differs from the default-thread output\n");
        }
    }
    DensityGrid naive;
    std::vector<double> naiveTimes;
    for (int r = 0; r < naiveRuns; ++r) {
        t0 = Clock::now();
        naive = naiveVoxelize(mesh, settings);
        naiveTimes.push_back(seconds(t0, Clock::now()));
    }

    size_t differing = 0, nonEmpty = 0;
    double mass = 0.0;
    for (size_t n = 0; n < fast.density.size(); ++n) {
        differing += fast.density[n] != naive.density[n] || fast.woodFraction[n] != naive.woodFraction[n];
        nonEmpty += fast.density[n] > 0.0f;
        mass += fast.density[n];
    }
    const double tFast = median(times), tSingle = median(single), tNaive = median(naiveTimes);
    std::printf("\n%-34s %10s %10s %10s\n", "", "median s", "min s", "max s");
    std::printf("%-34s %10.3f %10.3f %10.3f\n", "voxelize (all threads)", tFast,
                *std::min_element(times.begin(), times.end()), *std::max_element(times.begin(), times.end()));
    std::printf("%-34s %10.3f %10.3f %10.3f\n", "voxelize (1 thread)", tSingle,
                *std::min_element(single.begin(), single.end()), *std::max_element(single.begin(), single.end()));
    std::printf("%-34s %10.3f %10.3f %10.3f\n", "naive (1 thread, all sub-cells)", tNaive,
                *std::min_element(naiveTimes.begin(), naiveTimes.end()),
                *std::max_element(naiveTimes.begin(), naiveTimes.end()));
    std::printf("non-empty nodes %zu, total density %.1f, nodes differing from the naive peer: %zu\n\n", nonEmpty, mass,
                differing);

    // The product's own default species at 500k triangles (grown, then voxelized the same way).
    GrowOptions grow;
    grow.targetTriangles = triangles;
    const TriangleMesh grown = growTree(grow).mesh;
    std::vector<double> grownTimes;
    for (int r = 0; r < runs; ++r) {
        t0 = Clock::now();
        const DensityGrid d = voxelize(grown, settings);
        grownTimes.push_back(seconds(t0, Clock::now()));
    }
    const GridGeometry gg = gridForMesh(meshBounds(grown), settings);
    std::printf("grown broadleaf: %zu triangles, grid %dx%dx%d, voxelize median %.3f s\n\n", grown.triangleCount(), gg.dims.x,
                gg.dims.y, gg.dims.z, median(grownTimes));

    std::printf("triangles=%zu\n", mesh.triangleCount());
    std::printf("grid=%dx%dx%d\n", g.dims.x, g.dims.y, g.dims.z);
    std::printf("voxelize_500k_128_s=%.4f\n", tFast);
    std::printf("voxelize_500k_128_1thread_s=%.4f\n", tSingle);
    std::printf("naive_500k_128_s=%.4f\n", tNaive);
    std::printf("speedup=%.1f\n", tNaive / tFast);
    std::printf("nodes_differing=%zu\n", differing);
    std::printf("voxelize_grown_broadleaf_500k_128_s=%.4f\n", median(grownTimes));
    return differing == 0 ? 0 : 1;
}
