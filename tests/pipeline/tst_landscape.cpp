// Landscapes: the cells' 2D kd-tree and the tiles' lazy 2D trees against a flattened
// scene of the same plants (every plant a top-level instance, placed in double by the test), the Wang tiling
// (edges match, replicated plants on both sides, neighbour repetition as chance predicts), the density rule
// (eq. 2, 3 within binomial noise, snow and rock masks, as seen by traced rays), precision far from the
// origin, and the scene file's keys and bad input.
#include <QDir>
#include <QFile>
#include <QTemporaryDir>
#include <QTest>

#include <cmath>
#include <fstream>
#include <map>
#include <memory>
#include <random>
#include <vector>

#include <OpenImageIO/imageio.h>

#include "core/base/error.h"
#include "core/render/render_cpu.h"
#include "core/render/render_scene.h"
#include "core/render/shade.h"
#include "core/render/tonemap.h"
#include "core/render/trace_packet.h"
#include "core/terrain/landscape.h"
#include "pipeline/cache/grid_cache.h"
#include "pipeline/io/dem_io.h"
#include "pipeline/render/frame_build.h"
#include "pipeline/render/render_job.h"
#include "pipeline/scene/scene_file.h"
#include "tests/common/golden.h"
#include "tests/common/scenes.h"

using namespace sylva;

namespace {

constexpr test::LinearTolerance kGolden{0.005, 0.001, 0.002, 0.002};   // tst_render's

float hills(uint32_t i, uint32_t j) { return 6.0f * std::sin(float(i) * 0.09f) * std::cos(float(j) * 0.07f) + 0.05f * float(i); }

// A one-species landscape: n x n samples 1 m apart with heights h, `cells` cells, tiles of `tileSize` m.
Scene landscape(uint32_t n, float (*h)(uint32_t, uint32_t), int cells, double tileSize, glm::dvec3 origin = glm::dvec3(0.0))
{
    Scene s;
    s.species.resize(1);
    s.species[0].name = "shrub";
    std::vector<float> hts(size_t(n) * n);
    for (uint32_t j = 0; j < n; ++j)
        for (uint32_t i = 0; i < n; ++i) hts[size_t(j) * n + i] = h(i, j);
    s.terrain.dem = "(in memory)";
    s.terrain.origin = origin;
    s.terrain.spacing = 1.0;
    s.terrain.field = std::make_shared<const HeightField>(buildHeightField(std::move(hts), n, n, 1.0f, 1.0f));
    s.terrain.cells = cells;
    s.terrain.tiles.size = tileSize;
    s.terrain.tiles.seed = 7;
    TilePlantDesc p;
    p.species = 0;
    p.speciesName = "shrub";
    p.spacing = 2.2;
    p.scaleMin = 0.7f;
    p.scaleMax = 1.1f;
    s.terrain.tiles.plants = {p};
    s.camera.position = origin + glm::dvec3(10.0, 25.0, 8.0);
    s.camera.target = origin + glm::dvec3(40.0, 0.0, 40.0);
    s.sun.direction = glm::vec3(0.4f, 0.8f, 0.3f);
    s.render.width = 96;
    s.render.height = 64;
    return s;
}

// The landscape's plants as top-level instances placed in double: cell (cx, cz)'s tile plant p at DEM-frame
// (cx C + k p.x, surfaceHeight, cz C + k p.z), rotated as the plant, scaled k x its scale. `keep` decides.
template <class Keep>
Scene flattened(const Scene& land, const RenderScene& rs, Keep keep)
{
    Scene s = land;
    s.terrain.cells = 0;
    s.instances.clear();
    const LandscapeLayout& L = rs.frame.landscape.layout;
    const double C = L.cellSize, k = L.tileScale;
    for (uint32_t cz = 0; cz < L.cellsZ; ++cz)
        for (uint32_t cx = 0; cx < L.cellsX; ++cx) {
            const LandCell& c = rs.landCells[size_t(cz) * L.cellsX + cx];
            const TileRecord& t = rs.tileRecords[c.tile];
            for (uint32_t q = t.plantOffset; q < t.plantOffset + t.plantCount; ++q) {
                const TilePlant& p = rs.tilePlants[q];
                const double x = double(cx) * C + k * double(p.x), z = double(cz) * C + k * double(p.z);
                const double y = surfaceHeight(*land.terrain.field, x, z);
                if (std::isnan(y) || !keep(cx, cz, q, y)) continue;
                InstanceDesc d;
                d.species = p.species;
                d.position = land.terrain.origin + glm::dvec3(x, y, z);
                const double cs = double(p.row[0].x) * double(p.scale), sn = -double(p.row[0].z) * double(p.scale);
                d.rotationDeg = glm::vec3(0.0f, float(std::atan2(sn, cs) * 180.0 / M_PI), 0.0f);
                d.scale = float(k * double(p.scale));
                s.instances.push_back(d);
            }
        }
    return s;
}

} // namespace

class TestLandscape : public QObject {
    Q_OBJECT

    std::vector<SpeciesAssets> m_assets;
    QTemporaryDir m_dir;

    std::string file(const char* name) const { return m_dir.filePath(QString::fromLatin1(name)).toStdString(); }

private Q_SLOTS:
    void initTestCase() { m_assets = test::oneShrub(); }

    // The cells' ground bound (LandCell: range and plane +- deviation), which the traversal raises tile nodes
    // and plants over: the ground under every plant of every cell's tile (its root, where the traversal reads it
    // with landPlantHeight, and random points under its box) lies inside it, at 4, 16 and 32 cells of a sloped,
    // bumpy terrain; and on cells much smaller than the hills the plane's band is narrower than the range it replaces.
    void cellGroundBoundHoldsTheGround()
    {
        const uint32_t n = 257;
        const float spacing = 2.0f;
        std::vector<float> heights(size_t(n) * n);
        for (uint32_t j = 0; j < n; ++j)
            for (uint32_t i = 0; i < n; ++i)
                heights[size_t(j) * n + i] = 40.0f * std::sin(0.05f * float(i)) * std::cos(0.04f * float(j)) + 0.3f * float(i) +
                                             2.0f * std::sin(1.3f * float(i) + 0.7f * float(j)) + 1500.0f;
        const HeightField field = buildHeightField(std::move(heights), n, n, spacing, spacing);
        const HeightFieldView view{field.layout, field.heights.data(), field.ranges.data()};
        std::mt19937 rng(5);
        std::uniform_real_distribution<float> u01(0.0f, 1.0f);
        for (const uint32_t cells : {4u, 16u, 32u}) {
            TileSetDesc tiles;
            tiles.size = 0.8 * double(n - 1) * spacing / double(cells);   // non-conforming: plants scaled by 1.25
            tiles.seed = 3;
            TilePlantDesc p;
            p.species = 0;
            p.speciesName = "tree";
            p.spacing = 3.0;
            tiles.plants = {p};
            const LandscapeSpecies sp{0, glm::vec3(-1.5f, 0.0f, -1.5f), glm::vec3(1.5f, 6.0f, 1.5f), 100.0};
            const LandscapeBuild b = buildLandscape(field, cells, tiles, TilingDesc{}, DensityDesc{}, 0.0, 3e38f, -2.0f, {sp});
            const LandscapeLayout& L = b.layout;
            size_t tested = 0, outside = 0;
            double range = 0.0, band = 0.0;
            for (uint32_t cz = 0; cz < L.cellsZ; ++cz)
                for (uint32_t cx = 0; cx < L.cellsX; ++cx) {
                    const LandCell& c = b.cells[size_t(cz) * L.cellsX + cx];
                    range += double(c.ground.y - c.ground.x);
                    band += std::min(2.0 * double(c.plane.w), double(c.ground.y - c.ground.x));
                    const TileRecord& t = b.tiles[c.tile];
                    for (uint32_t k = 0; k < t.plantCount; ++k) {
                        const TilePlant& pl = b.plants[t.plantOffset + k];
                        for (int s = 0; s < 4; ++s) {
                            TilePlant at = pl;   // s = 0: the root; else a random point under the plant's box
                            if (s > 0) {
                                at.x = pl.x + pl.lo.x + u01(rng) * (pl.hi.x - pl.lo.x);
                                at.z = pl.z + pl.lo.z + u01(rng) * (pl.hi.z - pl.lo.z);
                            }
                            float y;
                            uint32_t tri;
                            if (!landPlantHeight(L, view, cx, cz, at, y, tri)) continue;   // off the terrain
                            const double g = double(c.plane.x) + double(c.plane.y) * at.x + double(c.plane.z) * at.z;
                            const double lo = std::max(g - c.plane.w, double(c.ground.x)), hi = std::min(g + c.plane.w, double(c.ground.y));
                            ++tested;
                            if (!(double(y) >= lo && double(y) <= hi)) {
                                if (outside++ < 5)
                                    qWarning("cells %u, cell (%u, %u): ground %.4f outside [%.4f, %.4f]", cells, cx, cz, double(y), lo, hi);
                            }
                        }
                    }
                }
            const double nc = double(L.cellsX) * L.cellsZ;
            qInfo("%u^2 cells: %zu ground points tested, %zu outside; mean range %.2f m, mean plane band %.2f m", cells, tested, outside,
                  range / nc, band / nc);
            QVERIFY(tested > 20000);
            QCOMPARE(outside, size_t(0));
            // Cells much smaller than the hills' 250 m wavelength are nearly planar (at 4 cells of 103 m the hills curve
            // within a cell, and the band is about the range).
            if (cells >= 16) QVERIFY2(band < 0.7 * range, "the plane's band should be narrower than the range on these slopes");
        }
    }

    // The cells' kd-tree and the tiles' 2D trees find the closest hit a flattened scene of the same plants
    // finds (a BVH over every plant), ray for ray: rays from the camera, from above and grazing the ground,
    // with tiles that do (k = 1) and do not (k = 0.8) conform to the cells.
    void landscapeMatchesFlattenedScene()
    {
        for (double tileSize : {16.0, 20.0}) {
            const Scene land = landscape(97, hills, 6, tileSize);
            const RenderScene rs = buildRenderScene(land, m_assets, glm::vec3(1.0f));
            QVERIFY(rs.frame.landscape.enabled);
            const Scene flat = flattened(land, rs, [](uint32_t, uint32_t, uint32_t, double) { return true; });
            QVERIFY(flat.instances.size() > 1000);
            const RenderScene fs = buildRenderScene(flat, m_assets, glm::vec3(1.0f));
            const RenderView a = rs.view(), b = fs.view();
            std::mt19937 rng(5);
            std::uniform_real_distribution<float> u(0.0f, 1.0f);
            int plants = 0, terrain = 0, differ = 0, anyDiffer = 0;
            const int n = 20000;
            for (int r = 0; r < n; ++r) {
                Ray ray;
                const int kind = r % 3;
                const glm::vec3 cam(0.0f);
                if (kind == 0) {
                    ray.org = cam;
                    ray.dir = glm::normalize(glm::vec3(u(rng) - 0.3f, -0.2f - u(rng), u(rng) - 0.3f));
                } else {
                    // A point over the terrain (camera-relative), looking down steeply or grazing.
                    const glm::vec3 p(u(rng) * 96.0f, (kind == 1 ? 14.0f : 3.0f) + 4.0f * u(rng), u(rng) * 96.0f);
                    ray.org = p - glm::vec3(land.camera.position);
                    const float dy = kind == 1 ? -0.5f - u(rng) : -0.15f * u(rng);
                    ray.dir = glm::normalize(glm::vec3(u(rng) - 0.5f, dy, u(rng) - 0.5f));
                }
                ray.tmin = 0.0f;
                ray.tmax = 1e30f;
                Hit ha{}, hb{};
                const bool ga = traceScene<false>(a, ray, ha), gb = traceScene<false>(b, ray, hb);
                if (ga && hitKind(ha) == SurfaceKind::Landscape) ++plants;
                if (ga && hitKind(ha) == SurfaceKind::Terrain) ++terrain;
                const bool same = ga == gb && (!ga || (std::fabs(ha.t - hb.t) <= 1e-4f * std::max(1.0f, ha.t) &&
                                                       ((hitKind(ha) == SurfaceKind::Terrain) == (hitKind(hb) == SurfaceKind::Terrain))));
                if (!same) ++differ;
                if (ga && hitKind(ha) == SurfaceKind::Landscape && !(ha.prim == hb.prim)) ++differ;
                Hit sa{}, sb{};
                if (traceScene<true>(a, ray, sa) != traceScene<true>(b, ray, sb)) ++anyDiffer;
            }
            qInfo("tile %g m: %d plant hits, %d terrain hits of %d rays; %d closest and %d any hits differ", tileSize, plants, terrain, n,
                  differ, anyDiffer);
            QVERIFY(plants > n / 5);
            QVERIFY(terrain > n / 10);
            QVERIFY2(differ <= n / 2000, qPrintable(QString("%1 rays differ").arg(differ)));
            QVERIFY(anyDiffer <= n / 2000);
            // The shaded picture too: the hit's instance (composed from the cell and the plant) shades alike.
            const std::vector<glm::vec3> ia = composeMode(renderFilm(a), RenderMode::Full, land.sky);
            const std::vector<glm::vec3> ib = composeMode(renderFilm(b), RenderMode::Full, land.sky);
            int pix = 0;
            for (size_t i = 0; i < ia.size(); ++i) pix += glm::any(glm::greaterThan(glm::abs(ia[i] - ib[i]), glm::vec3(0.02f)));
            QVERIFY2(pix <= int(ia.size()) / 200, qPrintable(QString("%1 pixels differ").arg(pix)));
        }
    }

    // Packets (traceScenePacket) answer every ray as traceScene does alone, closest and any hit, BVH and kd-tree:
    // a camera tile's rays (coherent), the sun's shadow rays from their hits, 64 random rays in all directions
    // (the packet's order then suits none of them), rays straight down and along the axes (zero direction
    // components), and packets of every size from 1 to 64.
    void packetsAnswerAsSingleRays_data()
    {
        test::accelRows();
    }
    void packetsAnswerAsSingleRays()
    {
        QFETCH(int, accel);
        Scene land = landscape(97, hills, 6, 20.0);
        land.render.accel = AccelKind(accel);
        const RenderScene rs = buildRenderScene(land, m_assets, glm::vec3(1.0f));
        const RenderView v = rs.view();
        QVERIFY(v.landscape.enabled);
        std::mt19937 rng(11);
        std::uniform_real_distribution<float> u(0.0f, 1.0f);
        int rays = 0, plantHits = 0, occluded = 0, differ = 0;
        // Every ray of the packet against itself alone; a closest hit must agree in t and in what was hit.
        auto check = [&](const std::vector<Ray>& packet) {
            const int n = int(packet.size());
            const size_t count = packet.size();
            std::vector<Hit> hp(count), sp(count);
            std::unique_ptr<bool[]> fp(new bool[size_t(n)]), op(new bool[size_t(n)]);
            traceScenePacket<false>(v, packet.data(), n, hp.data(), fp.get());
            traceScenePacket<true>(v, packet.data(), n, sp.data(), op.get());
            for (int i = 0; i < n; ++i) {
                Hit h{}, a{};
                const bool f = traceScene<false>(v, packet[size_t(i)], h), o = traceScene<true>(v, packet[size_t(i)], a);
                ++rays;
                plantHits += f && hitKind(h) == SurfaceKind::Landscape;
                occluded += o;
                const Hit& g = hp[size_t(i)];
                const bool same = f == fp[size_t(i)] && o == op[size_t(i)] &&
                                  (!f || (h.t == g.t && h.prim == g.prim && h.inst == g.inst &&
                                          (hitKind(h) != SurfaceKind::Landscape || (h.nested[0] == g.nested[0] && h.nested[1] == g.nested[1]))));
                if (!same && differ++ < 5)
                    qWarning("ray %d of a packet of %d: (%d %d, t %g, inst %x, prim %u, cell %u, plant %u) alone, (%d %d, t %g, inst %x, prim %u, cell %u, "
                             "plant %u) in the packet",
                             i, n, int(f), int(o), double(h.t), h.inst, h.prim, h.nested[0], h.nested[1], int(fp[size_t(i)]), int(op[size_t(i)]),
                             double(g.t), g.inst, g.prim, g.nested[0], g.nested[1]);
            }
        };
        // Camera tiles, and the sun's shadow rays from the surfaces they hit.
        for (int ty = 0; ty < v.height; ty += 8)
            for (int tx = 0; tx < v.width; tx += 8) {
                std::vector<Ray> cam, sun;
                for (int y = ty; y < std::min(ty + 8, v.height); ++y)
                    for (int x = tx; x < std::min(tx + 8, v.width); ++x) cam.push_back(sampleRay(v, x, y, 0));
                check(cam);
                for (const Ray& r : cam) {
                    Hit h{};
                    if (traceScene<false>(v, r, h)) sun.push_back(Ray{shadowOrigin(surfaceStage(v, r, h)), 0.0f, lbLight(v).direction, 1e30f});
                }
                check(sun);
            }
        // Incoherent packets over the terrain, every size from 1 to 64.
        for (int size = 1; size <= kPacketRays; ++size) {
            std::vector<Ray> packet;
            for (int i = 0; i < size; ++i) {
                const glm::vec3 p(u(rng) * 96.0f, 3.0f + 14.0f * u(rng), u(rng) * 96.0f);
                Ray r;
                r.org = p - glm::vec3(land.camera.position);
                r.dir = glm::normalize(glm::vec3(u(rng) - 0.5f, u(rng) - 0.7f, u(rng) - 0.5f));
                r.tmin = 0.0f;
                r.tmax = 1e30f;
                packet.push_back(r);
            }
            check(packet);
        }
        // Zero direction components: straight down, and level along x and z.
        for (int k = 0; k < 3; ++k) {
            std::vector<Ray> packet;
            for (int i = 0; i < 40; ++i) {
                Ray r;
                r.org = glm::vec3(8.0f + 2.0f * float(i), k == 0 ? 12.0f : 1.5f + 0.1f * float(i), 10.0f + 1.7f * float(i)) - glm::vec3(land.camera.position);
                r.dir = k == 0 ? glm::vec3(0.0f, -1.0f, 0.0f) : (k == 1 ? glm::vec3(1.0f, 0.0f, 0.0f) : glm::vec3(0.0f, 0.0f, -1.0f));
                r.tmin = 0.0f;
                r.tmax = 1e30f;
                packet.push_back(r);
            }
            check(packet);
        }
        qInfo("%d rays: %d hit plants, %d occluded; %d answered differently in a packet", rays, plantHits, occluded, differ);
        QVERIFY(plantHits > rays / 10);
        QVERIFY(occluded > rays / 4);
        QCOMPARE(differ, 0);
    }

    // The CPU loop traces a landscape's tiles as packets: the film is bit for bit what shadePixel gives pixel by
    // pixel (2 jittered samples, sun shadows), whole and as a rectangle not aligned with the 8 x 8 tiles.
    void packetFilmEqualsPixelByPixel()
    {
        Scene land = landscape(97, hills, 6, 20.0);
        land.render.spp = 2;
        land.render.width = 45;
        land.render.height = 29;
        const RenderScene rs = buildRenderScene(land, m_assets, glm::vec3(1.0f));
        const RenderView v = rs.view();
        QVERIFY(v.landscape.enabled && v.shadows);
        const Film film = renderFilm(v);
        const int x0 = 3, y0 = 5, x1 = 40, y1 = 26;
        std::vector<SampleParts> rect(size_t(x1 - x0) * size_t(y1 - y0));
        renderFilmRect(v, x0, y0, x1, y1, rect.data());
        int differ = 0, plantPixels = 0;
        auto same = [](const SampleParts& a, const SampleParts& b) {
            return a.local == b.local && a.indirect == b.indirect && a.albedo == b.albedo && a.skyCover == b.skyCover && a.normal == b.normal &&
                   a.depth == b.depth && a.background == b.background;
        };
        for (int y = 0; y < v.height; ++y)
            for (int x = 0; x < v.width; ++x) {
                const SampleParts p = shadePixel(v, x, y);
                differ += !same(p, film.pixels[size_t(y) * size_t(v.width) + size_t(x)]);
                if (x >= x0 && x < x1 && y >= y0 && y < y1) differ += !same(p, rect[size_t(y - y0) * size_t(x1 - x0) + size_t(x - x0)]);
                Hit h{};
                plantPixels += traceScene<false>(v, sampleRay(v, x, y, 0), h) && hitKind(h) == SurfaceKind::Landscape;
            }
        qInfo("%d of %d pixels show plants; %d pixels differ", plantPixels, v.width * v.height, differ);
        QVERIFY(plantPixels > v.width * v.height / 10);
        QCOMPARE(differ, 0);
    }

    // Wang tiling of 64 x 64 cells with the 2 x 2 colour set: every shared edge matches; a tile repeats its left
    // neighbour as often as chance predicts (the sum of each cell's 1 / candidates where the neighbour is one),
    // within 4 sigma; a periodic tiling would repeat far more.
    void wangTilingMatchesEdges()
    {
        TilingDesc d;
        const std::vector<WangTile> set = wangTileSet(d);
        QCOMPARE(set.size(), size_t(16));
        const uint32_t N = 64;
        const std::vector<uint32_t> t = wangTiling(set, N, N, 11);
        QCOMPARE(wangTiling(set, N, N, 11), t);   // deterministic
        QVERIFY(wangTiling(set, N, N, 12) != t);
        double expect = 0.0, var = 0.0;
        int repeats = 0;
        std::vector<int> used(set.size(), 0);
        for (uint32_t z = 0; z < N; ++z)
            for (uint32_t x = 0; x < N; ++x) {
                const WangTile& w = set[t[z * N + x]];
                ++used[t[z * N + x]];
                if (x + 1 < N) QCOMPARE(w.e, set[t[z * N + x + 1]].w);
                if (z + 1 < N) QCOMPARE(w.n, set[t[(z + 1) * N + x]].s);
                if (x == 0 || z == 0) continue;
                const int needS = set[t[(z - 1) * N + x]].n, needW = set[t[z * N + x - 1]].e;
                int cand = 0;
                bool leftIsCandidate = false;
                for (uint32_t k = 0; k < set.size(); ++k)
                    if (set[k].s == needS && set[k].w == needW) {
                        ++cand;
                        leftIsCandidate = leftIsCandidate || k == t[z * N + x - 1];
                    }
                if (leftIsCandidate) {
                    expect += 1.0 / cand;
                    var += (1.0 / cand) * (1.0 - 1.0 / cand);
                }
                repeats += t[z * N + x] == t[z * N + x - 1];
            }
        qInfo("left-neighbour repeats %d, chance predicts %.1f +- %.1f", repeats, expect, std::sqrt(var));
        QVERIFY(std::fabs(repeats - expect) <= 4.0 * std::sqrt(var) + 1.0);
        for (int c : used) QVERIFY(c > int(N * N / set.size() / 2));   // every tile is used, none dominates
    }

    // Plants crossing a tile's edge exist in every tile with that edge colour, at the same world position
    // when the two tiles are neighbours (same species, scale, rotation and density id).
    void edgePlantsAreReplicated()
    {
        TileSetDesc d;
        d.size = 30.0;
        TilePlantDesc a, b;
        a.species = 0, a.spacing = 3.0;
        a.speciesName.push_back('a');   // not = "a": GCC 12 warns falsely (-Wrestrict) about that assignment
        b.species = 1, b.spacing = 2.0;
        b.speciesName.push_back('b');
        d.plants = {a, b};
        const std::vector<LandscapeSpecies> sp = {{0, glm::vec3(-1.0f, 0.0f, -1.0f), glm::vec3(1.0f, 4.0f, 1.0f), 100.0},
                                                  {1, glm::vec3(-0.5f, 0.0f, -0.6f), glm::vec3(0.5f, 2.0f, 0.4f), 50.0}};
        const std::vector<WangTile> set = wangTileSet(TilingDesc{});
        const TilePopulation pop = populateTiles(d, set, sp);
        QCOMPARE(pop.tiles.size(), set.size());
        auto find = [](const std::vector<TilePlant>& ps, const TilePlant& p, float dx, float dz) {
            for (const TilePlant& q : ps)
                if (std::fabs(q.x - (p.x + dx)) < 1e-4f && std::fabs(q.z - (p.z + dz)) < 1e-4f && q.species == p.species && q.scale == p.scale &&
                    q.densityId == p.densityId && q.row[0] == p.row[0])
                    return true;
            return false;
        };
        const float S = float(d.size);
        int crossing = 0;
        for (size_t i = 0; i < set.size(); ++i)
            for (const TilePlant& p : pop.tiles[i]) {
                QVERIFY(p.x + p.lo.x >= -S * 0.5f && p.x + p.hi.x <= S * 1.5f);
                const bool cornerFree = !((p.x + p.lo.x < 0.0f || p.x + p.hi.x > S) && (p.z + p.lo.z < 0.0f || p.z + p.hi.z > S));
                QVERIFY2(cornerFree, "a plant crosses two edges (it would reach a diagonal neighbour)");
                for (size_t j = 0; j < set.size(); ++j) {
                    if (p.z + p.hi.z > S && set[j].s == set[i].n) {
                        ++crossing;
                        QVERIFY(find(pop.tiles[j], p, 0.0f, -S));
                    }
                    if (p.z + p.lo.z < 0.0f && set[j].n == set[i].s) {
                        ++crossing;
                        QVERIFY(find(pop.tiles[j], p, 0.0f, S));
                    }
                    if (p.x + p.hi.x > S && set[j].w == set[i].e) {
                        ++crossing;
                        QVERIFY(find(pop.tiles[j], p, -S, 0.0f));
                    }
                    if (p.x + p.lo.x < 0.0f && set[j].e == set[i].w) {
                        ++crossing;
                        QVERIFY(find(pop.tiles[j], p, S, 0.0f));
                    }
                }
            }
        QVERIFY(crossing > 100);
        // Poisson disk: roots in the tile's middle (all drawn by one pass of dart throwing) keep the mean of their
        // spacings, and the pass fills the area (at least half the density of a hexagonal packing at the larger
        // spacing).
        for (const std::vector<TilePlant>& ps : pop.tiles) {
            int inner = 0;
            for (size_t x = 0; x < ps.size(); ++x) {
                auto mid = [S](const TilePlant& p) { return p.x > 0.25f * S && p.x < 0.75f * S && p.z > 0.25f * S && p.z < 0.75f * S; };
                if (!mid(ps[x])) continue;
                ++inner;
                for (size_t y = 0; y < ps.size(); ++y) {
                    if (y == x || !mid(ps[y])) continue;
                    const float dd = std::hypot(ps[x].x - ps[y].x, ps[x].z - ps[y].z);
                    QVERIFY(dd >= 0.5f * float(d.plants[ps[x].species].spacing + d.plants[ps[y].species].spacing) - 1e-4f);
                }
            }
            QVERIFY(inner > int(0.5 * (0.25 * S * S) / (0.866 * 9.0)));
        }
    }

    // The density rule as traced: the landscape with density on finds the closest hits of a flattened scene
    // holding exactly the plants eq. 2's p <= eq. 3's d keeps at their altitude (computed here from the
    // published formula), none on snow; the kept fraction per altitude band follows d within binomial noise.
    void densityFollowsEquations()
    {
        auto ramp = [](uint32_t, uint32_t j) { return 0.5f * float(j); };   // 0 .. 48 m along z
        Scene land = landscape(97, ramp, 6, 16.0);
        land.terrain.density.enabled = true;
        land.terrain.density.lower = 8.0;
        land.terrain.density.upper = 36.0;
        land.terrain.density.atLower = 0.9f;
        land.terrain.density.atUpper = 0.1f;
        land.terrain.snowLine = 42.0f;
        land.terrain.rockSlope = 60.0f;   // the ramp (27 degrees) is no rock
        const RenderScene rs = buildRenderScene(land, m_assets, glm::vec3(1.0f));
        const RenderView v = rs.view();
        std::vector<int> total(6, 0), kept(6, 0);
        std::vector<double> dsum(6, 0.0);
        int snowKept = 0, close = 0;
        const Scene flat = flattened(land, rs, [&](uint32_t cx, uint32_t cz, uint32_t q, double y) {
            const TilePlant& p = rs.tilePlants[q];
            const double pv = double((47ull * p.densityId) % 256ull) / 255.0;
            const double d = 0.9 + std::clamp((y - 8.0) / (36.0 - 8.0), 0.0, 1.0) * (0.1 - 0.9);
            if (std::fabs(pv - d) < 0.005 || std::fabs(y - 42.0) < 0.05) {   // within float rounding of a threshold: as traced
                ++close;
                float yy;
                return landPlantGrows(v.landscape.layout, HeightFieldView{v.terrain.layout, v.terrainHeights, v.terrainRanges}, v.terrain.snowY, v.terrain.rockCos, cx, cz, p, yy);
            }
            const bool keep = pv <= d && y <= 42.0;
            if (y > 42.0) {
                snowKept += keep;
                return keep;
            }
            const int band = std::min(5, int(y / 7.0));
            ++total[size_t(band)];
            kept[size_t(band)] += keep;
            dsum[size_t(band)] += d;
            return keep;
        });
        const RenderScene fs = buildRenderScene(flat, m_assets, glm::vec3(1.0f));
        const RenderView fv = fs.view();
        std::mt19937 rng(9);
        std::uniform_real_distribution<float> u(0.0f, 1.0f);
        int differ = 0, plants = 0;
        const int n = 12000;
        for (int r = 0; r < n; ++r) {
            Ray ray;
            ray.org = glm::vec3(u(rng) * 96.0f, 60.0f, u(rng) * 96.0f) - glm::vec3(land.camera.position);
            ray.dir = glm::normalize(glm::vec3(0.3f * (u(rng) - 0.5f), -1.0f, 0.3f * (u(rng) - 0.5f)));
            ray.tmin = 0.0f;
            ray.tmax = 1e30f;
            Hit ha{}, hb{};
            const bool ga = traceScene<false>(v, ray, ha), gb = traceScene<false>(fv, ray, hb);
            plants += ga && hitKind(ha) == SurfaceKind::Landscape;
            if (ga != gb || (ga && std::fabs(ha.t - hb.t) > 1e-4f * std::max(1.0f, ha.t))) ++differ;
        }
        qInfo("%d of %d rays hit plants, %d differ from the flattened scene; %d plants at a threshold", plants, n, differ, close);
        QVERIFY(plants > n / 10);
        QVERIFY2(differ <= n / 2000, qPrintable(QString("%1 rays differ").arg(differ)));
        QCOMPARE(snowKept, 0);
        int bands = 0;
        for (size_t b = 0; b < 6; ++b) {
            if (total[b] < 50) continue;
            ++bands;
            const double cnt = total[b], dm = dsum[b] / cnt, frac = kept[b] / cnt;
            qInfo("band %zu: %d plants, %.3f kept, eq. 3's mean d %.3f", b, total[b], frac, dm);
            // p takes the values k / 255 (a = 47 is prime to m = 256): P(p <= d) = (floor(255 d) + 1) / 256.
            const double want = (std::floor(255.0 * dm) + 1.0) / 256.0;
            QVERIFY2(std::fabs(frac - want) <= 4.0 * std::sqrt(want * (1.0 - want) / cnt) + 0.01, qPrintable(QString("band %1").arg(b)));
        }
        QVERIFY(bands >= 4);
    }

    // Rock: where the ground is steeper than rock_slope no plant grows (and none is hit).
    void noPlantsOnRock()
    {
        auto cliff = [](uint32_t i, uint32_t) { return i > 48 ? 2.0f * float(i - 48) : 0.0f; };   // 63 degrees beyond x = 48
        Scene land = landscape(97, cliff, 6, 16.0);
        land.terrain.density.enabled = true;
        land.terrain.density.atLower = 1.0f;
        land.terrain.density.atUpper = 1.0f;
        land.terrain.rockSlope = 45.0f;
        const RenderScene rs = buildRenderScene(land, m_assets, glm::vec3(1.0f));
        const RenderView v = rs.view();
        int flat = 0, steep = 0, steepHits = 0, flatHits = 0;
        std::mt19937 rng(3);
        std::uniform_real_distribution<float> u(1.0f, 95.0f);
        for (int r = 0; r < 4000; ++r) {
            const float x = u(rng), z = u(rng);
            if (std::fabs(x - 48.0f) < 4.0f) continue;   // plants by the cliff's foot may lean over it
            Ray ray;
            ray.org = glm::vec3(glm::dvec3(x, 200.0, z) - land.camera.position);
            ray.dir = glm::vec3(0.0f, -1.0f, 0.0f);
            ray.tmin = 0.0f;
            ray.tmax = 1e30f;
            Hit h{};
            traceScene<false>(v, ray, h);
            (x > 48.0f ? steep : flat) += 1;
            if (hitKind(h) == SurfaceKind::Landscape) (x > 48.0f ? steepHits : flatHits) += 1;
        }
        qInfo("flat: %d of %d rays hit plants; rock: %d of %d", flatHits, flat, steepHits, steep);
        QVERIFY(flatHits > flat / 5);
        QCOMPARE(steepHits, 0);
    }

    // The same landscape 5e6 m from the origin (terrain origin and camera moved together) renders the same
    // picture: the height field and the cells are traced in frames rebased under the camera in double; no
    // acne: an unoccluded plane of 82 km seen from its far corner is lit everywhere.
    void farFromOriginRendersTheSame()
    {
        const Scene near = landscape(97, hills, 6, 20.0);
        const glm::dvec3 off(5e6, 800.0, -5e6);
        const Scene far = landscape(97, hills, 6, 20.0, off);
        const std::vector<glm::vec3> a = composeMode(renderFilm(buildRenderScene(near, m_assets, glm::vec3(1.0f)).view()), RenderMode::Full, near.sky);
        const std::vector<glm::vec3> b = composeMode(renderFilm(buildRenderScene(far, m_assets, glm::vec3(1.0f)).view()), RenderMode::Full, far.sky);
        int differ = 0;
        for (size_t i = 0; i < a.size(); ++i) differ += glm::any(glm::greaterThan(glm::abs(a[i] - b[i]), glm::vec3(0.02f)));
        qInfo("%d of %zu pixels differ by more than 0.02", differ, a.size());
        QVERIFY(differ <= int(a.size()) / 500);

        // 2049 x 2049 samples 40 m apart (81.92 km) at UTM-like coordinates; camera 2 m over its far corner.
        Scene wide;
        wide.species.resize(1);
        wide.species[0].name = "shrub";
        wide.terrain.dem = "(in memory)";
        wide.terrain.origin = glm::dvec3(5.2e5, 0.0, 5.1e6);
        wide.terrain.spacing = 40.0;
        std::vector<float> slope(2049u * 2049u);
        for (size_t k = 0; k < slope.size(); ++k) slope[k] = 100.0f + 2.0f * float(k % 2049u);   // a plane rising 1:20 along +x
        wide.terrain.field = std::make_shared<const HeightField>(buildHeightField(std::move(slope), 2049, 2049, 40.0f, 40.0f));
        wide.camera.position = wide.terrain.origin + glm::dvec3(81013.0, 100.0 + 0.05 * 81013.0 + 2.0, 81007.0);
        wide.camera.target = wide.camera.position + glm::dvec3(-30.0, -3.5, -20.0);
        wide.sun.direction = sunDirection(6.0, 270.0);   // grazing light from the side the plane faces: acne shows first
        wide.render.width = 64;
        wide.render.height = 48;
        const RenderScene ws = buildRenderScene(wide, m_assets, glm::vec3(1.0f));
        const Film film = renderFilm(ws.view());
        int ground = 0, dark = 0;
        for (int i = 0; i < film.width * film.height; ++i) {
            if (film.pixels[size_t(i)].skyCover > 0.5f) continue;
            ++ground;
            if (!(film.pixels[size_t(i)].local.x > 0.0f)) ++dark;
        }
        qInfo("%d ground pixels, %d in (false) shadow", ground, dark);
        QVERIFY(ground > 1000);
        QCOMPARE(dark, 0);
    }

    // The bundled example (resources/landscape.sylva.json: St Helens, five species as Wang tiles, density on) at
    // 128 x 96 against its linear baseline tests/data/golden/landscape_example.exr (tests/common/golden.h), with
    // its species grown at 1/8 of their triangles and lit on 32-node grids to keep the test short; then the same
    // scene with terrain.origin and the camera moved by 5e6 m against the same baseline (the frame is placed
    // relative to the camera: measured, the same bits). The bounds are tst_render's (the same bits run to run;
    // room for another compiler's rounding only): a sun 2% brighter fails both.
    // A missing baseline is written and fails; SYLVA_TEST_UPDATE=1 rewrites it.
    void exampleMatchesGoldenImage()
    {
        Scene s = readSceneFile(std::string(SYLVA_SOURCE_DIR) + "/resources/landscape.sylva.json");
        for (SpeciesDesc& sp : s.species) {
            if (sp.grow) sp.grow->triangles = std::max<uint64_t>(2000, sp.grow->triangles / 8);
            sp.grid = 32;
        }
        s.render.width = 128;
        s.render.height = 96;
        s.render.spp = 1;
        const QString outDir = QString(SYLVA_TEST_OUTPUT) + "/landscape";
        QDir().mkpath(outDir);
        GridCache cache((outDir + "/cache").toStdString());
        for (const double shift : {0.0, 5e6}) {
            Scene at = s;
            const glm::dvec3 d(shift, 0.0, -shift);
            at.terrain.origin += d;
            at.camera.position += d;
            at.camera.target += d;
            const RenderOutput out = renderScene(at, &cache);
            const std::vector<glm::vec3> linear = composeMode(out.film, at.render.mode, at.sky);
            std::string summary;
            const QString failed = test::checkGolden("landscape_example", linear, at.render.width, at.render.height,
                                                     kGolden, outDir + "/shift_" + QString::number(shift, 'g', 3), &summary, shift == 0.0);
            qInfo("shift %g m: %s", shift, summary.c_str());
            if (!failed.isEmpty()) QFAIL(qPrintable(QString("shift %1 m: %2").arg(shift).arg(failed)));
        }
    }

    // The scene file: terrain.cells, tiles, tiling and density read and written back; bad input named.
    void sceneFileKeysAndBadInput()
    {
        const std::string dem = file("hills.png");
        {
            std::vector<uint16_t> px(33 * 33);
            for (size_t k = 0; k < px.size(); ++k) px[k] = uint16_t(100 * (k % 33));
            auto out = OIIO::ImageOutput::create(dem);
            QVERIFY(out && out->open(dem, OIIO::ImageSpec(33, 33, 1, OIIO::TypeDesc::UINT16)));
            QVERIFY(out->write_image(OIIO::TypeDesc::UINT16, px.data()) && out->close());
        }
        auto write = [&](const char* name, const std::string& terrainExtra) {
            const std::string path = file(name);
            std::ofstream f(path);
            f << "{\"version\": 1, \"species\": [{\"name\": \"shrub\", \"grow\": {\"species\": \"shrub\"}}], \"instances\": [],\n"
                 " \"terrain\": {\"dem\": \"hills.png\", \"spacing\": 2, \"height_scale\": 0.01"
              << terrainExtra << "}}\n";
            return path;
        };
        const std::string good = write("good.sylva.json",
                                       ", \"cells\": 4, \"tiles\": {\"size\": 16, \"seed\": 3, \"plants\": [{\"species\": \"shrub\", \"spacing\": 2.5}]},"
                                       " \"tiling\": {\"colors\": [2, 3], \"seed\": 9}, \"density\": {\"enabled\": true, \"lower\": 2, \"upper\": 5}");
        const Scene s = readSceneFile(good);
        QCOMPARE(s.terrain.cells, 4);
        QCOMPARE(s.terrain.tiles.size, 16.0);
        QCOMPARE(s.terrain.tiles.plants.size(), size_t(1));
        QCOMPARE(s.terrain.tiles.plants[0].spacing, 2.5);
        QCOMPARE(s.terrain.tiling.vertical, 3);
        QCOMPARE(s.terrain.tiling.seed, uint64_t(9));
        QVERIFY(s.terrain.density.enabled);
        QCOMPARE(s.terrain.density.a, 47);
        const std::string back = file("back.sylva.json");
        writeSceneFile(s, back);
        const Scene r = readSceneFile(back);
        QCOMPARE(r.terrain.cells, 4);
        QCOMPARE(r.terrain.tiling.vertical, 3);
        QCOMPARE(r.terrain.tiles.seed, uint64_t(3));
        QCOMPARE(r.terrain.density.upper, 5.0);

        const std::string unknown = test::sceneFileError(write("unknown.sylva.json", ", \"cells\": 4, \"tiles\": {\"plants\": [{\"species\": \"oak\"}]}"));
        QVERIFY2(unknown.find("terrain.tiles.plants[0].species") != std::string::npos && unknown.find("oak") != std::string::npos, unknown.c_str());
        const std::string empty = test::sceneFileError(write("empty.sylva.json",
                                                ", \"cells\": 4, \"tiles\": {\"plants\": [{\"species\": \"shrub\"}]}, \"tiling\": {\"set\": []}"));
        QVERIFY2(empty.find("terrain.tiling.set") != std::string::npos && empty.find("empty") != std::string::npos, empty.c_str());
        const std::string cannot = test::sceneFileError(write("cannot.sylva.json", ", \"cells\": 4, \"tiles\": {\"plants\": [{\"species\": \"shrub\"}]},"
                                                                     " \"tiling\": {\"set\": [[0, 0, 0, 0], [1, 1, 1, 0]]}"));
        QVERIFY2(cannot.find("cannot tile") != std::string::npos, cannot.c_str());
        const std::string noTiles = test::sceneFileError(write("notiles.sylva.json", ", \"cells\": 4"));
        QVERIFY2(noTiles.find("terrain.tiles") != std::string::npos, noTiles.c_str());
        const std::string noPlants = test::sceneFileError(write("noplants.sylva.json", ", \"cells\": 4, \"tiles\": {\"plants\": []}"));
        QVERIFY2(noPlants.find("at least one species") != std::string::npos, noPlants.c_str());
    }
};

QTEST_GUILESS_MAIN(TestLandscape)
#include "tst_landscape.moc"
