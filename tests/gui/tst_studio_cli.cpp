// sylva-studio's command line (--help, --version, a scene, bad usage; --help without a display) and
// its window layout, saved on close and restored by the next window (under Xvfb).
#include <QDockWidget>
#include <QProcess>
#include <QSettings>
#include <QTest>

#include "studio/command_line.h"
#include "studio_test_util.h"
#include "tests/common/run_program.h"

using namespace sylva;
using namespace sylva::test;

namespace {

Run runStudio(const QStringList& args, const QProcessEnvironment& env = QProcessEnvironment::systemEnvironment())
{
    return runProgram(QStringLiteral(SYLVA_STUDIO_PATH), args, env, 60000);
}

} // namespace

class TstStudioCli : public QObject {
    Q_OBJECT

    QTemporaryDir m_dir;

private Q_SLOTS:
    void helpAndVersion()
    {
        Run r = runStudio({"--help"});
        QCOMPARE(r.code, 0);
        QVERIFY2(r.out.contains(QLatin1String("Usage:")) && r.out.contains(QLatin1String("[scene]")) &&
                     r.out.contains(QLatin1String("--version")) && r.out.contains(QLatin1String("--help")),
                 qPrintable(r.out));
        r = runStudio({"--version"});
        QCOMPARE(r.code, 0);
        QCOMPARE(r.out, QStringLiteral("sylva-studio " SYLVA_VERSION "\n"));
        // Without any display: answered all the same (a QApplication would abort here).
        QProcessEnvironment headless = QProcessEnvironment::systemEnvironment();
        headless.remove("DISPLAY");
        headless.remove("WAYLAND_DISPLAY");
        headless.insert("QT_QPA_PLATFORM", "xcb");
        r = runStudio({"-h"}, headless);
        QVERIFY2(r.code == 0 && r.out.contains(QLatin1String("[scene]")), qPrintable(r.err));
        QCOMPARE(runStudio({"-v"}, headless).out, QStringLiteral("sylva-studio " SYLVA_VERSION "\n"));
        // Bad usage: exit 2 and a message, before any window opens.
        QProcessEnvironment offscreen = QProcessEnvironment::systemEnvironment();
        offscreen.insert("QT_QPA_PLATFORM", "offscreen");
        r = runStudio({"--bogus"}, offscreen);
        QCOMPARE(r.code, 2);
        QVERIFY2(r.err.contains(QLatin1String("bogus")), qPrintable(r.err));
        r = runStudio({"a.sylva.json", "b.sylva.json"}, offscreen);
        QCOMPARE(r.code, 2);
        QVERIFY2(r.err.contains(QLatin1String("one scene at a time")), qPrintable(r.err));
    }

    void sceneArgument()
    {
        StudioCommandLine line = parseStudioCommandLine({"sylva-studio", "forest.sylva.json"});
        QCOMPARE(int(line.action), int(StudioCommandLine::Action::Run));
        QCOMPARE(line.scene, QStringLiteral("forest.sylva.json"));
        line = parseStudioCommandLine({"sylva-studio", "--", "--help.sylva.json"});   // a file named like an option
        QCOMPARE(int(line.action), int(StudioCommandLine::Action::Run));
        QCOMPARE(line.scene, QStringLiteral("--help.sylva.json"));
        QVERIFY(parseStudioCommandLine({"sylva-studio"}).scene.isEmpty());
    }

    // A window whose inspector is shown and whose log moved to the left, closed; the next window shows
    // them so, at the same size. Without saved settings, the defaults (inspector hidden, log below).
    void layoutSavedAndRestored()
    {
        SYLVA_SKIP_WITHOUT_X();
        QVERIFY(m_dir.isValid());
        isolate(m_dir);
        auto open = [] {
            auto w = std::make_unique<MainWindow>();
            w->lighting()->setAutoLighting(false);
            w->setSavePrompt([](const QString&) { return QMessageBox::Discard; });
            w->resize(1000, 700);
            w->show();
            return w;
        };
        auto dock = [](MainWindow* w, const char* name) { return w->findChild<QDockWidget*>(QString::fromLatin1(name)); };
        {
            auto fresh = open();
            QVERIFY(QTest::qWaitForWindowExposed(fresh.get()));
            QVERIFY(!fresh->inspectorDock()->isVisible());
            QCOMPARE(fresh->dockWidgetArea(dock(fresh.get(), "logDock")), Qt::BottomDockWidgetArea);
            fresh->inspectorDock()->show();
            fresh->addDockWidget(Qt::LeftDockWidgetArea, dock(fresh.get(), "logDock"));
            fresh->resize(900, 640);
            // The window manager applies the new size and dock layout asynchronously: wait for them before
            // closing (what close saves is what the next window must show).
            QTRY_COMPARE_WITH_TIMEOUT(fresh->size(), QSize(900, 640), 60000);
            QTRY_VERIFY_WITH_TIMEOUT(fresh->inspectorDock()->isVisible(), 60000);
            QVERIFY(fresh->close());
        }
        QVERIFY(!QSettings().value("window/state").toByteArray().isEmpty());
        QVERIFY(!QSettings().value("window/geometry").toByteArray().isEmpty());
        {
            auto again = open();
            QVERIFY(QTest::qWaitForWindowExposed(again.get()));
            QTRY_VERIFY(again->inspectorDock()->isVisible());
            QCOMPARE(again->dockWidgetArea(dock(again.get(), "logDock")), Qt::LeftDockWidgetArea);
            QCOMPARE(again->size(), QSize(900, 640));
        }
        QSettings().remove("window");
        {
            auto fresh = open();
            QVERIFY(QTest::qWaitForWindowExposed(fresh.get()));
            QVERIFY(!fresh->inspectorDock()->isVisible());
            QCOMPARE(fresh->dockWidgetArea(dock(fresh.get(), "logDock")), Qt::BottomDockWidgetArea);
        }
    }
};

QTEST_MAIN(TstStudioCli)
#include "tst_studio_cli.moc"
