// sylva-studio's command line through QCommandLineParser (command_line.h).
#include "studio/command_line.h"

#include <cstdio>
#include <cstring>

#include <QCommandLineParser>
#include <QCoreApplication>

namespace sylva {

StudioCommandLine parseStudioCommandLine(const QStringList& arguments)
{
    QCommandLineParser parser;
    parser.setApplicationDescription(QStringLiteral("Sylva studio: lay out, light (lattice-Boltzmann) and render forests."));
    const QCommandLineOption help = parser.addHelpOption();
    const QCommandLineOption version = parser.addVersionOption();
    parser.addPositionalArgument(QStringLiteral("scene"), QStringLiteral("A scene file (*.sylva.json) to open."), QStringLiteral("[scene]"));
    StudioCommandLine result;
    if (!parser.parse(arguments)) {
        std::fprintf(stderr, "sylva-studio: %s (see sylva-studio --help)\n", qPrintable(parser.errorText()));
        return {StudioCommandLine::Action::Exit, 2, {}};
    }
    if (parser.isSet(help) || parser.isSet(QStringLiteral("help-all"))) {
        std::fputs(qPrintable(parser.helpText()), stdout);
        return {StudioCommandLine::Action::Exit, 0, {}};
    }
    if (parser.isSet(version)) {
        std::printf("%s %s\n", qPrintable(QCoreApplication::applicationName()), qPrintable(QCoreApplication::applicationVersion()));
        return {StudioCommandLine::Action::Exit, 0, {}};
    }
    const QStringList scenes = parser.positionalArguments();
    if (scenes.size() > 1) {
        std::fprintf(stderr, "sylva-studio: one scene at a time (got %lld: %s) (see sylva-studio --help)\n", (long long)scenes.size(),
                     qPrintable(scenes.join(QLatin1Char(' '))));
        return {StudioCommandLine::Action::Exit, 2, {}};
    }
    result.scene = scenes.value(0);
    return result;
}

bool studioWantsOnlyInfo(int argc, char** argv)
{
    for (int a = 1; a < argc; ++a) {
        const char* s = argv[a];
        if (!std::strcmp(s, "-h") || !std::strcmp(s, "--help") || !std::strcmp(s, "-?") || !std::strcmp(s, "--help-all") ||
            !std::strcmp(s, "-v") || !std::strcmp(s, "--version"))
            return true;
    }
    return false;
}

} // namespace sylva
