// cmake --install: the build tree installed into a temporary prefix (install only, no
// rebuild). The installed sylva runs from there (--version, a render that needs its bundled colour
// table); the man page and the bash completion name every command and option the binary's own --help
// lists; the .desktop file, icon and MIME type fit together (Qt's MIME database, reading the prefix,
// maps *.sylva.json to the type the desktop file opens).
#include <QDir>
#include <QFile>
#include <QMimeDatabase>
#include <QProcess>
#include <QRegularExpression>
#include <QTemporaryDir>
#include <QTest>

#include <algorithm>
#include <map>
#include <set>

#include <QStandardPaths>

#include "pipeline/io/image_io.h"
#include "tests/common/files.h"
#include "tests/common/run_program.h"

namespace {

using sylva::test::readText;
using sylva::test::Run;

Run run(const QString& program, const QStringList& args, const QString& cwd = QString(), int timeoutMs = 120000)
{
    return sylva::test::runProgram(program, args, QProcessEnvironment::systemEnvironment(), timeoutMs, cwd);
}

// A one-triangle scene, tri.sylva.json with its mesh tri.obj, in `dir`: 16 x 8 pixels, local mode.
bool writeTriangleScene(const QTemporaryDir& dir)
{
    QFile obj(dir.filePath("tri.obj"));
    if (!obj.open(QIODevice::WriteOnly)) return false;
    obj.write("v -1 0 -1\nv 1 0 -1\nv 0 0 1\nf 1 2 3\n");
    obj.close();
    QFile scene(dir.filePath("tri.sylva.json"));
    if (!scene.open(QIODevice::WriteOnly)) return false;
    scene.write(R"({"version": 1, "species": [{"name": "tri", "mesh": "tri.obj"}],
                    "instances": [{"species": "tri", "position": [0, 0.5, 0]}],
                    "camera": {"position": [0, 3, -3], "target": [0, 0, 0]},
                    "render": {"width": 16, "height": 8, "mode": "local"}})");
    return true;
}

} // namespace

class TestInstall : public QObject {
    Q_OBJECT

    QTemporaryDir m_prefix;
    QString m_sylva;
    std::map<QString, std::set<QString>> m_table;

    QString installed(const QString& rel) const { return m_prefix.filePath(rel); }

private Q_SLOTS:
    void initTestCase()
    {
        QVERIFY(m_prefix.isValid());
        const Run r = run(CMAKE_COMMAND, {"--install", SYLVA_BUILD_DIR, "--prefix", m_prefix.path()});
        QVERIFY2(r.code == 0, qPrintable(r.out + r.err));
        m_sylva = installed("bin/sylva");
        m_table = sylva::test::sylvaHelpTable(m_sylva);
        QVERIFY2(m_table.size() >= 7, qPrintable(QString::number(m_table.size())));
        QVERIFY(m_table.count("render") && m_table.at("render").count("--passes"));
    }

    void filesInPlace()
    {
        for (const char* rel : {"bin/sylva", "bin/sylva-studio", "share/applications/sylva-studio.desktop",
                                "share/icons/hicolor/scalable/apps/sylva-studio.svg", "share/mime/packages/sylva-scene.xml",
                                "share/man/man1/sylva.1", "share/bash-completion/completions/sylva",
                                "share/sylva/default_forest.sylva.json", "share/sylva/color/cie1931_2deg_xyz_cmf_360-830_1nm.csv",
                                "share/sylva/ocio/config.ocio"})
            QVERIFY2(QFileInfo(installed(rel)).size() > 0, rel);
        QVERIFY(QFileInfo(installed("bin/sylva")).isExecutable());
        QVERIFY(QFileInfo(installed("bin/sylva-studio")).isExecutable());
        // OpenImageIO's module, where the programs look for it relative to their folder (image_module.h)
        const QString module = installed(QString(SYLVA_INSTALL_LIBDIR) + "/sylva/libsylva_oiio.so");
        QVERIFY2(QFileInfo(module).size() > 0, qPrintable(module));
    }

    // The installed binary, run from a folder outside the build and source trees.
    void installedSylvaRuns()
    {
        QTemporaryDir work;
        const Run v = run(m_sylva, {"--version"}, work.path());
        QCOMPARE(v.code, 0);
        QVERIFY2(v.out.startsWith(QString("sylva ") + SYLVA_VERSION), qPrintable(v.out));
        // A one-triangle scene: the sun's colour comes from the bundled CIE table (a resource).
        QVERIFY(writeTriangleScene(work));
        // The installed program draws the picture the build tree's draws (the same linear values: a missing or
        // other colour table would change the sun's colour).
        const Run r = run(m_sylva, {"render", "tri.sylva.json", "-o", "tri.exr", "--quiet", "--no-cache"}, work.path());
        QVERIFY2(r.code == 0, qPrintable(r.out + r.err));
        const Run b = run(QStringLiteral(SYLVA_BUILD_DIR "/pipeline/sylva"),
                          {"render", "tri.sylva.json", "-o", "built.exr", "--quiet", "--no-cache"}, work.path());
        QVERIFY2(b.code == 0, qPrintable(b.out + b.err));
        const sylva::ImageRgba mine = sylva::readImage(work.filePath("tri.exr").toStdString()), built = sylva::readImage(work.filePath("built.exr").toStdString());
        QCOMPARE(mine.width, 16);
        QCOMPARE(mine.height, 8);
        QVERIFY(mine.pixels == built.pixels);
        float lit = 0.0f;
        for (size_t p = 0; p < mine.pixels.size(); p += 4) lit = std::max(lit, mine.pixels[p + 1]);
        QVERIFY2(lit > 0.0f, "the triangle should be lit");
    }

    // The installed Python module: found by its interpreter with PYTHONPATH on the installed folder only, it renders
    // the one-triangle scene to the picture the build tree's sylva draws, writing it through the OpenImageIO module it
    // finds relative to its own file.
    void installedPythonModuleRenders()
    {
#ifndef SYLVA_PYTHON
        QSKIP("this build has no Python module (pybind11 not found)");
#else
        const QString folder = installed(SYLVA_PYTHON_INSTALL_DIR);
        QVERIFY2(!QDir(folder).entryList({"sylva*.so"}, QDir::Files).isEmpty(), qPrintable(folder));
        QVERIFY2(QFileInfo(folder + "/" + SYLVA_PYTHON_TO_IMAGE_MODULE).isFile(), SYLVA_PYTHON_TO_IMAGE_MODULE);
        QTemporaryDir work;
        QVERIFY(writeTriangleScene(work));
        QProcessEnvironment env = QProcessEnvironment::systemEnvironment();
        env.insert("PYTHONPATH", folder);
        env.insert("PYTHONDONTWRITEBYTECODE", "1");
        const char* script = "import sylva, os\n"
                             "print(os.path.dirname(sylva.__file__))\n"
                             "sylva.render(sylva.Scene.load('tri.sylva.json'), cache=False).save('py.exr')\n";
        const sylva::test::Run p = sylva::test::runProgram(SYLVA_PYTHON, {"-c", script}, env, 120000, work.path());
        QVERIFY2(p.code == 0, qPrintable(p.out + p.err));
        QCOMPARE(QDir(p.out.trimmed()).canonicalPath(), QDir(folder).canonicalPath());
        const Run b = run(QStringLiteral(SYLVA_BUILD_DIR "/pipeline/sylva"),
                          {"render", "tri.sylva.json", "-o", "built.exr", "--quiet", "--no-cache"}, work.path());
        QVERIFY2(b.code == 0, qPrintable(b.out + b.err));
        const sylva::ImageRgba mine = sylva::readImage(work.filePath("py.exr").toStdString());
        const sylva::ImageRgba built = sylva::readImage(work.filePath("built.exr").toStdString());
        QCOMPARE(mine.width, 16);
        QVERIFY(mine.pixels == built.pixels);
#endif
    }

    // Every command and every option of the binary's --help pages in sylva(1); groff reads it without warnings.
    void manPageNamesEverything()
    {
        QString man = readText(installed("share/man/man1/sylva.1"));
        QVERIFY(man.startsWith(".\\\"") || man.startsWith(".TH"));
        man.replace("\\-", "-");
        for (const char* font : {"\\fB", "\\fI", "\\fR", "\\fP"}) man.remove(font);
        for (const auto& [name, options] : m_table) {
            QVERIFY2(man.contains(QString(".SH \"SYLVA %1\"").arg(name)), qPrintable(name));
            QVERIFY2(man.contains(QString(".B %1\n").arg(name)), qPrintable(name));
            for (const QString& o : options)
                QVERIFY2(man.contains(QRegularExpression(QString("(^|[^-\\w])%1([^-\\w]|$)").arg(QRegularExpression::escape(o)))),
                         qPrintable(name + " " + o));
        }
        if (!QStandardPaths::findExecutable("groff").isEmpty()) {
            const Run g = run("groff", {"-man", "-ww", "-z", installed("share/man/man1/sylva.1")});
            QVERIFY2(g.code == 0 && g.err.trimmed().isEmpty(), qPrintable(g.err));
        }
    }

    // Bash, with the installed completion loaded, offers exactly the table's commands after `sylva`,
    // exactly a command's options after `sylva CMD -`, and a placeholder's choices after its option.
    void completionOffersEverything()
    {
        QString script = "source '" + installed("share/bash-completion/completions/sylva") + "'\n"
                         "complete -p sylva >/dev/null || exit 3\n"
                         "ask() { COMP_WORDS=(\"$@\"); COMP_CWORD=$((${#COMP_WORDS[@]} - 1)); COMPREPLY=(); _sylva; "
                         "echo \"${COMPREPLY[*]}\"; }\n"
                         "ask sylva ''\n";
        for (const auto& [name, options] : m_table) script += "ask sylva " + name + " -\n";
        script += "ask sylva render --backend ''\n";
        const Run r = run("bash", {"--norc", "-c", script});
        QVERIFY2(r.code == 0, qPrintable(r.err));
        const QStringList lines = r.out.split('\n');
        QCOMPARE(lines.size(), int(m_table.size()) + 3);   // + commands, + --backend, + the final newline
        auto words = [](const QString& line) {
            const QStringList w = line.split(' ', Qt::SkipEmptyParts);
            return std::set<QString>(w.begin(), w.end());
        };
        std::set<QString> commands{"--help", "--version"};
        for (const auto& entry : m_table) commands.insert(entry.first);
        QCOMPARE(words(lines[0]), commands);
        int i = 1;
        for (const auto& [name, options] : m_table) {
            const std::set<QString> got = words(lines[i++]);
            QVERIFY2(got == options, qPrintable(name + ": completion " + QStringList(got.begin(), got.end()).join(' ') +
                                                  " vs help " + QStringList(options.begin(), options.end()).join(' ')));
        }
        QCOMPARE(words(lines[i]), (std::set<QString>{"auto", "cpu", "cuda"}));
    }

    // The desktop entry starts the installed studio with the file, shows the installed icon, and opens
    // the MIME type that the installed MIME package gives *.sylva.json.
    void desktopIntegration()
    {
        const QString desktop = readText(installed("share/applications/sylva-studio.desktop"));
        std::map<QString, QString> entry;
        for (const QString& line : desktop.split('\n'))
            if (line.contains('=') && !line.startsWith('#')) entry[line.section('=', 0, 0)] = line.section('=', 1);
        QCOMPARE(entry["Type"], QString("Application"));
        const QStringList exec = entry["Exec"].split(' ');
        QVERIFY2(QFileInfo(installed("bin/" + exec.value(0))).isExecutable(), qPrintable(entry["Exec"]));
        QVERIFY(exec.contains("%f") || exec.contains("%F") || exec.contains("%u") || exec.contains("%U"));
        QVERIFY(QFileInfo(installed("share/icons/hicolor/scalable/apps/" + entry["Icon"] + ".svg")).exists());
        const QStringList types = entry["MimeType"].split(';', Qt::SkipEmptyParts);
        QVERIFY(types.contains("application/x-sylva-scene"));
        if (!QStandardPaths::findExecutable("desktop-file-validate").isEmpty()) {
            const Run v = run("desktop-file-validate", {installed("share/applications/sylva-studio.desktop")});
            QVERIFY2(v.code == 0, qPrintable(v.out + v.err));
        }
        if (!QStandardPaths::findExecutable("update-mime-database").isEmpty()) {
            const Run u = run("update-mime-database", {installed("share/mime")});
            QVERIFY2(u.code == 0, qPrintable(u.err));
            QVERIFY(readText(installed("share/mime/globs2")).contains("application/x-sylva-scene:*.sylva.json"));
        }
        // Qt's MIME database over the prefix (and the system's, for application/json).
        qputenv("XDG_DATA_DIRS", (m_prefix.path() + "/share:/usr/local/share:/usr/share").toUtf8());
        const QMimeType t = QMimeDatabase().mimeTypeForFile(m_prefix.filePath("forest.sylva.json"), QMimeDatabase::MatchExtension);
        QCOMPARE(t.name(), QString("application/x-sylva-scene"));
        QVERIFY(t.inherits("application/json"));
        QVERIFY(types.contains(t.name()));
    }

    // docs/BUILD.md lists exactly the packages build.sh installs.
    void buildDocListsThePackages()
    {
        const QString script = readText(SYLVA_SOURCE_DIR "/build.sh");
        const QRegularExpressionMatch array = QRegularExpression("\\nPACKAGES=\\((.*?)\\)\\n",
                                                                 QRegularExpression::DotMatchesEverythingOption).match(script);
        QVERIFY(array.hasMatch());
        QStringList fromScript;
        for (const QString& line : array.captured(1).split('\n'))
            fromScript += line.section('#', 0, 0).split(QRegularExpression("\\s+"), Qt::SkipEmptyParts);
        const QString doc = readText(SYLVA_SOURCE_DIR "/docs/BUILD.md");
        const qsizetype marker = doc.indexOf("exactly `build.sh`'s list");
        QVERIFY(marker >= 0);
        const qsizetype open = doc.indexOf("```text\n", marker), close = doc.indexOf("```", open + 8);
        QVERIFY(open > marker && close > open);
        const QStringList fromDoc = doc.mid(open + 8, close - open - 8).split(QRegularExpression("\\s+"), Qt::SkipEmptyParts);
        QVERIFY(fromScript.size() > 10);
        QCOMPARE(fromDoc, fromScript);
    }
};

QTEST_GUILESS_MAIN(TestInstall)
#include "tst_install.moc"
