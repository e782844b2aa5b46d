// sylva's command-line manners: SIGINT/SIGTERM cancel a long job in its solve, exit 128 + signal and
// leave no temporary file and no partial cache entry; `sylva cache info|clean|limit`; `sylva --version`.
#include <QDir>
#include <QFile>
#include <QFileInfo>
#include <QProcess>
#include <QRegularExpression>
#include <QTest>

#include <csignal>
#include <memory>
#include <string_view>

#include "pipeline/cache/grid_cache.h"
#include "pipeline/io/atomic_file.h"
#include "pipeline/io/npy.h"
#include "tests/common/run_program.h"

using namespace sylva;

namespace {

using test::Run;

QString outDir()
{
    return QStringLiteral(SYLVA_TEST_OUTPUT "/cli_manners");
}

// Every run gets this test's settings folder (the cache size limit) and cache folder.
QProcessEnvironment environment()
{
    QProcessEnvironment env = QProcessEnvironment::systemEnvironment();
    env.insert("XDG_CONFIG_HOME", outDir() + "/config");
    env.insert("XDG_CACHE_HOME", outDir() + "/xdg-cache");
    return env;
}

Run runSylva(const QStringList& args, const QProcessEnvironment& env = environment())
{
    return test::runProgram(SYLVA_CLI_PATH, args, env);
}

// Files whose name starts with ".tmp." (AtomicFile's temporary files) anywhere under dir.
QStringList tempFiles(const QString& dir)
{
    QStringList found;
    for (const QFileInfo& f : QDir(dir).entryInfoList(QDir::Files | QDir::Hidden | QDir::Dirs | QDir::NoDotAndDotDot)) {
        if (f.isDir()) found += tempFiles(f.filePath());
        else if (f.fileName().startsWith(QLatin1String(".tmp."))) found << f.filePath();
    }
    return found;
}

uint64_t bytesIn(const QString& dir)
{
    uint64_t total = 0;
    for (const QFileInfo& f : QDir(dir).entryInfoList(QDir::Files | QDir::Hidden)) total += uint64_t(f.size());
    return total;
}

} // namespace

class TestCliManners : public QObject {
    Q_OBJECT

    QString m_tree, m_density, m_small;

    // Starts a long `sylva light` (a 128-node grid on one thread: tens of seconds), waits until its
    // progress says the LB solve is under way (the "light: 10%" line: the solve's steps have begun and
    // most are left), sends `sig`, and checks the exit: 128 + sig, one line naming the signal, no output,
    // no temporary file, and no cache entry (partial or whole) nor temporary file in the cache. The
    // process must exit by itself; the 120 s wait only bounds a hang.
    void cancelLight(int sig, const QString& name)
    {
        const QString dir = outDir() + "/" + name;
        QDir(dir).removeRecursively();
        QVERIFY(QDir().mkpath(dir));
        const QString cache = dir + "/cache";
        QProcess p;
        p.setProcessEnvironment(environment());
        p.start(SYLVA_CLI_PATH, {"light", "--density", m_density, "--threads", "1", "--sun", "0.3,1,0.2", "--cache", cache, "-o",
                                 dir + "/light.npy"});
        QVERIFY(p.waitForStarted());
        p.setReadChannel(QProcess::StandardError);   // waitForReadyRead waits on this channel
        // Progress goes to a pipe (not a terminal): one line per tenth, "light: 10% ...".
        const QRegularExpression inSolve(QStringLiteral("(^|\\n)light: [1-9]0% "));
        QString err;
        while (!err.contains(inSolve) && p.state() == QProcess::Running) {
            if (!p.waitForReadyRead(120000)) break;
            err += QString::fromUtf8(p.readAllStandardError());
        }
        QVERIFY2(err.contains(inSolve), qPrintable(err));
        QVERIFY2(!err.contains(QLatin1String("light: done")), qPrintable(err));   // a 128^3 solve on one thread: far from done
        QCOMPARE(p.state(), QProcess::Running);
        QCOMPARE(::kill(pid_t(p.processId()), sig), 0);
        QVERIFY2(p.waitForFinished(120000), "the signalled job did not exit");
        err += QString::fromUtf8(p.readAllStandardError());
        QCOMPARE(p.exitStatus(), QProcess::NormalExit);
        QCOMPARE(p.exitCode(), 128 + sig);
        QVERIFY2(!err.contains(QLatin1String("light: done")), qPrintable(err));   // cancelled, not finished
        const QStringList lines = err.trimmed().split(QLatin1Char('\n'));
        QVERIFY2(lines.last().contains(sig == SIGINT ? QLatin1String("cancelled by SIGINT") : QLatin1String("cancelled by SIGTERM")),
                 qPrintable(err));
        QVERIFY(!QFileInfo::exists(dir + "/light.npy"));
        QVERIFY(!QFileInfo::exists(dir + "/light.npy.json"));
        QVERIFY2(tempFiles(dir).isEmpty(), qPrintable(tempFiles(dir).join(QLatin1Char(' '))));
        QCOMPARE(QDir(cache + "/grids").entryList(QDir::Files | QDir::Hidden), QStringList());
        // The same job left alone stores its entry (so the empty folder above means something): a small
        // grid, lit to the end, leaves one whole lighting entry.
        const Run small = runSylva({"light", "--density", m_small, "--sun", "0.3,1,0.2", "--cache", cache, "-o", dir + "/small.npy"});
        QVERIFY2(small.code == 0, qPrintable(small.err));
        const QStringList entries = QDir(cache + "/grids").entryList(QDir::Files | QDir::Hidden);
        QCOMPARE(entries.size(), 1);
        const std::string text = describeCacheFile((cache + "/grids/" + entries[0]).toStdString());
        QVERIFY2(text.find("checksum:  ok") != std::string::npos, text.c_str());
    }

private Q_SLOTS:
    void initTestCase()
    {
        QDir(outDir()).removeRecursively();
        QVERIFY(QDir().mkpath(outDir()));
        // A box (12 triangles) for the runs from a mesh, and uniform densities (a medium in every node,
        // so every node collides) for the runs from a grid.
        m_tree = outDir() + "/box.obj";
        QFile box(m_tree);
        QVERIFY(box.open(QIODevice::WriteOnly));
        box.write("v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\n"
                  "f 1 3 2\nf 1 4 3\nf 5 6 7\nf 5 7 8\nf 1 2 6\nf 1 6 5\nf 4 7 3\nf 4 8 7\nf 1 5 8\nf 1 8 4\nf 2 3 7\nf 2 7 6\n");
        box.close();
        m_density = outDir() + "/density128.npy";
        m_small = outDir() + "/density16.npy";
        writeNpy(m_density.toStdString(), NpyArray{{128, 128, 128}, std::vector<float>(size_t(128) * 128 * 128, 0.05f)});
        writeNpy(m_small.toStdString(), NpyArray{{16, 16, 16}, std::vector<float>(size_t(16) * 16 * 16, 0.05f)});
    }

    void version()
    {
        const Run r = runSylva({"--version"});
        QCOMPARE(r.code, 0);
        const QStringList lines = r.out.split(QLatin1Char('\n'));
        QCOMPARE(lines[0], QStringLiteral("sylva " SYLVA_VERSION));
        QVERIFY2(lines.value(1).startsWith(QLatin1String("backends: cpu")), qPrintable(r.out));
        QVERIFY2(runSylva({"--help"}).out.contains(QRegularExpression("\\n  cache +the grid cache")), "sylva --help lists cache");
    }

    // OpenImageIO (about 260 libraries) is a module loaded when an image is first read or written: sylva
    // --version loads none of it (the dynamic loader's own log says which libraries it opened), and a
    // render whose module cannot be found fails before it renders, naming SYLVA_IMAGE_MODULE, with no file.
    void imageModuleLoadedOnUse()
    {
        QProcessEnvironment traced = environment();
        traced.insert("LD_DEBUG", "libs");
        const Run v = runSylva({"--version"}, traced);
        QCOMPARE(v.code, 0);
        QVERIFY2(v.err.contains(QLatin1String("libsylva_core")) || v.err.contains(QLatin1String("libc.so")), "LD_DEBUG logged nothing");
        QVERIFY2(!v.err.contains(QLatin1String("libOpenImageIO")), "sylva --version loaded OpenImageIO");

        const QString picture = outDir() + "/no_module.png";
        QFile::remove(picture);
        QProcessEnvironment missing = environment();
        missing.insert("SYLVA_IMAGE_MODULE", outDir() + "/nowhere/libsylva_oiio.so");
        const Run r = runSylva({"render", "--width", "32", "--height", "16", "--no-cache", "-o", picture}, missing);
        QCOMPARE(r.code, 1);
        QVERIFY2(r.err.contains(QLatin1String("SYLVA_IMAGE_MODULE")) && r.err.contains(QLatin1String("no such file")), qPrintable(r.err));
        QVERIFY2(!r.err.contains(QLatin1String("render: done")), qPrintable(r.err));   // failed before rendering
        QVERIFY(!QFileInfo::exists(picture));
    }

    // What a second signal runs before it exits: the temporary files of the writers still open go, a
    // committed file and files of writers that finished stay.
    void pendingTemporaryFilesRemoved()
    {
        const std::string dir = (outDir() + "/pending").toStdString();
        QDir(QString::fromStdString(dir)).removeRecursively();
        AtomicFile done(dir + "/done.npy");
        done.write(std::string_view("done"));
        done.commit();
        std::vector<std::unique_ptr<AtomicFile>> open;
        for (int i = 0; i < 3; ++i) {
            open.push_back(std::make_unique<AtomicFile>(dir + "/open" + std::to_string(i) + ".npy"));
            open.back()->write(std::string_view("partial"));
        }
        open.erase(open.begin());   // abandoned normally: its own destructor removed it
        QCOMPARE(tempFiles(QString::fromStdString(dir)).size(), 2);
        removePendingAtomicFiles();
        QCOMPARE(tempFiles(QString::fromStdString(dir)), QStringList());
        QVERIFY(QFileInfo::exists(QString::fromStdString(dir + "/done.npy")));
        open.clear();   // their destructors find nothing left to remove
        QCOMPARE(QDir(QString::fromStdString(dir)).entryList(QDir::Files | QDir::Hidden), QStringList{"done.npy"});
    }

    void sigintCancelsLight() { cancelLight(SIGINT, "sigint"); }
    void sigtermCancelsLight() { cancelLight(SIGTERM, "sigterm"); }

    // info, clean and limit against the folder's files as listed here.
    void cacheCommand()
    {
        const QString cache = outDir() + "/cache-cmd";
        QDir(cache).removeRecursively();
        Run r = runSylva({"cache", "info", "--cache", cache});
        QCOMPARE(r.code, 0);
        QVERIFY2(r.out.contains(QLatin1String("entries:   0 (0 density, 0 lighting)")), qPrintable(r.out));
        QVERIFY2(r.out.contains(QLatin1String("limit:     20.00 GiB")), qPrintable(r.out));   // the default

        r = runSylva({"light", "--mesh", m_tree, "--grid", "16", "--sun", "0,1,0", "--cache", cache, "-o", outDir() + "/small.npy"});
        QVERIFY2(r.code == 0, qPrintable(r.err));
        QVERIFY(QFileInfo::exists(cache + "/CACHEDIR.TAG"));
        const QString grids = cache + "/grids";
        const uint64_t total = bytesIn(grids);
        r = runSylva({"cache", "info", "--cache", cache});
        QCOMPARE(r.code, 0);
        QVERIFY2(r.out.contains(QLatin1String("entries:   2 (1 density, 1 lighting)")), qPrintable(r.out));
        QVERIFY2(r.out.contains(QStringLiteral("(%1 bytes)").arg(total)), qPrintable(r.out));
        QVERIFY2(r.out.contains(QLatin1String("oldest:")) && r.out.contains(QLatin1String("just now")), qPrintable(r.out));

        // Nothing is a day old; then down to the larger entry's size: the density (used first) goes.
        r = runSylva({"cache", "clean", "--older-than", "1d", "--cache", cache});
        QCOMPARE(r.code, 0);
        QVERIFY2(r.out.startsWith(QLatin1String("removed 0 file(s)")), qPrintable(r.out));
        QCOMPARE(QDir(grids).entryList(QDir::Files).size(), 2);
        const QString lighting = QDir(grids).entryList({"*.l.sgrid"}).value(0);
        const qint64 lightingBytes = QFileInfo(grids + "/" + lighting).size();
        r = runSylva({"cache", "clean", "--max-size", QString::number(lightingBytes), "--cache", cache});
        QCOMPARE(r.code, 0);
        QCOMPARE(QDir(grids).entryList(QDir::Files), QStringList{lighting});
        r = runSylva({"cache", "clean", "--cache", cache});
        QCOMPARE(r.code, 0);
        QVERIFY2(r.out.startsWith(QLatin1String("removed 1 file(s)")), qPrintable(r.out));
        QVERIFY(QDir(grids).entryList(QDir::Files).isEmpty());

        // The limit setting, as `limit` and `info` show it.
        r = runSylva({"cache", "limit", "1G"});
        QVERIFY2(r.code == 0, qPrintable(r.err));
        QVERIFY(runSylva({"cache", "info", "--cache", cache}).out.contains(QLatin1String("limit:     1.00 GiB (1073741824 bytes)")));
        QCOMPARE(runSylva({"cache", "limit", "none"}).code, 0);
        QCOMPARE(runSylva({"cache", "limit"}).out.trimmed(), QStringLiteral("none"));

        // Bad usage: exit 2 with a message naming the problem.
        const QList<QStringList> bad = {{"cache", "frob"}, {"cache", "clean", "--older-than", "3y"}, {"cache", "info", "--max-size", "1G"},
                                        {"cache", "limit", "lots"}};
        for (const QStringList& args : bad) {
            r = runSylva(args);
            QVERIFY2(r.code == 2 && !r.err.isEmpty(), qPrintable(args.join(' ') + ": " + QString::number(r.code) + " " + r.err));
        }
    }
};

QTEST_GUILESS_MAIN(TestCliManners)
#include "tst_cli_manners.moc"
