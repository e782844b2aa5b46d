// File > Export Scene as glTF (ExportController::exportGltf) under Xvfb: driven through the menu action and its
// save dialog, the .glb read back by the tests' own GLB reader (tests/common/glb_reader.h): each instance's mesh box
// placed by the file's TRANSLATION / ROTATION / SCALE equals the studio's instanceBounds of that box; the count and
// the size logged; above the limit the job fails with them and writes nothing.
#include <QAction>
#include <QAbstractButton>
#include <QFileDialog>
#include <QLineEdit>
#include <QSignalSpy>
#include <QTimer>

#include "studio_test_util.h"
#include "tests/common/glb_reader.h"

using namespace sylva;
using namespace sylva::test;

namespace {

// Names `path` in a save dialog and accepts it (the name typed as well: selectFile alone can lose to the dialog's
// own initial name while its folder loads).
void answerSaveDialog(QFileDialog* d, const QString& path)
{
    d->selectFile(path);
    if (auto* name = d->findChild<QLineEdit*>("fileNameEdit")) name->setText(QFileInfo(path).fileName());
    static_cast<QDialog*>(d)->accept();   // QFileDialog::accept, reached through the public slot
}

} // namespace

class TstStudioGltf : public QObject {
    Q_OBJECT

    QTemporaryDir m_dir;

private Q_SLOTS:
    void initTestCase()
    {
        SYLVA_SKIP_WITHOUT_X();
        QVERIFY(m_dir.isValid());
        isolate(m_dir);
    }

    void exportThroughTheMenu()
    {
        auto w = std::make_unique<MainWindow>();
        QStringList errors;
        quietWindow(*w, &errors);
        w->lighting()->setAutoLighting(false);
        Scene scene = treeScene();
        scene.instances[1].rotationDeg = {15.0f, 40.0f, -25.0f};
        scene.instances[2].scale = 1.3f;
        w->document()->edit(scene, "set up");
        QSignalSpy lines(w->exporter(), &StudioController::logLine);

        // The action opens the save dialog; the test names the file in it.
        QAction* action = w->findChild<QAction*>("actionExportGltf");
        QVERIFY(action);
        QCOMPARE(action->text().remove('&'), QStringLiteral("Export Scene as glTF..."));
        const QString path = m_dir.filePath("studio.glb");
        bool answered = false;
        QTimer poll;
        connect(&poll, &QTimer::timeout, this, [&] {
            auto* d = qobject_cast<QFileDialog*>(QApplication::activeModalWidget());
            if (!d || answered) return;
            answered = true;
            answerSaveDialog(d, path);
        });
        poll.start(50);
        action->trigger();
        poll.stop();
        QVERIFY2(answered, "no file dialog");
        auto exported = [&] {
            for (const QList<QVariant>& l : lines)
                if (l[0].toString().startsWith(QLatin1String("exported"))) return true;
            return false;
        };
        QVERIFY2(QTest::qWaitFor(exported, 60000), qPrintable(errors.join('\n')));
        QVERIFY(errors.isEmpty());
        // The count and the size, in the log and the controller.
        const GltfPlan& plan = w->exporter()->lastGltfPlan();
        QCOMPARE(plan.instances, size_t(3));
        QCOMPARE(qint64(plan.estimatedBytes), QFileInfo(path).size());
        bool counted = false;
        for (const QList<QVariant>& l : lines) counted = counted || l[0].toString().contains(QLatin1String("3 instances"));
        QVERIFY(counted);

        // Read back: one species node with three instances, each placing the mesh box where instanceBounds does.
        const Glb g = readGlb(path);
        QVERIFY2(structureProblems(g).isEmpty(), qPrintable(structureProblems(g)));
        QString problem;
        const std::vector<SpeciesNode> nodes = instancedNodes(g, &problem);
        QVERIFY2(problem.isEmpty(), qPrintable(problem));
        QCOMPARE(nodes.size(), size_t(1));
        QCOMPARE(nodes[0].instances.size(), size_t(3));
        const QJsonObject pos = g.json["accessors"].toArray()[g.json["meshes"].toArray()[nodes[0].mesh].toObject()["primitives"]
                                                                 .toArray()[0].toObject()["attributes"].toObject()["POSITION"].toInt()].toObject();
        Bounds3 box;   // the mesh's box as the file states it (POSITION's min and max)
        for (int c = 0; c < 3; ++c) box.lo[c] = float(pos["min"].toArray()[c].toDouble()), box.hi[c] = float(pos["max"].toArray()[c].toDouble());
        double worst = 0.0;
        for (size_t i = 0; i < 3; ++i) {
            const Bounds3 want = instanceBounds(scene, scene.instances[i], box);
            Bounds3 got;
            for (int k = 0; k < 8; ++k)
                got.extend(glm::vec3(nodes[0].instances[i].apply(glm::dvec3((k & 1) ? box.hi.x : box.lo.x, (k & 2) ? box.hi.y : box.lo.y,
                                                                            (k & 4) ? box.hi.z : box.lo.z))));
            worst = std::max({worst, double(glm::length(got.lo - want.lo)), double(glm::length(got.hi - want.hi))});
        }
        qInfo("3 instances, %lld bytes, box corners within %.2e m of instanceBounds", qint64(QFileInfo(path).size()), worst);
        QVERIFY2(worst < 1e-4, qPrintable(QString::number(worst)));

        // Above the limit (lowered here): the job fails naming the count and the size, and writes nothing.
        GltfExportOptions small;
        small.instanceLimit = 2;
        const QString refused = m_dir.filePath("refused.glb");
        Job::State state = Job::State::Running;
        QVERIFY(!waitForJob(w->exporter()->exportGltf(refused, small), 60000, &state));
        QCOMPARE(int(state), int(Job::State::Failed));
        QVERIFY2(errors.size() == 1 && errors[0].contains(QLatin1String("3 instances")) && errors[0].contains(QLatin1String("limit")),
                 qPrintable(errors.join('\n')));
        QVERIFY(!QFile::exists(refused));
        QVERIFY(w->exporter()->lastGltfPlan().overLimit());
        // Not a .glb: refused before any job.
        QVERIFY(!w->exporter()->exportGltf(m_dir.filePath("scene.gltf")));

        // Through the menu above the limit (lowered to 2): the job refuses, the window asks with the count and the
        // size, and Yes writes the file anyway.
        errors.clear();
        lines.clear();
        w->exporter()->setGltfLimits(2, kGltfByteLimit);
        const QString forced = m_dir.filePath("forced.glb");
        QString question;
        answered = false;
        QTimer answer;
        connect(&answer, &QTimer::timeout, this, [&] {
            QWidget* modal = QApplication::activeModalWidget();
            if (auto* d = qobject_cast<QFileDialog*>(modal); d && !answered) {
                answered = true;
                answerSaveDialog(d, forced);
            } else if (auto* ask = qobject_cast<QMessageBox*>(modal)) {
                question = ask->text();
                ask->button(QMessageBox::Yes)->click();
            }
        });
        answer.start(50);
        action->trigger();
        QVERIFY2(QTest::qWaitFor(exported, 60000), qPrintable(errors.join('\n')));
        answer.stop();
        QVERIFY2(question.contains(QLatin1String("3 instances")) && question.contains(QLatin1String("MB")), qPrintable(question));
        QVERIFY2(errors.size() == 1 && errors[0].contains(QLatin1String("limit")), qPrintable(errors.join('\n')));   // the refusal, reported
        QStringList logged;
        for (const QList<QVariant>& l : lines) logged << l[0].toString();
        QVERIFY2(QFile::exists(forced), qPrintable(logged.join('\n')));
        QCOMPARE(w->exporter()->lastGltfPlan().instances, size_t(3));
    }
};

QTEST_MAIN(TstStudioGltf)
#include "tst_studio_gltf.moc"
