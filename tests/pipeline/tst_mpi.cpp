// sylva render --mpi under mpirun (label mpi; registered only when MPI and mpirun are there): the picture at
// 1, 2 and 3 ranks against a single-process render of the same scene, byte for byte, in every mode, in
// bands and as the passes' 32-bit float layers; a killed and a stopped rank end the job non-zero within a
// bounded time with no picture; ranks of different executables are refused; --mpi outside mpirun.
#include <QDir>
#include <QElapsedTimer>
#include <QFile>
#include <QFileInfo>
#include <QProcess>
#include <QTemporaryDir>
#include <QThread>
#include <QtTest>

#include <OpenImageIO/imageio.h>

#include <csignal>
#include <sys/types.h>
#include <unistd.h>

#include "pipeline/render/render_job.h"
#include "pipeline/scene/scene_file.h"
#include "tests/common/run_program.h"

using namespace sylva;
using test::Run;

namespace {

// mpirun's options for one machine: oversubscribed (CI has 2 cores), as root where the tests run as root,
// shared memory only (no network probing).
QStringList mpirunArgs(int ranks)
{
    QStringList a{"--oversubscribe"};
    if (::geteuid() == 0) a << "--allow-run-as-root";
    a << "--mca" << "btl" << "self,vader" << "-np" << QString::number(ranks);
    return a;
}

QProcessEnvironment mpiEnv(const QString& cache)
{
    QProcessEnvironment env = QProcessEnvironment::systemEnvironment();
    env.insert("XDG_CACHE_HOME", cache);
    env.insert("OMPI_MCA_btl_vader_single_copy_mechanism", "none");   // no ptrace-based copies in containers
    env.insert("OMPI_MCA_hwloc_base_binding_policy", "none");        // ranks oversubscribe the cores
    env.insert("OMPI_MCA_pml", "ob1");                               // shared memory: no 0.2 s UCX probe in MPI_Init
    return env;
}

QByteArray fileBytes(const QString& path)
{
    QFile f(path);
    if (!f.open(QIODevice::ReadOnly)) return {};
    return f.readAll();
}

// An EXR's channel names and its pixels as 32-bit floats (the files themselves differ: they carry the time
// they were written).
QByteArray exrPixels(const QString& path)
{
    auto in = OIIO::ImageInput::open(path.toStdString());
    if (!in) return {};
    const OIIO::ImageSpec& spec = in->spec();
    QByteArray out;
    for (const std::string& name : spec.channelnames) out += QByteArray::fromStdString(name) + ',';
    std::vector<float> px(size_t(spec.width) * size_t(spec.height) * size_t(spec.nchannels));
    if (!in->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::FLOAT, px.data())) return {};
    out += QByteArray(reinterpret_cast<const char*>(px.data()), qsizetype(px.size() * sizeof(float)));
    return out;
}

// The pid of the rank `rank` among mpirun's children (its environment names the rank), 0 when not found.
pid_t rankPid(qint64 mpirunPid, int rank)
{
    const QByteArray want = "OMPI_COMM_WORLD_RANK=" + QByteArray::number(rank);
    for (const QString& entry : QDir("/proc").entryList(QDir::Dirs)) {
        bool ok = false;
        const qint64 pid = entry.toLongLong(&ok);
        if (!ok) continue;
        const QByteArray stat = fileBytes("/proc/" + entry + "/stat");
        const int close = stat.lastIndexOf(')');
        if (close < 0) continue;
        const QList<QByteArray> fields = stat.mid(close + 2).split(' ');
        if (fields.size() < 2 || fields[1].toLongLong() != mpirunPid) continue;
        for (const QByteArray& var : fileBytes("/proc/" + entry + "/environ").split('\0'))
            if (var == want) return pid_t(pid);
    }
    return 0;
}

} // namespace

class TestMpi : public QObject {
    Q_OBJECT
    QTemporaryDir m_dir;
    QString m_cache, m_scene;

    // options: more of mpirun's (e.g. -x NAME=VALUE for the ranks' environment).
    Run mpirun(int ranks, const QStringList& renderArgs, const QStringList& launch = {}, const QStringList& options = {})
    {
        QStringList a = mpirunArgs(ranks) << options;
        if (launch.isEmpty()) a << SYLVA_CLI_PATH << "render" << "--mpi" << renderArgs;
        else a = launch;
        return test::runProgram(SYLVA_MPIEXEC, a, mpiEnv(m_cache), 120000);
    }

    Run single(const QStringList& renderArgs)
    {
        return test::runProgram(SYLVA_CLI_PATH, QStringList{"render"} << renderArgs, mpiEnv(m_cache), 120000);
    }

private Q_SLOTS:
    void initTestCase()
    {
        QVERIFY(m_dir.isValid());
        m_cache = QString(SYLVA_TEST_OUTPUT) + "/mpi-cache";
        // The default forest (its 962 instances, camera and sun) with light species, so CI grows, lights
        // and builds it in a second per process.
        Scene s = defaultScene();
        for (SpeciesDesc& sp : s.species) {
            QVERIFY(sp.grow.has_value());
            sp.grow->triangles = std::max<uint64_t>(2000, sp.grow->triangles / 40);
            sp.grid = 16;
        }
        m_scene = m_dir.filePath("forest.sylva.json");
        writeSceneFile(s, m_scene.toStdString());
        // Grow and light the species once, into the cache the ranks share.
        const Run r = single({m_scene, "--width", "8", "--height", "8", "-o", m_dir.filePath("warm.png"), "--quiet"});
        QVERIFY2(r.code == 0, qPrintable(r.err));
    }

    void picturesEqualSingleProcess_data()
    {
        QTest::addColumn<QString>("mode");
        for (const char* m : {"full", "local", "ambient", "lb"}) QTest::newRow(m) << QString(m);
    }
    // Every mode at 1, 2 and 3 ranks: the PNG file is byte for byte the single process's (96 x 40, 2 spp:
    // 8-pixel tiles at 3 ranks, so every rank traces several); the scene handed out by rank 0 (the
    // default: one copy per host, which this machine is) and, at 2 ranks, built by every rank (--mpi-scene
    // each). Then the several-host paths on this one machine (SYLVA_MPI_NODE_SIZE): 3 ranks as hosts of 2 and 1
    // (rank 0 fills its host's shared copy, rank 2 receives the broadcast into its own) and 2 ranks as two hosts.
    void picturesEqualSingleProcess()
    {
        QFETCH(QString, mode);
        const QStringList common{m_scene, "--width", "96", "--height", "40", "--spp", "2", "--mode", mode, "--quiet"};
        const QString ref = m_dir.filePath("single_" + mode + ".png");
        Run r = single(QStringList(common) << "-o" << ref);
        QVERIFY2(r.code == 0, qPrintable(r.err));
        const QByteArray want = fileBytes(ref);
        QVERIFY(!want.isEmpty());
        for (int ranks = 1; ranks <= 3; ++ranks) {
            const QString out = m_dir.filePath(QString("mpi%1_%2.png").arg(ranks).arg(mode));
            r = mpirun(ranks, QStringList(common) << "-o" << out);
            QVERIFY2(r.code == 0, qPrintable(r.err));
            QVERIFY2(r.out.contains(QString("%1 MPI rank").arg(ranks)), qPrintable(r.out));
            if (ranks > 1) QVERIFY2(r.out.contains(QString("%1 MPI ranks on 1 host ").arg(ranks)), qPrintable(r.out));
            QVERIFY2(fileBytes(out) == want, qPrintable(QString("%1 ranks, mode %2: the picture differs").arg(ranks).arg(mode)));
        }
        const struct {
            int ranks, perHost;
            const char* says;
        } hosts[] = {{3, 2, "3 MPI ranks on 2 hosts"}, {2, 1, "2 MPI ranks on 2 hosts"}};
        for (const auto& h : hosts) {
            const QString out = m_dir.filePath(QString("mpi%1_hosts_%2.png").arg(h.ranks).arg(mode));
            r = mpirun(h.ranks, QStringList(common) << "-o" << out, {}, {"-x", QString("SYLVA_MPI_NODE_SIZE=%1").arg(h.perHost)});
            QVERIFY2(r.code == 0, qPrintable(r.err));
            QVERIFY2(r.out.contains(h.says), qPrintable(r.out));
            QVERIFY2(fileBytes(out) == want, qPrintable(QString("%1, mode %2: the picture differs").arg(h.says).arg(mode)));
        }
        const QString each = m_dir.filePath(QString("mpi_each_%1.png").arg(mode));
        r = mpirun(2, QStringList(common) << "--mpi-scene" << "each" << "--threads" << "1" << "-o" << each);
        QVERIFY2(r.code == 0, qPrintable(r.err));
        QVERIFY2(fileBytes(each) == want, qPrintable(QString("--mpi-scene each, mode %1: the picture differs").arg(mode)));
    }

    // The bundled cloud (volume arrays) and landscape (terrain, cells and tiles) at 2 ranks: the broadcast
    // frame carries every array kind, so the picture is still the single process's to the bit.
    void volumeAndLandscapeEqualSingleProcess_data()
    {
        QTest::addColumn<QString>("name");
        QTest::newRow("cloud") << "cloud";
        QTest::newRow("landscape") << "landscape";
    }
    void volumeAndLandscapeEqualSingleProcess()
    {
        QFETCH(QString, name);
        const QString sceneFile = QString(SYLVA_SOURCE_DIR) + "/resources/" + name + ".sylva.json";
        const QStringList common{sceneFile, "--width", "64", "--height", "36", "--quiet"};
        const QString ref = m_dir.filePath("single_" + name + ".png"), out = m_dir.filePath("mpi2_" + name + ".png");
        Run r = single(QStringList(common) << "-o" << ref);
        QVERIFY2(r.code == 0, qPrintable(r.err));
        r = mpirun(2, QStringList(common) << "-o" << out);
        QVERIFY2(r.code == 0, qPrintable(r.err));
        QVERIFY(!fileBytes(ref).isEmpty());
        QVERIFY2(fileBytes(out) == fileBytes(ref), qPrintable(name + ": the picture differs"));
    }

    // The shading parts themselves (the passes' 32-bit float layers: direct, indirect, albedo, sky,
    // normal, depth, alpha) and a frame in bands (the tiles of each band from the queue) at 2 and 3 ranks.
    void passesAndBandsEqualSingleProcess()
    {
        const QStringList common{m_scene, "--width", "72", "--height", "36", "--spp", "3", "--quiet"};
        const QString refExr = m_dir.filePath("single_passes.exr"), refBands = m_dir.filePath("single_bands.exr");
        Run r = single(QStringList(common) << "--passes" << "-o" << refExr);
        QVERIFY2(r.code == 0, qPrintable(r.err));
        r = single(QStringList(common) << "--mode" << "ambient" << "--band-rows" << "8" << "-o" << refBands);
        QVERIFY2(r.code == 0, qPrintable(r.err));
        for (int ranks : {2, 3}) {
            const QString exr = m_dir.filePath(QString("mpi%1_passes.exr").arg(ranks));
            r = mpirun(ranks, QStringList(common) << "--passes" << "-o" << exr);
            QVERIFY2(r.code == 0, qPrintable(r.err));
            const QByteArray want = exrPixels(refExr);
            QVERIFY(want.contains("DiffInd") && want.size() > 72 * 36 * 8 * 4);
            QVERIFY2(exrPixels(exr) == want, "the passes differ");
            const QString bands = m_dir.filePath(QString("mpi%1_bands.exr").arg(ranks));
            r = mpirun(ranks, QStringList(common) << "--mode" << "ambient" << "--band-rows" << "8" << "-o" << bands);
            QVERIFY2(r.code == 0, qPrintable(r.err));
            QVERIFY2(r.err.contains("5 bands"), qPrintable(r.err));
            QVERIFY(!exrPixels(refBands).isEmpty());
            QVERIFY2(exrPixels(bands) == exrPixels(refBands), "the frame in bands differs");
        }
    }

    // Species lighting across the ranks: with an empty cache, 2 ranks share the 5 species' LB solves
    // (rank 0 species 0, 2 and 4, rank 1 species 1 and 3), each solved once, and the picture equals a
    // single process's from that cache; a second run solves none. Both ways of getting the scene: rank 0
    // asks the others for their share when its render misses (broadcast), or every rank lights its share
    // before building its own scene (each).
    void speciesLitAcrossRanks_data()
    {
        QTest::addColumn<QString>("scene");
        QTest::newRow("broadcast") << "broadcast";
        QTest::newRow("each") << "each";
    }
    void speciesLitAcrossRanks()
    {
        QFETCH(QString, scene);
        QTemporaryDir fresh;
        const QString out = m_dir.filePath("shared_lit_" + scene + ".png"), ref = m_dir.filePath("shared_lit_single_" + scene + ".png");
        const QStringList common{m_scene, "--cache", fresh.path(), "--width", "48", "--height", "24", "--quiet"};
        Run r = mpirun(2, QStringList(common) << "--mpi-scene" << scene << "-o" << out);
        QVERIFY2(r.code == 0, qPrintable(r.err));
        QVERIFY2(r.out.contains("species lighting on 2 ranks: 5 LB solves (3 + 2 by rank)"), qPrintable(r.out));
        r = mpirun(2, QStringList(common) << "--mpi-scene" << scene << "-o" << out);
        QVERIFY2(r.code == 0, qPrintable(r.err));
        QVERIFY2(r.out.contains("species lighting on 2 ranks: 0 LB solves (0 + 0 by rank)"), qPrintable(r.out));
        r = single(QStringList(common) << "-o" << ref);
        QVERIFY2(r.code == 0, qPrintable(r.err));
        QVERIFY(!fileBytes(ref).isEmpty());
        QCOMPARE(fileBytes(out), fileBytes(ref));
    }

    // A rank killed (SIGKILL) or stopped (SIGSTOP: it hangs) while the frame is traced (512 spp: tens of
    // seconds of tracing even on idle cores, so the signal lands mid-frame; the job ends first): mpirun exits
    // non-zero by itself (120 s bound only a hang), rank 0 says what happened, and neither the picture nor a temporary file is left.
    // A rank stopped as soon as it exists ("hung at start": before MPI_Init, or in it) ends the job
    // through the start bound (2 x --mpi-timeout + 5 s).
    void deadOrHungRankEndsTheJob_data()
    {
        QTest::addColumn<int>("signal");
        QTest::addColumn<bool>("atStart");
        QTest::addColumn<QString>("message");
        QTest::newRow("killed") << int(SIGKILL) << false << "";
        QTest::newRow("hung") << int(SIGSTOP) << false << "rank 1 on";
        QTest::newRow("hung at start") << int(SIGSTOP) << true << "did not all start within 11 s";
    }
    void deadOrHungRankEndsTheJob()
    {
        QFETCH(int, signal);
        QFETCH(bool, atStart);
        QFETCH(QString, message);
        QTemporaryDir outDir;
        const QString out = outDir.filePath("frame.png");
        QProcess p;
        p.setProcessEnvironment(mpiEnv(m_cache));
        p.setProcessChannelMode(QProcess::SeparateChannels);
        p.start(SYLVA_MPIEXEC, mpirunArgs(2) << SYLVA_CLI_PATH << "render" << "--mpi" << "--mpi-timeout" << "3" << m_scene << "--width"
                                              << "320" << "--height" << "160" << "--spp" << "512" << "-o" << out);
        QVERIFY(p.waitForStarted());
        QByteArray err;
        QElapsedTimer wait;
        wait.start();
        pid_t victim = 0;
        if (atStart) {
            // As soon as rank 1's process is there.
            while (!(victim = rankPid(p.processId(), 1)) && wait.elapsed() < 30000 && p.state() == QProcess::Running) QTest::qWait(1);
        } else {
            // Wait until rank 0 reports tracing (its progress lines on stderr).
            while (!err.contains("tracing") && wait.elapsed() < 60000 && p.state() == QProcess::Running) {
                p.waitForReadyRead(200);
                err += p.readAllStandardError();
            }
            QVERIFY2(err.contains("tracing"), err.constData());
            victim = rankPid(p.processId(), 1);
        }
        QVERIFY(victim > 0);
        QCOMPARE(::kill(victim, signal), 0);
        QElapsedTimer t;
        t.start();
        const bool ended = p.waitForFinished(120000);   // bounds a hang only: the job must end by itself
        if (!ended) {
            ::kill(victim, SIGKILL);
            p.kill();
            p.waitForFinished(5000);
        }
        QVERIFY2(ended, "the job did not end after a rank was signalled");
        err += p.readAllStandardError();
        qInfo("the job ended %.1f s after the signal", double(t.elapsed()) / 1000.0);
        QVERIFY(p.exitStatus() != QProcess::NormalExit || p.exitCode() != 0);
        if (!message.isEmpty()) QVERIFY2(err.contains(message.toUtf8()), err.constData());
        if (!message.isEmpty() && !atStart) QVERIFY2(err.contains("sent nothing"), err.constData());
        QVERIFY2(err.contains("no picture was written") || err.contains("exited on signal 9"), err.constData());
        QVERIFY(!QFileInfo::exists(out));
        QVERIFY2(QDir(outDir.path()).entryList(QDir::Files | QDir::Hidden).isEmpty(), "a file was left beside the picture");
        if (signal == SIGSTOP) ::kill(victim, SIGKILL);   // in case it outlived the job
    }

    // A rank of another executable (the same program with one byte appended) is refused at start.
    void differentBuildsAreRefused()
    {
        const QString other = m_dir.filePath("sylva-other");
        QVERIFY(QFile::copy(SYLVA_CLI_PATH, other));
        QFile f(other);
        QVERIFY(f.open(QIODevice::Append));
        f.write("x", 1);
        f.close();
        QVERIFY(f.setPermissions(f.permissions() | QFileDevice::ExeOwner));
        const QString out = m_dir.filePath("builds.png");
        const QStringList render{"render", "--mpi", m_scene, "--width", "16", "--height", "8", "-o", out, "--quiet"};
        QStringList launch = mpirunArgs(1) << SYLVA_CLI_PATH << render << ":" << "-np" << "1" << other << render;
        const Run r = mpirun(2, {}, launch);
        QVERIFY(r.code != 0);
        QVERIFY2(r.err.contains("different builds") && r.err.contains("rank 1"), qPrintable(r.err));
        QVERIFY(!QFileInfo::exists(out));
        // The same executable twice passes the check.
        launch = mpirunArgs(1) << SYLVA_CLI_PATH << render << ":" << "-np" << "1" << SYLVA_CLI_PATH << render;
        const Run ok = mpirun(2, {}, launch);
        QVERIFY2(ok.code == 0, qPrintable(ok.err));
        QVERIFY(QFileInfo::exists(out));
    }

    // --mpi without mpirun: a usage error that says how to launch it, before any work.
    void mpiOutsideMpirun()
    {
        const Run r = single({"--mpi", m_scene, "-o", m_dir.filePath("no.png")});
        QCOMPARE(r.code, 2);
        QVERIFY2(r.err.contains("not started by mpirun"), qPrintable(r.err));
        QVERIFY(!QFileInfo::exists(m_dir.filePath("no.png")));
        const Run scene = single({"--mpi-scene", "each", m_scene, "-o", m_dir.filePath("no.png")});
        QCOMPARE(scene.code, 2);
        QVERIFY2(scene.err.contains("--mpi-scene: applies to --mpi only"), qPrintable(scene.err));
        QVERIFY(!QFileInfo::exists(m_dir.filePath("no.png")));
    }
};

QTEST_GUILESS_MAIN(TestMpi)
#include "tst_mpi.moc"
