// sylva-studio: the Qt desktop application; everything lives in sylva_studio_lib.
#include <QApplication>

#include "studio/command_line.h"
#include "studio/main_window.h"

int main(int argc, char** argv)
{
    QApplication::setOrganizationName("Sylva");
    QApplication::setApplicationName("sylva-studio");
    QApplication::setApplicationVersion(SYLVA_VERSION);
    if (sylva::studioWantsOnlyInfo(argc, argv)) {   // --help, --version: answered without a display
        QCoreApplication core(argc, argv);
        return sylva::parseStudioCommandLine(QCoreApplication::arguments()).exitCode;
    }
    QApplication app(argc, argv);
    const sylva::StudioCommandLine line = sylva::parseStudioCommandLine(QApplication::arguments());
    if (line.action == sylva::StudioCommandLine::Action::Exit) return line.exitCode;
    sylva::MainWindow window;
    window.resize(1400, 860);
    window.show();   // the last session's size, place and docks come back here (MainWindow::restoreLayout)
    if (!line.scene.isEmpty()) window.openFile(line.scene);
    return QApplication::exec();
}
