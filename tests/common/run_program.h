// The tests' one way to run a program in a child process: its exit code (-1 when it did not start, did not
// exit normally or ran past its time, and then standard error says which), standard output and standard error.
#pragma once

#include <QProcess>
#include <QProcessEnvironment>
#include <QRegularExpression>
#include <QString>
#include <QStringList>

#include <map>
#include <set>

namespace sylva::test {

struct Run {
    int code = -1;
    QString out, err;
};

// `program ARGS` in the folder workDir (when given; else this process's), killed after timeoutMs.
inline Run runProgram(const QString& program, const QStringList& args,
                      const QProcessEnvironment& env = QProcessEnvironment::systemEnvironment(), int timeoutMs = 600000,
                      const QString& workDir = {})
{
    QProcess p;
    p.setProcessEnvironment(env);
    if (!workDir.isEmpty()) p.setWorkingDirectory(workDir);
    p.start(program, args);
    if (!p.waitForStarted()) return {-1, QString(), program + " did not start: " + p.errorString()};
    if (!p.waitForFinished(timeoutMs)) {
        p.kill();
        p.waitForFinished();
        return {-1, QString::fromUtf8(p.readAllStandardOutput()),
                QString::fromUtf8(p.readAllStandardError()) + "\n" + program + " timed out after " + QString::number(timeoutMs / 1000) + " s"};
    }
    return {p.exitStatus() == QProcess::NormalExit ? p.exitCode() : -1, QString::fromUtf8(p.readAllStandardOutput()),
            QString::fromUtf8(p.readAllStandardError())};
}

// Every command `sylva --help` lists, with the options its own `--help` lists (lines "  -x ...": "-h, --help"
// names two; --output also answers to -o): what the docs, the man page and the completion must name.
inline std::map<QString, std::set<QString>> sylvaHelpTable(const QString& sylva)
{
    std::map<QString, std::set<QString>> table;
    bool inCommands = false;
    static const QRegularExpression commandLine("^  ([a-z][a-z0-9-]*) ");   // "  render     render a scene ..."
    for (const QString& line : runProgram(sylva, {"--help"}).out.split('\n')) {
        if (line.startsWith("commands:")) {
            inCommands = true;
            continue;
        }
        if (inCommands && line.trimmed().isEmpty()) break;
        const QRegularExpressionMatch m = commandLine.match(line);
        if (inCommands && m.hasMatch()) table[m.captured(1)];
    }
    static const QRegularExpression optionLine("^  (-\\S+)");
    for (auto& [name, options] : table) {
        for (const QString& line : runProgram(sylva, {name, "--help"}).out.split('\n')) {
            if (!optionLine.match(line).hasMatch()) continue;
            for (QString word : line.trimmed().split(' ', Qt::SkipEmptyParts)) {
                if (!word.startsWith('-')) break;
                word.remove(',');
                options.insert(word);
            }
        }
        if (options.count("--output")) options.insert("-o");   // its help line: "output file (also -o)"
    }
    return table;
}

#ifdef SYLVA_CLI_PATH
// `sylva ARGS`; cacheDir (when given) becomes its XDG_CACHE_HOME, so the grid cache lives there.
inline Run runSylva(const QStringList& args, const QString& cacheDir = {})
{
    QProcessEnvironment env = QProcessEnvironment::systemEnvironment();
    if (!cacheDir.isEmpty()) env.insert("XDG_CACHE_HOME", cacheDir);
    return runProgram(SYLVA_CLI_PATH, args, env);
}
#endif

} // namespace sylva::test
