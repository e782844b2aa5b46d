// sylva-studio: the Qt desktop application; everything lives in sylva_studio_lib.
#include <QApplication>

#include "studio/main_window.h"

int main(int argc, char** argv)
{
    QApplication app(argc, argv);
    QApplication::setOrganizationName("Sylva");
    QApplication::setApplicationName("sylva-studio");
    QApplication::setApplicationVersion(SYLVA_VERSION);
    sylva::MainWindow window;
    window.resize(1400, 860);
    window.show();
    for (const QString& arg : QApplication::arguments().mid(1)) window.openFile(arg);
    return QApplication::exec();
}
