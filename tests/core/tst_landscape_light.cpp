// The forest-level LB grid over a landscape (core/terrain/landscape_light.h): open flat ground
// keeps the unobstructed light (closed form: the empty lattice's steady state is the boundary's), a valley is
// darker than its ridges and a slope facing away from a low sun darker than one facing it, a stand darker
// than open ground beside it, the plants counted are those the traversal's own growth test keeps (brute
// force over every cell's tile), testing 1 in k plants gives nearly the same field, a sparse landscape is
// uniform (auto skips it), the field is continuous in the foliage, and bad input is refused.
#include <QTest>

#include <algorithm>
#include <cmath>
#include <random>

#include "core/base/error.h"
#include "core/lb/forest_grid.h"
#include "core/lb/lattice.h"
#include "core/lb/lb_params.h"
#include "core/lb/lb_solver.h"
#include "core/terrain/landscape_light.h"

using namespace sylva;

namespace {

constexpr float kNoSnow = 3.0e38f, kNoRock = -2.0f;

// The density rule on (eq. 2, 3): d = atLower at the lower tree line, atUpper at the upper one.
DensityDesc densityRule(double lower, double upper, float atLower, float atUpper)
{
    DensityDesc d;
    d.enabled = true;
    d.lower = lower;
    d.upper = upper;
    d.atLower = atLower;
    d.atUpper = atUpper;
    return d;
}

struct Land {
    HeightField field;
    LandscapeBuild build;
};

// n x n samples `spacing` apart with heights h(x, z) (metres), cut into `cells` cells of one 160 m tile of
// plants `plantSpacing` apart (scale 1), under the density rule `density`.
template <class H>
Land makeLand(uint32_t n, float spacing, H h, uint32_t cells, double plantSpacing, const DensityDesc& density = {})
{
    std::vector<float> heights(size_t(n) * n);
    for (uint32_t j = 0; j < n; ++j)
        for (uint32_t i = 0; i < n; ++i) heights[size_t(j) * n + i] = h(float(i) * spacing, float(j) * spacing);
    Land l;
    l.field = buildHeightField(std::move(heights), n, n, spacing, spacing);
    TileSetDesc tiles;
    tiles.size = double(n - 1) * spacing / double(cells);
    tiles.seed = 3;
    TilePlantDesc p;
    p.species = 0;
    p.speciesName = "tree";
    p.spacing = plantSpacing;
    p.scaleMin = p.scaleMax = 1.0f;
    tiles.plants = {p};
    TilingDesc tiling;
    const LandscapeSpecies sp{0, glm::vec3(-3.0f, 0.0f, -3.0f), glm::vec3(3.0f, 10.0f, 3.0f), 100.0};
    l.build = buildLandscape(l.field, cells, tiles, tiling, density, 0.0, kNoSnow, kNoRock, {sp});
    return l;
}

// A 6 x 8 x 6 m crown from 2 m up, density 0.3 on a 0.25 m grid.
std::vector<lb::ForestSpecies> crown(double density = 0.3)
{
    lb::ForestSpecies s;
    s.boxMin = {-3.0, 2.0, -3.0};
    s.boxMax = {3.0, 10.0, 3.0};
    s.biomass = density * 6.0 * 8.0 * 6.0;
    s.spacing = 0.25;
    return {s};
}

lb::LbParams optics(glm::vec3 sun)
{
    lb::LbParams p = lb::paramsFromPreset(*lb::findPreset("leaf"));
    p.sun = sun;
    return p;
}

LandscapeLight solve(const Land& l, const std::vector<lb::ForestSpecies>& species, glm::vec3 sun, LandscapeLightSettings s = {})
{
    return solveLandscapeLight(l.field, l.build.layout, l.build.cells, l.build.tiles, l.build.plants, kNoSnow, kNoRock, species, optics(sun), s);
}

float mean(const glm::vec3& f) { return (f.x + f.y + f.z) / 3.0f; }

// The factor a plant standing at terrain-frame (x, z) reads 6 m above the ground.
float at(const LandscapeLight& r, const HeightField& f, double x, double z)
{
    return mean(landLightFactor(r.layout, r.nodes.data(), glm::vec3(float(x), float(surfaceHeight(f, x, z)) + 6.0f, float(z))));
}

} // namespace

class TestLandscapeLight : public QObject {
    Q_OBJECT

private Q_SLOTS:
    void openFlatGroundIsUnobstructed()
    {
        GridGeometry g;
        g.dims = {18, 10, 14};
        g.spacing = 5.0;
        std::vector<uint8_t> solid(g.nodeCount(), 0);
        for (int i = 0; i < g.dims.x; ++i)
            for (int j = 0; j < 4; ++j)
                for (int k = 0; k < g.dims.z; ++k) solid[g.index(i, j, k)] = 1;
        for (const glm::vec3 sun : {glm::vec3(0.0f, 1.0f, 0.0f), glm::vec3(0.8f, 0.45f, -0.3f), glm::vec3(-0.2f, 0.15f, 1.0f)}) {
            int steps = 0;
            const LightingGrid l = lb::solveGroundedLattice(g, std::vector<float>(g.nodeCount(), 0.0f), solid, optics(sun), &steps);
            QCOMPARE(steps, 2 * g.longestEdge());
            float worst = 0.0f;
            for (float v : l.rgb) worst = std::max(worst, std::fabs(v - 1.0f));
            QVERIFY2(worst < 1e-5f, qPrintable(QString("max |factor - 1| = %1").arg(double(worst))));
        }
        QVERIFY_THROWS_EXCEPTION(Error, lb::solveGroundedLattice(g, std::vector<float>(3, 0.0f), solid, optics({0, 1, 0})));
    }

    void beamIsTheSunsDirection()
    {
        std::mt19937 rng(5);
        std::uniform_real_distribution<float> u(-1.0f, 1.0f);
        for (int k = 0; k < 200; ++k) {
            const glm::vec3 sun(u(rng), u(rng), u(rng));
            const std::vector<float> bc = lb::beamDistribution(sun);
            glm::dvec3 sum(0.0);
            double weights = 0.0;
            int used = 0;
            for (int m = 1; m < lb::kDirections; ++m) {
                QVERIFY(bc[size_t(m)] >= 0.0f);
                sum += double(bc[size_t(m)]) * glm::normalize(glm::dvec3(lb::kC[m][0], lb::kC[m][1], lb::kC[m][2]));
                weights += bc[size_t(m)];
                used += bc[size_t(m)] > 0.0f;
            }
            QVERIFY(std::fabs(weights - 1.0) < 1e-5 && used >= 1 && used <= 3);
            QVERIFY(glm::length(glm::normalize(sum) + glm::normalize(glm::dvec3(sun))) < 1e-5);   // travels away from the sun
        }
        const std::vector<float> zenith = lb::beamDistribution(glm::vec3(0.0f, 2.0f, 0.0f));
        for (int m = 1; m < lb::kDirections; ++m) QCOMPARE(zenith[size_t(m)], lb::kC[m][1] == -1 && lb::kC[m][0] == 0 && lb::kC[m][2] == 0 ? 1.0f : 0.0f);
    }

    void valleyDarkerThanRidges()
    {
        // A V valley along z between plateaus 480 m high, its walls rising 1.2 m per metre (50 degrees), in a
        // 3.2 km square; a sun from +x 30 degrees high: the valley's floor and the wall facing away from the
        // sun lie in the far wall's shadow, the wall facing it does not.
        const Land l = makeLand(321, 10.0f, [](float x, float) { return std::min(480.0f, 1.2f * std::fabs(x - 1600.0f)); }, 20, 9.0);
        const glm::vec3 sun(std::cos(0.5236f), std::sin(0.5236f), 0.0f);
        const LandscapeLight r = solve(l, crown(), sun);
        QVERIFY(r.cellsWithPlants == 400 && r.nodes.size() == r.geometry.nodeCount());
        QCOMPARE(r.resolution, kLandLightAutoResolution);
        const float floor = at(r, l.field, 1600.0, 1600.0), west = at(r, l.field, 500.0, 1600.0), east = at(r, l.field, 2700.0, 1600.0);
        const float facing = at(r, l.field, 1400.0, 1600.0), away = at(r, l.field, 1800.0, 1600.0);
        // The terrain alone (foliage too thin to matter).
        const LandscapeLight bare = solve(l, crown(1e-6), sun);
        const float bareFloor = at(bare, l.field, 1600.0, 1600.0), bareWest = at(bare, l.field, 500.0, 1600.0);
        const float bareFacing = at(bare, l.field, 1400.0, 1600.0), bareAway = at(bare, l.field, 1800.0, 1600.0);
        qInfo("factors: west plateau %.3f, wall facing the sun %.3f, floor %.3f, wall facing away %.3f, east plateau %.3f; %dx%dx%d nodes, "
              "%.3f s; the terrain alone: plateau %.3f, facing %.3f, floor %.3f, away %.3f",
              double(west), double(facing), double(floor), double(away), double(east), r.geometry.dims.x, r.geometry.dims.y, r.geometry.dims.z,
              r.seconds, double(bareWest), double(bareFacing), double(bareFloor), double(bareAway));
        QVERIFY(std::fabs(bareWest - 1.0f) < 0.02f);   // open level ground
        QVERIFY(bareFloor < 0.1f && bareAway < 0.1f);   // in the far wall's shadow
        QVERIFY(bareFacing > 0.3f);
        QVERIFY(floor < 0.5f * std::min(west, east));
        QVERIFY(away < 0.5f * facing);
        QVERIFY(!r.uniform && r.spread > 0.1f);
    }

    void standDarkerThanOpenGround()
    {
        // Low ground (x < 800 m) carrying a stand, and a plateau 60 m up beyond a cliff, where the density rule
        // (plants below 30 m only) leaves open ground; a low sun from -x, over the stand first. On the lattice
        // a canopy shades its neighbours with the light that travels level through it (a column's canopy lies
        // in one node; light from above arrives unshaded): the stand's interior loses it, its edge facing the
        // sun and the open plateau keep it.
        DensityDesc d = densityRule(30.0, 31.0, 1.0f, 0.0f);
        d.m = 65536;   // eq. 2's value 0 (kept at d = 0) for no plant here
        const auto cliff = [](float x, float) { return 60.0f * std::clamp((x - 780.0f) / 40.0f, 0.0f, 1.0f); };
        const Land l = makeLand(161, 10.0f, cliff, 10, 7.0, d);
        const LandscapeLight r = solve(l, crown(0.5), glm::vec3(-1.0f, 0.3f, 0.1f));
        QVERIFY(r.cellsWithPlants >= 50 && r.cellsWithPlants <= 70);   // the low half, and the cliff's foot
        // The edge: the first lattice column (26 m) of the stand; level light does not get further into a dense one.
        const float inside = at(r, l.field, 500.0, 800.0), edge = at(r, l.field, 1.0, 800.0), open = at(r, l.field, 1300.0, 800.0);
        qInfo("stand interior %.3f, its edge facing the sun %.3f, open ground %.3f", double(inside), double(edge), double(open));
        QVERIFY(inside < 0.8f * open);
        QVERIFY(inside < 0.8f * edge);
        QVERIFY(std::fabs(open - 1.0f) < 0.05f);
    }

    void growingPlantsAreTheTraversals()
    {
        const DensityDesc d = densityRule(100.0, 300.0, 1.0f, 0.2f);
        const Land l = makeLand(81, 10.0f, [](float x, float z) { return 0.3f * x + 40.0f * std::sin(z * 0.01f); }, 8, 6.0, d);
        const LandscapeLight r = solve(l, crown(), glm::vec3(0.8f, 0.4f, 0.3f));
        const LandscapeLayout& L = l.build.layout;
        double tested = 0.0, grows = 0.0;
        for (size_t c = 0; c < l.build.cells.size(); ++c) {
            const TileRecord& t = l.build.tiles[l.build.cells[c].tile];
            for (uint32_t q = 0; q < t.plantCount; ++q) {
                float y = 0.0f;
                tested += 1.0;
                grows += landPlantGrows(L, l.field.view(), kNoSnow, kNoRock, uint32_t(c % L.cellsX), uint32_t(c / L.cellsX),
                                        l.build.plants[t.plantOffset + q], y);
            }
        }
        qInfo("%g of %g plants grow", grows, tested);
        QVERIFY(grows > 0.2 * tested && grows < 0.95 * tested);   // the rule thins them
        QCOMPARE(r.stride, 1u);
        QCOMPARE(r.plantsTested, tested);
        QCOMPARE(r.plantsGrowing, grows);

        // 1 in 4 plants tested: nearly the same field where a column holds hundreds of plants (as a landscape's
        // do: hundreds of metres wide), here at resolution 8 (133 m).
        LandscapeLightSettings s;
        s.resolution = 8;
        const LandscapeLight r8 = solve(l, crown(), glm::vec3(0.8f, 0.4f, 0.3f), s);
        s.maxPlantTests = size_t(tested / 4.0) + 1;
        const LandscapeLight q = solve(l, crown(), glm::vec3(0.8f, 0.4f, 0.3f), s);
        QCOMPARE(q.stride, 4u);
        QVERIFY(std::fabs(q.plantsTested - tested / 4.0) < double(l.build.cells.size()));
        QVERIFY(std::fabs(q.plantsGrowing - grows) < 0.05 * grows);
        float worst = 0.0f;   // at each cell's centre, 6 m above the ground (the lattices' heights may differ by a node)
        for (uint32_t c = 0; c < L.cellsX * L.cellsZ; ++c) {
            const double x = (double(c % L.cellsX) + 0.5) * double(L.cellSize), z = (double(c / L.cellsX) + 0.5) * double(L.cellSize);
            worst = std::max(worst, std::fabs(at(q, l.field, x, z) - at(r8, l.field, x, z)));
        }
        qInfo("1 in 4 plants tested: %g growing, field differs by %.4f at most", q.plantsGrowing, double(worst));
        QVERIFY(worst < 0.03f);
    }

    void sparseLandscapeIsUniform()
    {
        const Land l = makeLand(81, 10.0f, [](float, float) { return 5.0f; }, 8, 20.0);
        const LandscapeLight r = solve(l, crown(1e-4), glm::vec3(0.2f, 1.0f, 0.1f));
        QVERIFY(r.cellsWithPlants == 64);
        qInfo("factors %.4f - %.4f, spread %.4f", double(r.minFactor), double(r.maxFactor), double(r.spread));
        QVERIFY(r.uniform && r.spread < 0.02f);
        // No species with a density grid: no lattice.
        std::vector<lb::ForestSpecies> none(1);
        const LandscapeLight e = solve(l, none, glm::vec3(0.0f, 1.0f, 0.0f));
        QVERIFY(e.cellsWithPlants == 0 && e.nodes.empty() && e.layout.dims.x == 0);
        QCOMPARE(landLightFactor(e.layout, nullptr, glm::vec3(1.0f)), glm::vec3(1.0f));
    }

    void continuousInTheFoliage()
    {
        GridGeometry g;
        g.dims = {12, 8, 12};
        g.spacing = 4.0;
        std::vector<uint8_t> solid(g.nodeCount(), 0);
        for (int i = 0; i < g.dims.x; ++i)
            for (int k = 0; k < g.dims.z; ++k) solid[g.index(i, 0, k)] = solid[g.index(i, 1, k)] = 1;
        const auto field = [&](double shift) {
            std::vector<float> depth(g.nodeCount(), 0.0f);
            lb::splatDepth(glm::dvec3(14.0 + shift, 5.0, 14.0), glm::dvec3(26.0 + shift, 12.0, 22.0), 400.0, g, depth);
            return lb::solveGroundedLattice(g, depth, solid, optics({1.0f, 0.3f, 0.2f}));
        };
        const LightingGrid a = field(0.0), b = field(0.01), c = field(1.0);
        float small = 0.0f, large = 0.0f;
        for (size_t n = 0; n < a.rgb.size(); ++n)
            small = std::max(small, std::fabs(a.rgb[n] - b.rgb[n])), large = std::max(large, std::fabs(a.rgb[n] - c.rgb[n]));
        qInfo("moved 0.01 m: %.2e, 1 m: %.2e", double(small), double(large));
        QVERIFY(large > 1e-3f);
        QVERIFY(small < 0.03f * large);
    }

    void badInput()
    {
        const Land l = makeLand(41, 10.0f, [](float, float) { return 0.0f; }, 4, 20.0);
        LandscapeLightSettings s;
        s.resolution = 3;
        QVERIFY_THROWS_EXCEPTION(Error, solve(l, crown(), glm::vec3(0, 1, 0), s));
        s.resolution = 513;
        QVERIFY_THROWS_EXCEPTION(Error, solve(l, crown(), glm::vec3(0, 1, 0), s));
        s.resolution = 300;   // clamped (no density grid: nothing is solved)
        QCOMPARE(solve(l, std::vector<lb::ForestSpecies>(1), glm::vec3(0, 1, 0), s).resolution, kLandLightMaxResolution);
        QVERIFY_THROWS_EXCEPTION(Error, solve(l, {}, glm::vec3(0, 1, 0)));   // plants of species 0, none given
    }
};

QTEST_APPLESS_MAIN(TestLandscapeLight)
#include "tst_landscape_light.moc"
