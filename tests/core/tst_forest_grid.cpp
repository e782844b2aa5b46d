// The forest-level LB grid: factors per instance against what must hold without any
// fitted numbers: an isolated plant gets exactly the unobstructed 1, a plant inside a closed ring gets less
// than the ring, the factor is continuous as a plant moves, well-separated plants are uniform (skip).
#include <QTest>

#include <algorithm>
#include <cmath>

#include "core/base/error.h"
#include "core/grid/grid.h"
#include "core/lb/forest_grid.h"
#include "core/lb/lb_params.h"

using namespace sylva;
using namespace sylva::lb;

namespace {

// A 2 m cube crown of density 0.6 on a 0.25 m grid, origin at the bottom centre.
ForestSpecies cubeSpecies()
{
    DensityGrid d;
    d.geometry.dims = {10, 10, 10};
    d.geometry.spacing = 0.25;
    d.geometry.origin = {-1.125, -0.125 + 0.5, -1.125};
    d.density.assign(d.geometry.nodeCount(), 0.0f);
    for (int i = 1; i < 9; ++i)
        for (int j = 1; j < 9; ++j)
            for (int k = 1; k < 9; ++k) d.density[d.geometry.index(i, j, k)] = 0.6f;
    return forestSpecies(d);
}

LbParams params()
{
    LbParams p = paramsFromPreset(*findPreset("leaf"));
    p.sun = {0.3f, 1.0f, 0.2f};
    return p;
}

// One plant at the centre inside a closed ring of `count` plants twice its size (4 m crowns whose
// neighbours overlap).
std::vector<ForestPlant> ring(int count, double radius)
{
    std::vector<ForestPlant> plants{{glm::dvec3(0.0), 1.0f, 0}};
    for (int i = 0; i < count; ++i) {
        const double a = 2.0 * 3.14159265358979 * double(i) / double(count);
        plants.push_back({glm::dvec3(radius * std::cos(a), 0.0, radius * std::sin(a)), 2.0f, 0});
    }
    return plants;
}

} // namespace

class TestForestGrid : public QObject {
    Q_OBJECT
private Q_SLOTS:
    void speciesBiomass()
    {
        const ForestSpecies s = cubeSpecies();
        QVERIFY(std::fabs(s.biomass - 0.6 * 8.0) < 1e-5);   // 512 cells of 0.25^3 m^3 at 0.6
        QVERIFY(std::fabs(s.boxMax.x - s.boxMin.x - 2.0) < 1e-9);
    }

    void isolatedPlantGetsOne()
    {
        const ForestGridResult r = solveForestGrid({{glm::dvec3(3.0, 0.0, -2.0), 1.3f, 0}}, {cubeSpecies()}, params(), {24});
        for (int c = 0; c < 3; ++c) QVERIFY2(std::fabs(r.factors[0][c] - 1.0f) < 1e-4f, qPrintable(QString::number(r.factors[0][c])));
        QVERIFY(r.uniform);
    }

    // A coarse step keeps the Beer-Lambert transmittance of the optical depth it crosses: the cube crown
    // (density 0.6 on 0.25 m) at scale 4 on a 2 m lattice: a node inside it crosses 2 fine cells of 0.6, depth
    // 1.2, and leaf's sigma_t = 1, so its density is 1 - exp(-1.2) (the linear 1.2 would be capped at 1).
    void coarseStepKeepsTheTransmittance()
    {
        const ForestGridResult r = solveForestGrid({{glm::dvec3(0.0), 4.0f, 0}}, {cubeSpecies()}, params(), {6});
        QVERIFY(std::fabs(r.geometry.spacing - 2.0) < 1e-9);
        const float most = *std::max_element(r.density.begin(), r.density.end());
        QVERIFY2(std::fabs(most - float(-std::expm1(-1.2))) < 1e-5f, qPrintable(QString::number(most)));
        for (float v : r.density) QVERIFY(v >= 0.0f && v <= most);
    }

    void ringShadesTheInnerPlant()
    {
        const std::vector<ForestPlant> plants = ring(12, 5.0);
        LbParams p = params();
        p.sun = {1.0f, 0.6f, 0.3f};
        const ForestGridResult r = solveForestGrid(plants, {cubeSpecies()}, p, {32});
        double ringMean = 0.0;
        for (size_t i = 1; i < plants.size(); ++i) ringMean += r.factors[i].y;
        ringMean /= double(plants.size() - 1);
        qInfo("inner %.3f, ring mean %.3f; %s", double(r.factors[0].y), ringMean, forestGridSummary(r).c_str());
        QVERIFY(r.factors[0].y < ringMean);
        QVERIFY(r.factors[0].y < 0.95f);
        for (const glm::vec3& f : r.factors) QVERIFY(f.y > 0.0f);
        QVERIFY(!r.uniform);
    }

    // A plant walking past a neighbour: consecutive factors differ little (no jumps at cell edges).
    void continuousAsAPlantMoves()
    {
        float prev = -1.0f, maxJump = 0.0f, lowest = 1.0f;
        const int steps = 40;
        for (int s = 0; s <= steps; ++s) {
            const double x = 2.2 + 2.0 * double(s) / double(steps);
            // A fixed domain: a far third plant pins the grid's extent so only the mover moves.
            const std::vector<ForestPlant> plants{{glm::dvec3(0.0), 1.0f, 0}, {glm::dvec3(x, 0.0, 0.0), 1.0f, 0}, {glm::dvec3(12.0, 0.0, 6.0), 1.0f, 0}};
            const ForestGridResult r = solveForestGrid(plants, {cubeSpecies()}, params(), {32});
            const float f = r.factors[0].y;
            if (prev >= 0.0f) maxJump = std::max(maxJump, std::fabs(f - prev));
            lowest = std::min(lowest, f);
            prev = f;
        }
        qInfo("largest change between positions 5 cm apart: %.4f (lowest factor %.3f)", double(maxJump), double(lowest));
        QVERIFY(lowest < 0.99f);        // the neighbour does shade it
        QVERIFY(maxJump < 0.01f);
    }

    void separatedForestIsUniform()
    {
        // Light in the lattice travels along its 18 directions without spreading, so plants shade (and
        // light) each other along those lines however far apart: these four see each other along none of
        // them (pairwise offsets with |dx|, |dz| and ||dx| - |dz|| all over 4 m), so each is lit as if alone.
        std::vector<ForestPlant> plants;
        for (int a = 0; a < 2; ++a)
            for (int b = 0; b < 2; ++b) plants.push_back({glm::dvec3(12.0 * a + 5.0 * b, 0.0, 12.0 * b - 5.0 * a), 1.0f, 0});
        const ForestGridResult r = solveForestGrid(plants, {cubeSpecies()}, params(), {32});
        QVERIFY2(r.uniform, qPrintable(QString::fromStdString(forestGridSummary(r))));
    }

    void badInput()
    {
        QVERIFY_THROWS_EXCEPTION(Error, solveForestGrid({{glm::dvec3(0.0), 1.0f, 1}}, {cubeSpecies()}, params()));
        QVERIFY_THROWS_EXCEPTION(Error, solveForestGrid({{glm::dvec3(0.0), 0.0f, 0}}, {cubeSpecies()}, params()));
        QVERIFY_THROWS_EXCEPTION(Error, solveForestGrid({{glm::dvec3(0.0), 1.0f, 0}}, {cubeSpecies()}, params(), {2}));
        const ForestGridResult none = solveForestGrid({}, {cubeSpecies()}, params());
        QVERIFY(none.uniform && none.factors.empty());
    }
};

QTEST_APPLESS_MAIN(TestForestGrid)
#include "tst_forest_grid.moc"
