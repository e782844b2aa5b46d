// The LB grid in slabs along x (core/lb/lb_slab.h), the distributed solve's algorithm without MPI: the
// slabs of one process exchange their halo planes by copying, in the order sylva light --mpi runs
// (the planes that need no halo first, then the halos, then the planes beside them), and their
// gathered totals must equal solveLighting's to the bit, fp32 and fp16, for 1 to 5 slabs of an
// odd-sized grid (uneven slabs), with wood, two channel solves, f_0 kept or zeroed, a warm start.
#include <QTest>

#include <cstring>
#include <random>
#include <vector>

#include "core/base/error.h"
#include "core/grid/grid.h"
#include "core/lb/lb_params.h"
#include "core/lb/lb_slab.h"
#include "core/lb/lb_solver.h"

using namespace sylva;
using namespace sylva::lb;

namespace {

DensityGrid cloud(glm::ivec3 dims, uint32_t seed)
{
    DensityGrid g;
    g.geometry.dims = dims;
    g.geometry.origin = glm::dvec3(1.0, -2.0, 0.5);
    g.geometry.spacing = 0.25;
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    g.density.assign(g.geometry.nodeCount(), 0.0f);
    g.woodFraction.assign(g.geometry.nodeCount(), 0.0f);
    const glm::vec3 c = glm::vec3(dims) * 0.5f;
    for (int i = 0; i < dims.x; ++i)
        for (int j = 0; j < dims.y; ++j)
            for (int k = 0; k < dims.z; ++k) {
                const size_t n = g.geometry.index(i, j, k);
                const glm::vec3 p = (glm::vec3(i, j, k) - c) / c;
                if (glm::dot(p, p) > 0.8f) continue;   // empty rows and planes near the faces: the copy path too
                g.density[n] = u(rng) < 0.2f ? 0.0f : u(rng);
                g.woodFraction[n] = u(rng) < 0.1f ? 1.0f : 0.0f;
            }
    return g;
}

// The distributed solve with copies for messages: what mpi::solveDistributed does with Isend/Irecv.
LightingGrid slabSolve(const DensityGrid& density, const LbParams& params, int count)
{
    const glm::ivec3 dims = density.geometry.dims;
    std::vector<SlabRange> owned;
    std::vector<std::unique_ptr<LbSlab>> slabs;
    for (int r = 0; r < count; ++r) {
        owned.push_back(slabOwned(dims.x, r, count));
        slabs.push_back(makeCpuSlab(slabDensity(density, owned.back()), params));
    }
    int solveOf[3];
    const std::vector<ChannelParams> solves = distinctSolves(params, solveOf);
    const int steps = fixedSteps(params, dims);
    const size_t planeNodes = size_t(dims.y) * size_t(dims.z);
    LightingGrid out;
    out.geometry = density.geometry;
    out.rgb.assign(density.geometry.nodeCount() * 3, 0.0f);
    std::vector<float> tot;
    for (size_t s = 0; s < solves.size(); ++s) {
        for (auto& slab : slabs) slab->setSolve(solves[s]);
        for (int t = 0; t < steps; ++t) {
            for (auto& slab : slabs) slab->stepPlanes(1, slab->planes() - 1);
            for (int r = 0; r < count; ++r) {
                LbSlab& me = *slabs[size_t(r)];
                const int X = me.planes();
                if (r > 0) std::memcpy(me.plane(0), slabs[size_t(r - 1)]->plane(slabs[size_t(r - 1)]->planes() - 2), me.planeBytes());
                if (r + 1 < count) std::memcpy(me.plane(X - 1), slabs[size_t(r + 1)]->plane(1), me.planeBytes());
            }
            for (auto& slab : slabs) {
                slab->stepPlanes(0, 1);
                slab->stepPlanes(slab->planes() - 1, slab->planes());
                slab->finishStep();
            }
        }
        for (int r = 0; r < count; ++r) {
            slabs[size_t(r)]->totals(tot);
            const int lo = r == 0 ? 0 : 1, hi = r + 1 == count ? slabs[size_t(r)]->planes() : slabs[size_t(r)]->planes() - 1;
            for (int c = 0; c < 3; ++c) {
                if (solveOf[c] != int(s)) continue;
                for (size_t n = size_t(lo) * planeNodes; n < size_t(hi) * planeNodes; ++n) {
                    const size_t g = size_t(owned[size_t(r)].begin - 1) * planeNodes + n;
                    out.rgb[g * 3 + size_t(c)] = tot[n] * params.intensity[c];
                }
            }
        }
    }
    return out;
}

} // namespace

class TestLbSlab : public QObject {
    Q_OBJECT

private Q_SLOTS:
    void ownedPlanesCoverTheInterior()
    {
        for (int X : {3, 4, 9, 23, 64})
            for (int n = 1; n <= X - 2 && n <= 9; ++n) {
                int next = 1, least = X, most = 0;
                for (int r = 0; r < n; ++r) {
                    const SlabRange o = slabOwned(X, r, n);
                    QCOMPARE(o.begin, next);
                    QVERIFY(o.end > o.begin);
                    least = std::min(least, o.end - o.begin);
                    most = std::max(most, o.end - o.begin);
                    next = o.end;
                }
                QCOMPARE(next, X - 1);
                QVERIFY(most - least <= 1);
            }
        QVERIFY_THROWS_EXCEPTION(Error, slabOwned(5, 0, 4));   // 3 interior planes for 4 slabs
    }

    void slabDensityIsThePlanes()
    {
        const DensityGrid d = cloud({11, 6, 5}, 1);
        const DensityGrid s = slabDensity(d, {4, 7});
        QCOMPARE(s.geometry.dims, glm::ivec3(5, 6, 5));
        QCOMPARE(s.geometry.origin.x, d.geometry.origin.x + 3 * d.geometry.spacing);
        for (int i = 0; i < 5; ++i)
            for (int j = 0; j < 6; ++j)
                for (int k = 0; k < 5; ++k) {
                    QCOMPARE(s.density[s.geometry.index(i, j, k)], d.density[d.geometry.index(i + 3, j, k)]);
                    QCOMPARE(s.woodFraction[s.geometry.index(i, j, k)], d.woodFraction[d.geometry.index(i + 3, j, k)]);
                }
    }

    void slabsEqualTheWholeGrid_data()
    {
        QTest::addColumn<bool>("fp16");
        QTest::addColumn<bool>("keepF0");
        QTest::addColumn<bool>("warm");
        QTest::newRow("fp32") << false << false << false;
        QTest::newRow("fp16") << true << false << false;
        QTest::newRow("fp32 keep f0 warm") << false << true << true;
        QTest::newRow("fp16 keep f0") << true << true << false;
    }
    void slabsEqualTheWholeGrid()
    {
        QFETCH(bool, fp16);
        QFETCH(bool, keepF0);
        QFETCH(bool, warm);
        const DensityGrid d = cloud({17, 12, 19}, 7);
        LbParams p = paramsFromPreset(*findPreset("leaf"));
        p.channels[2] = {0.3f, 0.5f, 0.4f};   // a second distinct solve
        p.intensity = glm::vec3(1.0f, 0.8f, 1.3f);
        p.sun = glm::vec3(0.4f, 1.0f, -0.3f);
        p.zeroF0 = !keepF0;
        p.warmStart = warm;
        p.storage = fp16 ? Storage::Fp16 : Storage::Fp32;
        p.steps = 24;
        const LightingGrid whole = solveLighting(d, p);
        for (int n = 1; n <= 5; ++n) {
            const LightingGrid parts = slabSolve(d, p, n);
            QCOMPARE(parts.rgb.size(), whole.rgb.size());
            size_t differ = 0;
            for (size_t i = 0; i < whole.rgb.size(); ++i) differ += std::memcmp(&whole.rgb[i], &parts.rgb[i], sizeof(float)) != 0;
            if (differ) qWarning("%d slabs: %zu of %zu values differ", n, differ, whole.rgb.size());
            QCOMPARE(differ, size_t(0));
        }
        // Not a trivial field: light arrived and the medium shaped it.
        float lo = 1e30f, hi = 0.0f;
        for (float v : whole.rgb) {
            lo = std::min(lo, v);
            hi = std::max(hi, v);
        }
        QVERIFY(hi > 0.0f && lo < 0.5f * hi);
    }
};

QTEST_GUILESS_MAIN(TestLbSlab)
#include "tst_lb_slab.moc"
