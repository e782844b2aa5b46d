// The command-line tests' one way to run a program of ours in a child process: its exit code (-1 when it
// did not exit normally), standard output and standard error.
#pragma once

#include <QProcess>
#include <QProcessEnvironment>
#include <QString>
#include <QStringList>

namespace sylva::test {

struct Run {
    int code = -1;
    QString out, err;
};

inline Run runProgram(const QString& program, const QStringList& args,
                      const QProcessEnvironment& env = QProcessEnvironment::systemEnvironment(), int timeoutMs = 600000)
{
    QProcess p;
    p.setProcessEnvironment(env);
    p.start(program, args);
    p.waitForFinished(timeoutMs);
    return {p.exitStatus() == QProcess::NormalExit ? p.exitCode() : -1, QString::fromUtf8(p.readAllStandardOutput()),
            QString::fromUtf8(p.readAllStandardError())};
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
