// The distributed LB grid under mpirun (label mpi; registered only when MPI and mpirun are there). This
// program is both the test (run by ctest) and its ranks (run by the mpirun it starts): at 2 and 3 ranks
// each rank solves its slab of an odd-sized grid with medium (uneven slabs) through
// mpi::solveDistributed, and rank 0 compares the gathered grid with the single-process solveLighting
// to the bit, fp32 and fp16. `sylva light --mpi` at 2 ranks writes the file the single process writes,
// byte for byte. A rank that stops (SIGSTOP) before its first halo ends the job non-zero through the
// bounded halo wait (its message names the stopped rank and the wait's limit), without help from outside.
#include <QFile>
#include <QTemporaryDir>
#include <QtTest>

#include <csignal>
#include <cstdio>
#include <cstring>
#include <random>
#include <unistd.h>

#include "core/lb/lb_params.h"
#include "core/lb/lb_solver.h"
#include "pipeline/io/npy.h"
#include "pipeline/mpi/mpi_lb.h"
#include "pipeline/mpi/mpi_render.h"
#include "tests/common/run_program.h"

using namespace sylva;
using test::Run;

namespace {

// A cloud with wood in a 23 x 14 x 11 grid: 21 interior planes, 11 + 10 at 2 ranks, 7 each at 3.
DensityGrid testDensity()
{
    DensityGrid g;
    g.geometry.dims = {23, 14, 11};
    std::mt19937 rng(11);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    g.density.assign(g.geometry.nodeCount(), 0.0f);
    g.woodFraction.assign(g.geometry.nodeCount(), 0.0f);
    for (int i = 0; i < 23; ++i)
        for (int j = 0; j < 14; ++j)
            for (int k = 0; k < 11; ++k) {
                const float r2 = float((i - 11) * (i - 11)) / 81.0f + float((j - 7) * (j - 7)) / 30.0f + float((k - 5) * (k - 5)) / 20.0f;
                if (r2 > 1.0f) continue;
                const size_t n = g.geometry.index(i, j, k);
                g.density[n] = 0.2f + 0.8f * u(rng);
                g.woodFraction[n] = u(rng) < 0.15f ? 1.0f : 0.0f;
            }
    return g;
}

lb::LbParams testParams(bool fp16)
{
    lb::LbParams p = lb::paramsFromPreset(*lb::findPreset("leaf"));
    p.channels[1] = {0.25f, 0.6f, 0.5f};
    p.sun = glm::vec3(-0.5f, 1.0f, 0.25f);
    p.intensity = glm::vec3(1.0f, 1.5f, 0.75f);
    p.storage = fp16 ? lb::Storage::Fp16 : lb::Storage::Fp32;
    p.steps = 30;
    return p;
}

// A rank of the job: "solve" compares both storages with the single process on rank 0 (exit 0 when
// equal), "stop" has rank 1 stop itself before its first halo.
int rankMain(const char* what)
{
    const bool stop = std::strcmp(what, "stop") == 0;
    return mpi::runLightSession(
        [&](int rank, int ranks) {
            if (stop && rank == 1) std::raise(SIGSTOP);
            const DensityGrid d = testDensity();
            int failed = 0;
            for (bool fp16 : {false, true}) {
                const lb::LbParams p = testParams(fp16);
                mpi::DistributedStats st;
                const LightingGrid got = mpi::solveDistributed(d, p, nullptr, &st);
                if (rank != 0) continue;
                const LightingGrid want = lb::solveLighting(d, p);
                size_t differ = want.rgb.size() == got.rgb.size() ? 0 : want.rgb.size();
                for (size_t i = 0; i < std::min(want.rgb.size(), got.rgb.size()); ++i)
                    differ += std::memcmp(&want.rgb[i], &got.rgb[i], sizeof(float)) != 0;
                double sum = 0.0;
                for (float v : want.rgb) sum += v;
                std::printf("ranks=%d storage=%s steps=%d solves=%d planes0=%d differ=%zu of %zu sum=%.6g\n", ranks, fp16 ? "fp16" : "fp32",
                            st.steps, st.solves, st.ownedPlanes, differ, want.rgb.size(), sum);
                failed += differ != 0 || !(sum > 0.0);
            }
            std::fflush(stdout);
            return failed ? 1 : 0;
        },
        2.0);
}

QStringList mpirunArgs(int ranks)
{
    QStringList a{"--oversubscribe"};
    if (::geteuid() == 0) a << "--allow-run-as-root";
    a << "--mca" << "btl" << "self,vader" << "--bind-to" << "none" << "-np" << QString::number(ranks);
    return a;
}

QProcessEnvironment mpiEnv()
{
    QProcessEnvironment env = QProcessEnvironment::systemEnvironment();
    env.insert("OMPI_MCA_btl_vader_single_copy_mechanism", "none");
    env.insert("OMPI_MCA_hwloc_base_binding_policy", "none");
    return env;
}

QByteArray fileBytes(const QString& path)
{
    QFile f(path);
    if (!f.open(QIODevice::ReadOnly)) return {};
    return f.readAll();
}

} // namespace

class TestMpiLb : public QObject {
    Q_OBJECT
    QTemporaryDir m_dir;

private Q_SLOTS:
    void slabsEqualSingleProcess_data()
    {
        QTest::addColumn<int>("ranks");
        QTest::newRow("2 ranks") << 2;
        QTest::newRow("3 ranks") << 3;
    }
    void slabsEqualSingleProcess()
    {
        QFETCH(int, ranks);
        const Run r = test::runProgram(SYLVA_MPIEXEC, mpirunArgs(ranks) << QCoreApplication::applicationFilePath() << "--rank" << "solve",
                                       mpiEnv(), 120000);
        QVERIFY2(r.code == 0, qPrintable(r.out + r.err));
        for (const char* s : {"fp32", "fp16"})
            QVERIFY2(r.out.contains(QString("ranks=%1 storage=%2 steps=30 solves=3").arg(ranks).arg(s)) &&
                         r.out.count("differ=0 of 10626") == 2,
                     qPrintable(r.out));
        QVERIFY2(r.out.contains(ranks == 2 ? "planes0=11" : "planes0=7"), qPrintable(r.out));
    }

    // The command: the same file and sidecar as the single process (fp16 default, --part scattered).
    void lightCommandEqualsSingleProcess()
    {
        QVERIFY(m_dir.isValid());
        const QString density = m_dir.filePath("d.npy");
        const DensityGrid d = testDensity();
        writeDensityGrid(density.toStdString(), d);   // with its wood fraction beside it
        // --part scattered: two distributed solves (all light, then scattering off) and their difference.
        for (const QString& part : {QString("scattered")}) {
            const QStringList common{"light", "--density", density, "--sun", "0.3,1,-0.4", "--no-cache", "--quiet", "--part", part};
            const QString one = m_dir.filePath("one_" + part + ".npy"), two = m_dir.filePath("two_" + part + ".npy");
            Run r = test::runProgram(SYLVA_CLI_PATH, QStringList(common) << "-o" << one, mpiEnv(), 120000);
            QVERIFY2(r.code == 0, qPrintable(r.err));
            r = test::runProgram(SYLVA_MPIEXEC, mpirunArgs(2) << SYLVA_CLI_PATH << common << "--mpi" << "-o" << two, mpiEnv(), 120000);
            QVERIFY2(r.code == 0, qPrintable(r.out + r.err));
            QCOMPARE(r.out.count("wrote "), 1);   // rank 0 alone writes
            const QByteArray want = fileBytes(one);
            QVERIFY(want.size() > 23 * 14 * 11 * 12);
            QVERIFY2(fileBytes(two) == want, qPrintable(part));
            QVERIFY(fileBytes(two + ".json") == fileBytes(one + ".json"));
        }
        // Outside mpirun, and a tolerance solve, are refused as usage errors.
        Run r = test::runProgram(SYLVA_CLI_PATH, {"light", "--density", density, "--sun", "0,1,0", "--mpi", "-o", m_dir.filePath("x.npy")}, mpiEnv());
        QCOMPARE(r.code, 2);
        QVERIFY2(r.err.contains("not started by mpirun"), qPrintable(r.err));
        r = test::runProgram(SYLVA_MPIEXEC, mpirunArgs(2) << SYLVA_CLI_PATH << "light" << "--density" << density << "--sun" << "0,1,0" << "--tol" << "1e-4"
                                                          << "--mpi" << "-o" << m_dir.filePath("x.npy"),
                             mpiEnv(), 120000);
        QVERIFY(r.code != 0);
        QVERIFY2(r.err.contains("fixed step count"), qPrintable(r.err));
        QVERIFY(!QFile::exists(m_dir.filePath("x.npy")));
    }

    // Rank 1 stops before its first halo: rank 0's bounded halo wait (runLightSession's 2 s timeout, see
    // rankMain) ends the job, naming the stopped rank and the limit it waited, and mpirun exits by itself
    // (the 120 s wait here only bounds a hang: without the bounded wait the job would never end).
    void stoppedRankEndsTheJob()
    {
        QProcess p;
        p.setProcessEnvironment(mpiEnv());
        p.start(SYLVA_MPIEXEC, mpirunArgs(2) << QCoreApplication::applicationFilePath() << "--rank" << "stop");
        QVERIFY(p.waitForStarted());
        const bool ended = p.waitForFinished(120000);
        if (!ended) {
            p.kill();
            p.waitForFinished();
        }
        const QString out = QString::fromUtf8(p.readAllStandardOutput()), err = QString::fromUtf8(p.readAllStandardError());
        QVERIFY2(ended, qPrintable("the job with a stopped rank did not end: " + out + err));
        QVERIFY2(p.exitStatus() != QProcess::NormalExit || p.exitCode() != 0, qPrintable(out + err));
        // waitAll's message: "rank 0: no halo plane from rank 1 for N s (a rank hung, ...)", N the 2 s
        // timeout plus three times the (short) time since the step began, rounded.
        static const QRegularExpression bounded(QStringLiteral("no halo plane from rank 1 for ([0-9]+) s \\(a rank hung"));
        const QRegularExpressionMatch m = bounded.match(err);
        QVERIFY2(m.hasMatch(), qPrintable(err));
        QVERIFY2(m.captured(1).toInt() >= 2, qPrintable(err));
        QVERIFY2(!out.contains("differ="), qPrintable(out));   // no rank got as far as comparing a grid
    }
};

int main(int argc, char** argv)
{
    if (argc == 3 && std::strcmp(argv[1], "--rank") == 0 && mpi::launchedByMpi()) return rankMain(argv[2]);
    QCoreApplication app(argc, argv);
    TestMpiLb t;
    return QTest::qExec(&t, argc, argv);
}

#include "tst_mpi_lb.moc"
