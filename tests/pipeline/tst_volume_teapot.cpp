// The PMMA teapot (Geist & Westall, "Lattice-Boltzmann Lighting Models", section 3.2.3): the bundled
// resources/teapot.sylva.json read as `sylva render` reads it. Its solid voxelization against an independent
// volume (the teapot's parts closed by caps over their open edges, their union integrated exactly along
// vertical lines by ray parity), the LB glow against the sun (the lit side brighter than the far side, light
// through the plastic on the far side), the conventional twin's ambient equal to the diffuse colour, and
// `sylva light --mesh --solid` against the library's solid voxelizer.
#include <QTemporaryDir>
#include <QTest>

#include <algorithm>
#include <cmath>
#include <map>
#include <numeric>
#include <vector>

#include "core/render/render_cpu.h"
#include "core/render/render_scene.h"
#include "core/voxel/voxelize.h"
#include "pipeline/import/mesh_import.h"
#include "pipeline/io/grid_file.h"
#include "pipeline/render/frame_build.h"
#include "pipeline/render/render_job.h"
#include "pipeline/scene/scene_file.h"
#include "pipeline/services/grid_stats.h"
#include "tests/common/run_program.h"

using namespace sylva;

namespace {

std::string scenePath() { return std::string(SYLVA_SOURCE_DIR) + "/resources/teapot.sylva.json"; }
std::string meshPath() { return std::string(SYLVA_SOURCE_DIR) + "/resources/teapot/teapot.obj"; }

// The volume of the union of the mesh's connected parts, each closed by a fan over every loop of its
// open edges (the rim under the lid, the lid's base, the ends of spout and handle), by exact ray parity
// along n x n vertical lines over the mesh's x-z box (midpoint rule across, exact along each line).
// Ray parity is exact for a closed part; it knows nothing of winding numbers.
double cappedUnionVolume(const TriangleMesh& mesh, int n, int* openLoops)
{
    // Weld (1e-5), then the parts by union-find over the triangles' vertices.
    std::map<std::array<long long, 3>, uint32_t> key;
    std::vector<glm::dvec3> p;
    std::vector<uint32_t> remap(mesh.positions.size());
    for (size_t i = 0; i < mesh.positions.size(); ++i) {
        const glm::dvec3 q(mesh.positions[i]);
        const std::array<long long, 3> k{std::llround(q.x * 1e5), std::llround(q.y * 1e5), std::llround(q.z * 1e5)};
        auto [it, fresh] = key.emplace(k, uint32_t(p.size()));
        if (fresh) p.push_back(q);
        remap[i] = it->second;
    }
    std::vector<glm::uvec3> tris;
    for (const auto& t : mesh.triangles) {
        const glm::uvec3 w(remap[t.x], remap[t.y], remap[t.z]);
        if (w.x != w.y && w.y != w.z && w.x != w.z) tris.push_back(w);
    }
    std::vector<uint32_t> parent(p.size());
    std::iota(parent.begin(), parent.end(), 0u);
    auto find = [&](uint32_t x) {
        while (parent[x] != x) x = parent[x] = parent[parent[x]];
        return x;
    };
    for (const auto& t : tris) {
        parent[find(t.x)] = find(t.y);
        parent[find(t.y)] = find(t.z);
    }
    // Open edges (used by one triangle), directed as in it; each loop capped by a fan to its centroid.
    std::map<std::pair<uint32_t, uint32_t>, int> use;
    for (const auto& t : tris)
        for (int e = 0; e < 3; ++e) ++use[{std::min(t[e], t[(e + 1) % 3]), std::max(t[e], t[(e + 1) % 3])}];
    std::map<uint32_t, uint32_t> next;
    for (const auto& t : tris)
        for (int e = 0; e < 3; ++e)
            if (use[{std::min(t[e], t[(e + 1) % 3]), std::max(t[e], t[(e + 1) % 3])}] == 1) next[t[e]] = t[(e + 1) % 3];
    *openLoops = 0;
    while (!next.empty()) {
        std::vector<uint32_t> loop{next.begin()->first};
        for (uint32_t v = next.begin()->second; v != loop[0]; v = next.at(v)) loop.push_back(v);
        glm::dvec3 c(0.0);
        for (uint32_t v : loop) c += p[v];
        p.push_back(c / double(loop.size()));
        parent.push_back(find(loop[0]));
        for (size_t k = 0; k < loop.size(); ++k) {
            tris.push_back({loop[(k + 1) % loop.size()], loop[k], uint32_t(p.size() - 1)});
            next.erase(loop[k]);
        }
        ++*openLoops;
    }
    // Crossings of each vertical line with each part.
    glm::dvec3 lo(1e30), hi(-1e30);
    for (const auto& q : p) {
        lo = glm::min(lo, q);
        hi = glm::max(hi, q);
    }
    const double dx = (hi.x - lo.x) / n, dz = (hi.z - lo.z) / n;
    std::vector<std::vector<std::pair<uint32_t, double>>> lines(size_t(n) * size_t(n));
    for (const auto& t : tris) {
        const glm::dvec3 a = p[t.x], b = p[t.y], c = p[t.z];
        const uint32_t part = find(t.x);
        const int i0 = std::max(0, int(std::floor((std::min({a.x, b.x, c.x}) - lo.x) / dx - 0.5))),
                  i1 = std::min(n - 1, int(std::ceil((std::max({a.x, b.x, c.x}) - lo.x) / dx - 0.5)));
        const int k0 = std::max(0, int(std::floor((std::min({a.z, b.z, c.z}) - lo.z) / dz - 0.5))),
                  k1 = std::min(n - 1, int(std::ceil((std::max({a.z, b.z, c.z}) - lo.z) / dz - 0.5)));
        const double det = (b.x - a.x) * (c.z - a.z) - (c.x - a.x) * (b.z - a.z);
        if (det == 0.0) continue;   // vertical: no line crosses it (the lines avoid its plane generically)
        for (int i = i0; i <= i1; ++i)
            for (int k = k0; k <= k1; ++k) {
                // Line centres nudged off the lattice of the mesh's symmetric vertices (no line through an edge).
                const double x = lo.x + (i + 0.5 + 1.3e-4) * dx, z = lo.z + (k + 0.5 + 2.7e-4) * dz;
                const double u = ((x - a.x) * (c.z - a.z) - (c.x - a.x) * (z - a.z)) / det;
                const double v = ((b.x - a.x) * (z - a.z) - (x - a.x) * (b.z - a.z)) / det;
                if (u < 0.0 || v < 0.0 || u + v > 1.0) continue;
                lines[size_t(i) * size_t(n) + size_t(k)].push_back({part, a.y + u * (b.y - a.y) + v * (c.y - a.y)});
            }
    }
    double volume = 0.0;
    for (auto& line : lines) {
        std::sort(line.begin(), line.end());
        std::vector<std::pair<double, double>> inside;   // per part: crossings paired by parity
        for (size_t s = 0; s < line.size();) {
            size_t e = s;
            while (e < line.size() && line[e].first == line[s].first) ++e;
            for (size_t k = s; k + 1 < e; k += 2) inside.push_back({line[k].second, line[k + 1].second});
            s = e;
        }
        std::sort(inside.begin(), inside.end());
        double end = -1e30, len = 0.0;
        for (const auto& [y0, y1] : inside) {   // the union of the parts' intervals
            if (y1 <= end) continue;
            len += y1 - std::max(y0, end);
            end = y1;
        }
        volume += len * dx * dz;
    }
    return volume;
}

double gridVolume(const DensityGrid& g)
{
    const double s = g.geometry.spacing;
    return std::accumulate(g.density.begin(), g.density.end(), 0.0) * s * s * s;
}

// A one-instance copy of the scene: species `species` at the position of instance 0, nothing else.
Scene alone(const Scene& scene, uint32_t species)
{
    Scene s = scene;
    s.instances = {scene.instances[0]};
    s.instances[0].species = species;
    s.render.width = 96;
    s.render.height = 64;
    s.render.spp = 1;
    s.camera.target = scene.instances[0].position;
    s.camera.position = scene.instances[0].position + glm::dvec3(0.0, 2.5, -9.0);
    return s;
}

bool isTeapot(const SampleParts& p) { return p.albedo.x > 0.5f && p.albedo.x > 4.0f * p.albedo.y; }

} // namespace

class TestVolumeTeapot : public QObject {
    Q_OBJECT
private Q_SLOTS:
    void sceneReads()
    {
        const Scene s = readSceneFile(scenePath());
        QCOMPARE(s.species.size(), size_t(2));
        QVERIFY(s.species[0].solid && s.species[0].lit);
        QCOMPARE(s.species[0].preset, std::string("pmma"));
        const lb::ChannelParams& r = s.species[0].lighting.channels[0];
        QCOMPARE(r.g, 0.80f);   // Geist & Westall, Table 2
        QCOMPARE(s.species[0].lighting.channels[1].g, -0.88f);
        QCOMPARE(r.sigmaA, 0.01f);
        QCOMPARE(r.sigmaS, 0.99f);
        QVERIFY(!s.species[1].lit);
    }

    // The LB teapot's solid grid (as the render voxelizes it) holds the volume of the capped parts.
    void interiorIsFilled()
    {
        const Scene s = readSceneFile(scenePath());
        const SpeciesGrids g = loadSpeciesGrids(s, 0, nullptr);
        int loops = 0;
        const double oracle = cappedUnionVolume(importMesh(meshPath()), 600, &loops);
        const double filled = gridVolume(g.density);
        qInfo("teapot: %d open loops capped; union of the capped parts %.4f, solid grid %s %.4f (%+.2f%%)", loops, oracle,
              gridDimsText(g.density.geometry).c_str(), filled, 100.0 * (filled / oracle - 1.0));
        QCOMPARE(loops, 6);   // the rim, the lid's base, two ends each of handle and spout
        QVERIFY(std::fabs(filled / oracle - 1.0) < 0.01);   // as the watertight sphere (tst_volume_sources)
        // A node deep inside the body is full, so are the wood fractions empty (a medium, not biomass).
        const GridGeometry& geo = g.density.geometry;
        const glm::ivec3 c = glm::ivec3(glm::round((glm::dvec3(0.0, -0.2, 0.0) - geo.origin) / geo.spacing));
        QCOMPARE(g.density.density[geo.index(c.x, c.y, c.z)], 1.0f);
        QVERIFY(std::all_of(g.density.woodFraction.begin(), g.density.woodFraction.end(), [](float w) { return w == 0.0f; }));
    }

    // The same teapot at the same place, LB-lit and conventional: the same sun light (local) and colour
    // at every pixel; the conventional ambient is the diffuse colour x the sun (LB open-space value 1),
    // the LB's glow is brighter where the surface faces the sun and still there on the far side.
    void glowAndConventionalTwin()
    {
        const Scene scene = readSceneFile(scenePath());
        Film films[2];
        glm::vec3 sun(0.0f), sunDir(0.0f);
        for (uint32_t sp = 0; sp < 2; ++sp) {
            const Scene s = alone(scene, sp);
            const std::vector<SpeciesAssets> assets = loadSpeciesAssets(s, nullptr, true);
            QCOMPARE(assets[1].lighting.rgb.empty(), true);   // the conventional species solves no grid
            QCOMPARE(assets[0].lighting.rgb.empty(), false);
            sun = sunRadiance(s.sun);
            sunDir = glm::normalize(s.sun.direction);
            films[sp] = renderFilm(buildRenderScene(s, assets, sun).view());
        }
        const Film& lb = films[0];
        const Film& plain = films[1];
        QCOMPARE(lb.pixels.size(), plain.pixels.size());
        double litSum = 0.0, farSum = 0.0, farMin = 1e30;
        int teapot = 0, lit = 0, far = 0;
        for (size_t i = 0; i < lb.pixels.size(); ++i) {
            const SampleParts& a = lb.pixels[i];
            const SampleParts& b = plain.pixels[i];
            QCOMPARE(isTeapot(a), isTeapot(b));
            if (!isTeapot(a)) continue;
            ++teapot;
            QCOMPARE(a.local, b.local);
            QCOMPARE(a.albedo, b.albedo);
            for (int c = 0; c < 3; ++c) QVERIFY(std::fabs(b.indirect[c] - b.albedo[c] * sun[c]) <= 1e-5f * b.albedo[c] * sun[c]);
            const double phi = double(a.indirect.x) / (double(a.albedo.x) * double(sun.x));   // red: the LB's forward-scattering channel
            const float facing = glm::dot(a.normal, sunDir);
            if (facing > 0.5f) {
                litSum += phi;
                ++lit;
            } else if (facing < -0.3f) {
                farSum += phi;
                farMin = std::min(farMin, phi);
                ++far;
            }
        }
        qInfo("teapot pixels %d: LB photon density (red) facing the sun %.3f (%d px), away from it %.3f (%d px, min %.3f)", teapot,
              litSum / std::max(lit, 1), lit, farSum / std::max(far, 1), far, farMin);
        QVERIFY(teapot > 300 && lit > 50 && far > 20);
        QVERIFY(litSum / lit > 1.2 * (farSum / far));
        QVERIFY(farMin > 0.3);   // light scattered through the plastic lights the far side
    }

    void lightSolidCommand()
    {
        QTemporaryDir dir;
        const std::string out = dir.path().toStdString() + "/t.vdb";
        const auto r = sylva::test::runSylva(
            {"light", QString::fromStdString(meshPath()), "--solid", "--grid", "20", "--preset", "pmma", "--sun", "0.3,1,0.2", "--no-cache", "--quiet",
             "-o", QString::fromStdString(out)});
        QVERIFY2(r.code != 0, "a positional mesh is not sylva light's syntax");
        const auto ok = sylva::test::runSylva({"light", "--mesh", QString::fromStdString(meshPath()), "--solid", "--grid", "20", "--preset",
                                               "pmma", "--sun", "0.3,1,0.2", "--no-cache", "--quiet", "-o", QString::fromStdString(out)});
        QVERIFY2(ok.code == 0, qPrintable(ok.err));
        VoxelizeSettings vs;
        vs.longestAxisNodes = 20;
        vs.solid = true;
        QVERIFY(readDensityFile(out).density == voxelize(importMesh(meshPath()), vs).density);
        const auto bad = sylva::test::runSylva({"light", "--density", QString::fromStdString(out), "--solid", "--sun", "0,1,0", "-o",
                                                QString::fromStdString(dir.path().toStdString() + "/x.npy")});
        QCOMPARE(bad.code, 2);
        QVERIFY(bad.err.contains("--solid"));
    }
};

QTEST_GUILESS_MAIN(TestVolumeTeapot)
#include "tst_volume_teapot.moc"
