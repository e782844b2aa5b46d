// The lighting pipeline with the cache: which stages run, and damaged cache entries are recomputed, never used.
#include <QDir>
#include <QFile>
#include <QJsonArray>
#include <QJsonDocument>
#include <QJsonObject>
#include <QTest>

#include "core/lb/lb_solver.h"
#include "pipeline/cache/grid_cache.h"
#include "pipeline/grow/obj_writer.h"
#include "pipeline/grow/tree_grower.h"
#include "pipeline/lighting_job.h"
#include "tests/common/files.h"

using namespace sylva;

class TestLightingJob : public QObject {
    Q_OBJECT

    QString m_dir;
    std::string m_mesh;

private Q_SLOTS:
    void initTestCase()
    {
        m_dir = test::outputDir("lighting_job");
        GrowOptions g;
        g.species = TreeSpecies::Shrub;
        g.targetTriangles = 4000;
        m_mesh = (m_dir + "/shrub.obj").toStdString();
        writeObj(m_mesh, growTree(g));
    }

    void stagesFollowWhatChanged()
    {
        GridCache cache((m_dir + "/cache-stages").toStdString());
        DensityJob job{m_mesh, {}, {}};
        job.voxel.longestAxisNodes = 20;
        lb::LbParams p = lb::paramsFromPreset(*lb::findPreset("leaf"));
        p.sun = {0.2f, 1.0f, 0.1f};

        JobLog first;
        const DensityGrid d1 = densityForMesh(job, &cache, nullptr, &first);
        const LightingGrid l1 = lightingFor(d1, p, &cache, nullptr, &first);
        QCOMPARE(first.stages, (std::vector<std::string>{"import", "voxelize", "light"}));

        JobLog again;
        const DensityGrid d2 = densityForMesh(job, &cache, nullptr, &again);
        const LightingGrid l2 = lightingFor(d2, p, &cache, nullptr, &again);
        QCOMPARE(again.stages, (std::vector<std::string>{"import", "voxelize (cache hit)", "light (cache hit)"}));
        QVERIFY(d2.density == d1.density && l2.rgb == l1.rgb);

        // A sun move relights but does not revoxelize; a grid change does both.
        JobLog sunMoved;
        p.sun = {1.0f, 1.0f, 0.0f};
        lightingFor(densityForMesh(job, &cache, nullptr, &sunMoved), p, &cache, nullptr, &sunMoved);
        QCOMPARE(sunMoved.stages, (std::vector<std::string>{"import", "voxelize (cache hit)", "light"}));
        JobLog regrid;
        job.voxel.longestAxisNodes = 22;
        lightingFor(densityForMesh(job, &cache, nullptr, &regrid), p, &cache, nullptr, &regrid);
        QCOMPARE(regrid.stages, (std::vector<std::string>{"import", "voxelize", "light"}));
        // Sun vectors whose float length overflows still get distinct keys.
        JobLog huge1, huge2;
        p.sun = {1e20f, 0.0f, 0.0f};
        lightingFor(densityForMesh(job, &cache, nullptr, &huge1), p, &cache, nullptr, &huge1);
        p.sun = {0.0f, 1e20f, 0.0f};
        lightingFor(densityForMesh(job, &cache, nullptr, &huge2), p, &cache, nullptr, &huge2);
        QCOMPARE(huge2.stages.back(), std::string("light"));
        p.sun = {1.0f, 1.0f, 0.0f};
        // Block depth does not change a fixed-step answer, so it is not part of that key.
        JobLog blocked;
        p.blockSteps = 3;
        lightingFor(densityForMesh(job, &cache, nullptr, &blocked), p, &cache, nullptr, &blocked);
        QCOMPARE(blocked.stages.back(), std::string("light (cache hit)"));
    }

    void damagedEntryIsRecomputed()
    {
        const std::string dir = (m_dir + "/cache-damaged").toStdString();
        GridCache cache(dir);
        DensityJob job{m_mesh, {}, {}};
        job.voxel.longestAxisNodes = 16;
        lb::LbParams p = lb::paramsFromPreset(*lb::findPreset("leaf"));
        const DensityGrid d = densityForMesh(job, &cache, nullptr, nullptr);
        const LightingGrid good = lightingFor(d, p, &cache, nullptr, nullptr);
        // Flip one payload byte of the lighting entry.
        QDir entries(QString::fromStdString(dir) + "/grids");
        const QStringList files = entries.entryList({"*.l.sgrid"}, QDir::Files);
        QCOMPARE(files.size(), 1);
        QFile f(entries.filePath(files[0]));
        QVERIFY(f.open(QIODevice::ReadWrite));
        f.seek(f.size() - 5);
        char c;
        f.getChar(&c);
        f.seek(f.size() - 5);
        f.putChar(char(c ^ 0x40));
        f.close();
        JobLog log;
        const LightingGrid again = lightingFor(d, p, &cache, nullptr, &log);
        QCOMPARE(log.stages, (std::vector<std::string>{"light"}));
        QVERIFY(!log.warnings.empty());
        QVERIFY2(QString::fromStdString(log.warnings[0]).contains("corrupt"), log.warnings[0].c_str());
        QVERIFY(again.rgb == good.rgb);
        // Truncated entry: also detected and recomputed.
        QVERIFY(QFile::resize(entries.filePath(files[0]), 200));
        JobLog log2;
        const LightingGrid third = lightingFor(d, p, &cache, nullptr, &log2);
        QCOMPARE(log2.stages, (std::vector<std::string>{"light"}));
        QVERIFY(third.rgb == good.rgb);
    }

    // GridCache::setBeforeCompute (sylva render --mpi's rank 0): the hook runs once, only when a miss would
    // compute, and what it stored is then loaded, not computed again. Here it solves through a second cache
    // object on the same folder, as another rank would; its grids are the ones a plain solve gives.
    void beforeComputeRunsOnceOnAMiss()
    {
        const std::string dir = (m_dir + "/cache-hook").toStdString();
        DensityJob job{m_mesh, {}, {}};
        job.voxel.longestAxisNodes = 18;
        lb::LbParams p = lb::paramsFromPreset(*lb::findPreset("leaf"));
        p.sun = {0.3f, 1.0f, -0.2f};
        GridCache cache(dir), other(dir);
        int runs = 0;
        std::vector<std::string> otherStages;
        cache.setBeforeCompute([&] {
            ++runs;
            JobLog o;
            lightingFor(densityForMesh(job, &other, nullptr, &o), p, &other, nullptr, &o);
            otherStages = o.stages;
        });
        JobLog log;
        const DensityGrid d = densityForMesh(job, &cache, nullptr, &log);
        const LightingGrid l = lightingFor(d, p, &cache, nullptr, &log);
        QCOMPARE(runs, 1);
        QCOMPARE(otherStages, (std::vector<std::string>{"import", "voxelize", "light"}));
        QCOMPARE(log.stages, (std::vector<std::string>{"import", "voxelize (cache hit)", "light (cache hit)"}));
        const DensityGrid dRef = densityForMesh(job, nullptr, nullptr, nullptr);
        QVERIFY(d.density == dRef.density);
        QVERIFY(l.rgb == lightingFor(dRef, p, nullptr, nullptr, nullptr).rgb);
        // Cleared once it ran: the next miss (another sun) solves here.
        p.sun = {-0.5f, 1.0f, 0.0f};
        JobLog next;
        lightingFor(d, p, &cache, nullptr, &next);
        QCOMPARE(runs, 1);
        QCOMPARE(next.stages, (std::vector<std::string>{"light"}));
        // A warm cache never runs it.
        GridCache warm(dir);
        warm.setBeforeCompute([&] { ++runs; });
        JobLog hit;
        lightingFor(densityForMesh(job, &warm, nullptr, &hit), p, &warm, nullptr, &hit);
        QCOMPARE(runs, 1);
        QCOMPARE(hit.stages, (std::vector<std::string>{"import", "voxelize (cache hit)", "light (cache hit)"}));
    }

    // The sidecar parameters (`sylva light`, the studio's grid export) are valid JSON holding the
    // parameters as given, steps or tolerance, and a preset name that cannot break the object.
    void paramsJson()
    {
        lb::LbParams p = lb::paramsFromPreset(*lb::findPreset("dogrose"));
        p.sun = glm::vec3(0.25f, -0.5f, 0.75f);
        p.intensity = glm::vec3(1.0f, 0.5f, 2.0f);
        p.tolerance = 0.0;
        p.steps = 0;
        const QJsonObject o = QJsonDocument::fromJson(QByteArray::fromStdString(lightingParamsJson(p, "dog\"rose", {9, 5, 7}))).object();
        QVERIFY(!o.isEmpty());
        QCOMPARE(o["preset"].toString(), QStringLiteral("dogrose"));
        for (int c = 0; c < 3; ++c) {
            QCOMPARE(float(o["sigma_a"].toArray()[c].toDouble()), p.channels[size_t(c)].sigmaA);
            QCOMPARE(float(o["sigma_s"].toArray()[c].toDouble()), p.channels[size_t(c)].sigmaS);
            QCOMPARE(float(o["g"].toArray()[c].toDouble()), p.channels[size_t(c)].g);
            QCOMPARE(float(o["sun"].toArray()[c].toDouble()), p.sun[c]);
            QCOMPARE(float(o["intensity"].toArray()[c].toDouble()), p.intensity[c]);
        }
        QCOMPARE(o["steps"].toInt(), lb::defaultSteps({9, 5, 7}));
        QVERIFY(!o.contains("tolerance"));
        p.tolerance = 1e-3;
        const QJsonObject t = QJsonDocument::fromJson(QByteArray::fromStdString(lightingParamsJson(p, "leaf", {9, 5, 7}))).object();
        QCOMPARE(t["tolerance"].toDouble(), 1e-3);
        QVERIFY(!t.contains("steps"));
    }
};

QTEST_GUILESS_MAIN(TestLightingJob)
#include "tst_lighting_job.moc"
