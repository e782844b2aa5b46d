// Relighting from a cached basis, sylva light's front defaults (fp16, 1 x the longest
// edge) and its light parts (all, scattered, uncollided): the pipeline and the command line against direct solves.
#include <QDir>
#include <QFile>
#include <QJsonDocument>
#include <QJsonObject>
#include <QTest>

#include <cmath>
#include <random>

#include "core/lb/lb_basis.h"
#include "core/lb/lb_solver.h"
#include "pipeline/cache/grid_cache.h"
#include "pipeline/io/npy.h"
#include "pipeline/lighting_job.h"
#include "tests/common/files.h"
#include "tests/common/grids.h"
#include "tests/common/run_program.h"

using namespace sylva;
using sylva::test::relL2;
using sylva::test::Run;
using sylva::test::runSylva;

namespace {

DensityGrid randomDensity(glm::ivec3 dims, uint32_t seed)
{
    DensityGrid g;
    g.geometry.dims = dims;
    g.geometry.spacing = 0.25;
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    g.density.assign(g.geometry.nodeCount(), 0.0f);
    g.woodFraction.assign(g.geometry.nodeCount(), 0.0f);
    for (int i = 1; i < dims.x - 1; ++i)
        for (int j = 1; j < dims.y - 1; ++j)
            for (int k = 1; k < dims.z - 1; ++k) g.density[g.geometry.index(i, j, k)] = u(rng) < 0.5f ? 0.0f : u(rng);
    return g;
}

QJsonObject sidecar(const QString& npy)
{
    QFile f(npy + ".json");
    if (!f.open(QIODevice::ReadOnly)) return {};
    return QJsonDocument::fromJson(f.readAll()).object();
}

} // namespace

class TestLbRelight : public QObject {
    Q_OBJECT
    QString m_dir;

private Q_SLOTS:
    void initTestCase()
    {
        m_dir = test::outputDir("lb_relight");
        writeDensityGrid((m_dir + "/d.npy").toStdString(), randomDensity({10, 14, 9}, 3));
    }

    // lightingFor with a complete cached basis relights (no solve) and equals the direct solve (fp32:
    // float rounding); a changed optic or a missing basis grid falls back to a solve.
    void lightingForUsesTheBasis()
    {
        GridCache cache((m_dir + "/cache-job").toStdString());
        const DensityGrid d = randomDensity({12, 11, 10}, 7);
        lb::LbParams p = lb::paramsFromPreset(*lb::findPreset("leaf"));
        p.stepsPerEdge = 1;
        JobLog blog;
        const LightingBasis basis = lightingBasisFor(d, p, &cache, nullptr, &blog);
        QCOMPARE(int(basis.grids.size()), 18);
        QCOMPARE(int(std::count(blog.stages.begin(), blog.stages.end(), std::string("basis light"))), 18);
        JobLog again;
        lightingBasisFor(d, p, &cache, nullptr, &again);
        QCOMPARE(again.stages, std::vector<std::string>{"basis"});   // all 18 from the cache
        std::mt19937 rng(4);
        std::normal_distribution<float> n(0.0f, 1.0f);
        for (int t = 0; t < 3; ++t) {
            p.sun = {n(rng), std::fabs(n(rng)) + 0.1f, n(rng)};
            p.intensity = glm::vec3(1.0f + float(t), 0.5f, 2.0f);
            JobLog log;
            const LightingGrid relit = lightingFor(d, p, &cache, nullptr, &log);
            QCOMPARE(log.stages, std::vector<std::string>{"light (relit from the cached basis)"});
            const LightingGrid direct = lb::solveLighting(d, p);
            QVERIFY2(relL2(relit, direct) < 2e-6, qPrintable(QString::number(relL2(relit, direct))));
        }
        lb::LbParams other = p;
        other.channels[0].g = 0.3f;
        JobLog log;
        lightingFor(d, other, &cache, nullptr, &log);
        QCOMPARE(log.stages, std::vector<std::string>{"light"});
        QVERIFY(!cachedLightingBasis(d, other, cache));
        lb::LbParams tol = p;
        tol.tolerance = 1e-3;
        QVERIFY_THROWS_EXCEPTION(Error, lightingBasisFor(d, tol, &cache));
    }

    // sylva light: the default is fp16 at 1 x the longest edge, --seed-steps the seed's fp32 at 2 x;
    // --basis caches the basis and a later --sun relights from it, equal to a fresh solve within fp16's bound.
    void cliDefaultsAndBasis()
    {
        const QString d = m_dir + "/d.npy", cache = m_dir + "/xdg";
        Run r = runSylva({"light", "--density", d, "--sun", "0.3,1,0.2", "--no-cache", "--quiet", "-o", m_dir + "/def.npy"});
        QVERIFY2(r.code == 0, qPrintable(r.err));
        QCOMPARE(sidecar(m_dir + "/def.npy").value("parameters").toObject().value("storage").toString(), QString("fp16"));
        QCOMPARE(sidecar(m_dir + "/def.npy").value("parameters").toObject().value("steps").toInt(), 14);
        r = runSylva({"light", "--density", d, "--sun", "0.3,1,0.2", "--no-cache", "--quiet", "--seed-steps", "-o", m_dir + "/seed.npy"});
        QVERIFY2(r.code == 0, qPrintable(r.err));
        QCOMPARE(sidecar(m_dir + "/seed.npy").value("parameters").toObject().value("storage").toString(), QString("fp32"));
        QCOMPARE(sidecar(m_dir + "/seed.npy").value("parameters").toObject().value("steps").toInt(), 28);
        r = runSylva({"light", "--density", d, "--sun", "0.3,1,0.2", "--seed-steps", "--steps", "3", "-o", m_dir + "/x.npy"});
        QCOMPARE(r.code, 2);
        r = runSylva({"light", "--density", d, "--sun", "0.3,1,0.2", "--no-cache", "--basis", "-o", m_dir + "/x.npy"});
        QCOMPARE(r.code, 2);
        QVERIFY(r.err.contains("--no-cache"));

        r = runSylva({"light", "--density", d, "--sun", "0.3,1,0.2", "--basis", "--quiet", "-o", m_dir + "/b.npy"}, cache);
        QVERIFY2(r.code == 0, qPrintable(r.err));
        QVERIFY2(r.out.contains("18 directions"), qPrintable(r.out));
        r = runSylva({"light", "--density", d, "--sun", "-0.6,0.8,0.3", "-o", m_dir + "/relit.npy"}, cache);
        QVERIFY2(r.code == 0, qPrintable(r.err));
        QVERIFY2(r.err.contains("relit from the cached basis"), qPrintable(r.err));
        r = runSylva({"light", "--density", d, "--sun", "-0.6,0.8,0.3", "--no-cache", "--quiet", "-o", m_dir + "/fresh.npy"});
        QVERIFY2(r.code == 0, qPrintable(r.err));
        const double e = relL2(readLightingGrid((m_dir + "/relit.npy").toStdString()), readLightingGrid((m_dir + "/fresh.npy").toStdString()));
        qInfo("relit vs fresh fp16 solve: rel L2 %.3g", e);
        QVERIFY(e < 1e-3);
    }

    // --part: scattered + uncollided = all, node by node; the uncollided part is the whole light in open space.
    void cliParts()
    {
        const QString d = m_dir + "/d.npy";
        for (const char* part : {"all", "scattered", "uncollided"}) {
            const Run r = runSylva({"light", "--density", d, "--sun", "0.2,1,-0.4", "--no-cache", "--quiet", "--fp32", "--part", part, "-o",
                                    m_dir + "/part_" + part + ".npy"});
            QVERIFY2(r.code == 0, qPrintable(r.err));
        }
        const LightingGrid all = readLightingGrid((m_dir + "/part_all.npy").toStdString());
        const LightingGrid sc = readLightingGrid((m_dir + "/part_scattered.npy").toStdString());
        const LightingGrid un = readLightingGrid((m_dir + "/part_uncollided.npy").toStdString());
        double worst = 0.0, scattered = 0.0;
        for (size_t i = 0; i < all.rgb.size(); ++i) {
            worst = std::max(worst, double(std::fabs(sc.rgb[i] + un.rgb[i] - all.rgb[i])));
            scattered += sc.rgb[i];
        }
        QVERIFY2(worst < 1e-5, qPrintable(QString::number(worst)));
        QVERIFY(scattered > 0.0);
        QCOMPARE(un.at(0, 0, 0, 1), all.at(0, 0, 0, 1));
        QCOMPARE(sidecar(m_dir + "/part_scattered.npy").value("parameters").toObject().value("part").toString(), QString("scattered"));
        const Run bad = runSylva({"light", "--density", d, "--sun", "0,1,0", "--part", "direct", "-o", m_dir + "/x.npy"});
        QCOMPARE(bad.code, 2);
    }
};

QTEST_GUILESS_MAIN(TestLbRelight)
#include "tst_lb_relight.moc"
