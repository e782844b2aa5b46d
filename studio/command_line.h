// sylva-studio's command line (QCommandLineParser): --help, --version and an optional scene file.
#pragma once

#include <QString>
#include <QStringList>

namespace sylva {

struct StudioCommandLine {
    enum class Action { Run, Exit };
    Action action = Action::Run;
    int exitCode = 0;   // with Action::Exit: 0 after --help/--version, 2 after bad usage
    QString scene;      // the scene to open (empty: a new scene)
};

// Parses the arguments (argv[0] first; Qt's own -platform/-style options already removed by
// QApplication, or never given). --help and --version print on stdout and return Exit with 0; an
// unknown option or more than one scene prints the problem on stderr and returns Exit with 2.
StudioCommandLine parseStudioCommandLine(const QStringList& arguments);

// True when the arguments ask only for --help or --version (-h, -?, -v too), which main answers
// without a display.
bool studioWantsOnlyInfo(int argc, char** argv);

} // namespace sylva
