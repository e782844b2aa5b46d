// A monkey test of the studio: seeded random sequences of what a user does (menu actions, dialogs filled
// with random and extreme values and accepted or cancelled, the outliner, the property and sky panels, the
// toolbar, clicks, drags, the wheel and keys in the viewport, undo and redo, save and open in a temporary
// folder, lighting, render and export jobs cancelled half-way), driven through Qt's event API under Xvfb.
// It asserts that the studio survives without a warning that means a bug, that every scene it saves reads
// back as the scene saved, that undoing to the start gives the starting scene back (sceneToJson), and that a
// kill at a random point followed by a new window recovers the last autosave.
//
// SYLVA_MONKEY_SEED=<n>[,<n>...] runs those seeds instead of the fixed list, SYLVA_MONKEY_ACTIONS=<n> that
// many actions a seed. Every action goes to test-output/monkey/seed-<n>.log (flushed, so a crash leaves it);
// a failure prints the seed, the command that reproduces it and the last actions.
#include <QAbstractButton>
#include <QAbstractSpinBox>
#include <QAction>
#include <QCheckBox>
#include <QComboBox>
#include <QDial>
#include <QDialogButtonBox>
#include <QDoubleSpinBox>
#include <QFile>
#include <QFileDialog>
#include <QLineEdit>
#include <QMenu>
#include <QMenuBar>
#include <QMutex>
#include <QPushButton>
#include <QSlider>
#include <QSpinBox>
#include <QTimer>
#include <QTreeView>
#include <QWheelEvent>

#include <algorithm>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <deque>
#include <map>
#include <memory>
#include <random>
#include <set>
#include <utility>
#include <vector>

#include <unistd.h>

#include "pipeline/io/env_map_io.h"
#include "pipeline/scene/scene_file.h"
#include "studio/dialogs.h"
#include "studio/outliner_model.h"
#include "studio/property_panel.h"
#include "studio/render_window.h"
#include "studio/sky_panel.h"
#include "studio/scene_document.h"
#include "studio/volume_dialogs.h"
#include "studio_test_util.h"
#include "tests/common/run_program.h"
#include "tests/common/scenes.h"

using namespace sylva;
using namespace sylva::test;

namespace {

// The seeds CI runs (deterministic), each with its number of actions: two long runs, and the regression cases of
// bugs the monkey found, each a little past the action that showed it (41: the render window's samples above the
// scene file's 4096; 44: a camera looking straight along up, typed into the camera page; 48: wheel zooms out until
// the eye and the target were one point in double). Each showed as a saved scene that could not be read back.
const QList<QPair<quint64, int>> kSeeds = {{20261207, 600}, {4242, 600}, {41, 280}, {44, 230}, {48, 640}};
const QList<quint64> kKillSeeds = {13, 77, 1009};   // 13: the sky's sample groups typed above its lights
constexpr int kKillActions = 240;    // the child's actions before its kill (at most)
constexpr int kCheckEvery = 250;     // actions between the undo-to-the-start checks

// The scene as the studio would save it (sceneToJson; a scene it cannot write: the reason).
std::string json(const Scene& s)
{
    try {
        return sceneToJson(s, "/");
    } catch (const std::exception& e) {
        return std::string("unwritable: ") + e.what();
    }
}

// The same without the camera: navigation sets the camera with no undo step, and undo keeps it.
std::string jsonNoCamera(const Scene& s)
{
    Scene t = s;
    t.camera = CameraDesc{};
    return json(t);
}

// Warnings from Qt (and the studio) that mean a bug: everything but what Xvfb's GL and the platform
// say about themselves.
QMutex g_warningsMutex;
QStringList g_warnings;
QtMessageHandler g_previousHandler = nullptr;

bool benignWarning(const QString& m)
{
    static const QStringList benign = {
        // The X server's and Mesa's remarks about the display (no window manager, no session bus).
        QStringLiteral("QXcbConnection"), QStringLiteral("qt.qpa."), QStringLiteral("Qt: Session management"),
        QStringLiteral("libEGL"), QStringLiteral("MESA"), QStringLiteral("QStandardPaths: "),
    };
    for (const QString& b : benign)
        if (m.contains(b)) return true;
    return false;
}

void monkeyMessageHandler(QtMsgType type, const QMessageLogContext& context, const QString& message)
{
    if ((type == QtWarningMsg || type == QtCriticalMsg || type == QtFatalMsg) && !benignWarning(message)) {
        const QMutexLocker lock(&g_warningsMutex);
        g_warnings << message;
    }
    if (g_previousHandler) g_previousHandler(type, context, message);
}

QStringList takeWarnings()
{
    const QMutexLocker lock(&g_warningsMutex);
    return std::exchange(g_warnings, {});
}

// What the monkey needs of its window and does to it: one random action a call (step), a log of
// each, and the undo check.
class Monkey {
public:
    Monkey(MainWindow& w, quint64 seed, const QString& folder, const QString& logPath)
        : m_w(w), m_rng(seed), m_seed(seed), m_folder(folder), m_log(logPath)
    {
        m_log.open(QIODevice::WriteOnly | QIODevice::Truncate | QIODevice::Text);
        QDir().mkpath(m_folder);
        // Files for File > Open and Import: a scene written by hand that is not one, an empty file, a mesh.
        writeText(m_folder + "/broken.sylva.json", "{ \"species\": [ ");
        writeText(m_folder + "/empty.sylva.json", "");
        QDir().mkpath(m_folder + "/locked");
        QFile::setPermissions(m_folder + "/locked", QFile::ReadOwner | QFile::ExeOwner);
        m_w.setSavePrompt([this](const QString&) {
            const QMessageBox::StandardButton b[] = {QMessageBox::Discard, QMessageBox::Discard, QMessageBox::Save, QMessageBox::Cancel};
            const QMessageBox::StandardButton pick = b[below(4)];
            note(QStringLiteral("  save prompt: %1").arg(pick == QMessageBox::Save ? "save" : pick == QMessageBox::Cancel ? "cancel" : "discard"));
            return pick;
        });
        // A hang (an action that does not come back) ends the run with the seed and the last actions.
        m_watchdog.setInterval(1000);
        QObject::connect(&m_watchdog, &QTimer::timeout, [this] {
            if (m_sinceStep.elapsed() < 120000) return;
            fprintf(stderr, "%s", qPrintable(report(QStringLiteral("FAIL: an action has not come back for 120 s"))));
            fflush(stderr);
            std::abort();
        });
        m_sinceStep.start();
        m_watchdog.start();
        // Every save: the file is read back after the action and must hold the scene saved.
        QObject::connect(&m_w, &MainWindow::logLineAdded, &m_modal, [this](const QString& line) {
            if (line.startsWith(QLatin1String("saved "))) m_saved.emplace_back(doc()->filePath(), json(doc()->scene()));
        });
        m_modal.setInterval(5);
        QObject::connect(&m_modal, &QTimer::timeout, [this] { handleModal(); });
        m_modal.start();
        m_base = jsonNoCamera(doc()->scene());
    }
    ~Monkey() { QFile::setPermissions(m_folder + "/locked", QFile::ReadOwner | QFile::WriteOwner | QFile::ExeOwner); }

    SceneDocument* doc() const { return m_w.document(); }
    int actions() const { return m_count; }

    // The seed, how to run it again, and the last actions: what a failure says.
    QString report(const QString& what) const
    {
        QString s = QStringLiteral("%1\nseed %2 after %3 actions; reproduce: SYLVA_MONKEY_SEED=%2 SYLVA_MONKEY_ACTIONS=%3 "
                                   "ctest -R tst_studio_monkey --output-on-failure\nlog: %4\nlast actions:\n")
                        .arg(what)
                        .arg(m_seed)
                        .arg(m_count)
                        .arg(m_log.fileName());
        for (const QString& line : m_recent) s += line + '\n';
        return s;
    }

    void note(const QString& line)
    {
        m_log.write((line + '\n').toUtf8());
        m_log.flush();
        m_recent.push_back(line);
        if (m_recent.size() > 30) m_recent.pop_front();
    }

    quint64 next() { return m_rng(); }
    int below(int n) { return n <= 1 ? 0 : int(m_rng() % quint64(n)); }
    bool chance(double p) { return double(m_rng() >> 11) * 0x1.0p-53 < p; }
    double uniform(double lo, double hi) { return lo + (hi - lo) * double(m_rng() >> 11) * 0x1.0p-53; }

    // One random action; empty when all is well, else what went wrong (a warning, a hang).
    QString step()
    {
        ++m_count;
        m_sinceStep.restart();
        struct Choice {
            int weight;
            void (Monkey::*act)();
        };
        static const Choice choices[] = {
            {10, &Monkey::undo},          {6, &Monkey::redo},          {8, &Monkey::clickOutliner}, {16, &Monkey::editPanel},
            {5, &Monkey::clickViewport},  {5, &Monkey::dragViewport},  {3, &Monkey::wheelViewport}, {3, &Monkey::keyViewport},
            {14, &Monkey::menuAction},    {2, &Monkey::saveKey},       {1, &Monkey::closeTools},    {1, &Monkey::quit},
        };
        int total = 0;
        for (const Choice& c : choices) total += c.weight;
        int r = below(total);
        for (const Choice& c : choices) {
            if (r < c.weight) {
                (this->*c.act)();
                break;
            }
            r -= c.weight;
        }
        const QString jobs = settleJobs();
        if (!jobs.isEmpty()) return jobs;
        QCoreApplication::processEvents();
        if (m_sinceStep.elapsed() > 300) note(QStringLiteral("  (%1 ms)").arg(m_sinceStep.elapsed()));
        if (doc()->undoStack()->count() == 0) m_base = jsonNoCamera(doc()->scene());   // New, Open, the example: a new start
        for (const auto& [path, saved] : std::exchange(m_saved, {})) {
            std::string read;
            try {
                read = json(readSceneFile(path.toStdString()));
            } catch (const std::exception& e) {
                return QStringLiteral("the scene saved to %1 cannot be read back: %2").arg(path, QString::fromUtf8(e.what()));
            }
            if (read != saved) return QStringLiteral("the scene saved to %1 reads back as another scene").arg(path);
        }
        const QStringList w = takeWarnings();
        if (!w.isEmpty()) return QStringLiteral("Qt warned: ") + w.join(QStringLiteral("\n  "));
        return {};
    }

    // Undo until the stack cannot: the scene at the start (the last New/Open, or the first scene), its camera aside
    // (navigation is no undo step); redo back to where it was: the scene before. Empty when both hold.
    QString checkUndo()
    {
        m_w.jobs()->cancelAll();   // a job that ends during the check would push an edit between its steps
        if (!QTest::qWaitFor([&] { return !m_w.jobs()->isBusy(); }, 60000)) return QStringLiteral("a cancelled job did not end within 60 s");
        m_carry = 0;
        QCoreApplication::processEvents();
        if (doc()->undoStack()->count() == 0) m_base = jsonNoCamera(doc()->scene());
        QUndoStack* stack = doc()->undoStack();
        const std::string now = jsonNoCamera(doc()->scene());
        const int index = stack->index();
        note(QStringLiteral("check: undo %1 steps to the start, redo them").arg(index));
        while (stack->canUndo()) stack->undo();
        QCoreApplication::processEvents();
        if (jsonNoCamera(doc()->scene()) != m_base)
            return QStringLiteral("undo to the start did not give the starting scene back:\n  start %1\n  now   %2")
                .arg(QString::fromStdString(m_base).left(4000), QString::fromStdString(jsonNoCamera(doc()->scene())).left(4000));
        stack->setIndex(index);
        QCoreApplication::processEvents();
        if (jsonNoCamera(doc()->scene()) != now) return QStringLiteral("redo to where the check began did not give that scene back");
        return {};
    }

    // Lighting at the start, to its end (the viewport then has plants to click on).
    bool lightFully()
    {
        Job* job = m_w.lighting()->computeLighting();
        return !job || waitForJob(job, 120000);
    }

private:
    static void writeText(const QString& path, const QByteArray& text)
    {
        QFile f(path);
        if (f.open(QIODevice::WriteOnly | QIODevice::Truncate)) f.write(text);
    }

    // ---- the actions ----

    void undo() { history(false); }
    void redo() { history(true); }

    // An undo or a redo, by its key sequence to the focused widget or by its Edit menu action.
    void history(bool forward)
    {
        const QString word = forward ? QStringLiteral("redo") : QStringLiteral("undo");
        if (chance(0.5)) {
            note(QStringLiteral("%1 (%2 to %3)").arg(word, forward ? QStringLiteral("Ctrl+Shift+Z") : QStringLiteral("Ctrl+Z"), focusName()));
            QTest::keySequence(focusTarget(), forward ? QKeySequence::Redo : QKeySequence::Undo);
        } else {
            note(QStringLiteral("%1 (Edit > %2)").arg(word, forward ? QStringLiteral("Redo") : QStringLiteral("Undo")));
            m_w.findChild<QAction*>(forward ? "actionRedo" : "actionUndo")->trigger();
        }
    }

    QWidget* focusTarget() const
    {
        QWidget* f = QApplication::focusWidget();
        return f && f->window() == &m_w ? f : static_cast<QWidget*>(&m_w);
    }
    QString focusName() const
    {
        QWidget* f = focusTarget();
        return f->objectName().isEmpty() ? QString::fromLatin1(f->metaObject()->className()) : f->objectName();
    }

    // A click on a random row of the outliner (every row expanded).
    void clickOutliner()
    {
        QTreeView* t = m_w.outliner();
        std::vector<QModelIndex> rows;
        std::function<void(const QModelIndex&)> walk = [&](const QModelIndex& parent) {
            for (int r = 0; r < t->model()->rowCount(parent); ++r) {
                const QModelIndex i = t->model()->index(r, 0, parent);
                rows.push_back(i);
                walk(i);
            }
        };
        walk({});
        if (rows.empty()) return;
        const QModelIndex i = rows[size_t(below(int(rows.size())))];
        t->scrollTo(i);
        const QRect rect = t->visualRect(i);
        note(QStringLiteral("outliner: click %1").arg(i.data().toString()));
        if (rect.isValid()) QTest::mouseClick(t->viewport(), Qt::LeftButton, {}, rect.center());
    }

    // The editors a user reaches: the docks' and the toolbar's, visible and enabled.
    std::vector<QWidget*> editors() const
    {
        std::vector<QWidget*> out;
        // The main window's and those of the tool windows it opened (the render window, the help).
        for (QWidget* w : m_w.findChildren<QWidget*>()) {
            if (w->window() != &m_w && (w->window()->parentWidget() != &m_w || w->window()->isModal())) continue;
            if (!w->isVisible() || !w->isEnabled()) continue;
            if (qobject_cast<QAbstractSpinBox*>(w) || qobject_cast<QComboBox*>(w) || qobject_cast<QCheckBox*>(w) ||
                qobject_cast<QSlider*>(w) || qobject_cast<QDial*>(w) || qobject_cast<QPushButton*>(w) ||
                (qobject_cast<QLineEdit*>(w) && !qobject_cast<QAbstractSpinBox*>(w->parentWidget()) && !qobject_cast<QComboBox*>(w->parentWidget()) &&
                 !static_cast<QLineEdit*>(w)->isReadOnly()))
                out.push_back(w);
        }
        return out;
    }

    static QString nameOf(const QWidget* w)
    {
        return w->objectName().isEmpty() ? QString::fromLatin1(w->metaObject()->className()) : w->objectName();
    }

    // Values that make a job or the viewport expensive (memory, minutes): the monkey keeps them modest.
    static double capFor(const QString& name, double hi)
    {
        static const std::map<QString, double> caps = {
            {"species.grid", 24},  {"viewportSamples", 8}, {"sky.lights", 64},    {"cloud.resolution", 20},
            {"smoke.cells.x", 12}, {"smoke.cells.y", 12},  {"smoke.cells.z", 12}, {"smoke.steps", 50},
            {"tiles.size", 64},    {"sky.interleave", 8},   {"renderWidth", 320},   {"renderHeight", 320},
        };
        const auto it = caps.find(name);
        return it == caps.end() ? hi : std::min(hi, it->second);
    }

    // A random value of [lo, hi]: often an end, sometimes just inside, else anywhere.
    double pickValue(double lo, double hi)
    {
        switch (below(6)) {
        case 0: return lo;
        case 1: return hi;
        case 2: return lo + (hi - lo) * 1e-3;
        default: return uniform(lo, hi);
        }
    }

    void editPanel()
    {
        const std::vector<QWidget*> all = editors();
        if (all.empty()) return;
        QWidget* w = all[size_t(below(int(all.size())))];
        fiddle(w, QStringLiteral("panel"));
    }

    // Does something to one editor, through events where a user would (keys typed, clicks).
    void fiddle(QWidget* w, const QString& where)
    {
        const QString name = nameOf(w);
        if (auto* spin = qobject_cast<QAbstractSpinBox*>(w)) {
            double lo = 0, hi = 0;
            if (auto* s = qobject_cast<QSpinBox*>(spin)) lo = s->minimum(), hi = s->maximum();
            else if (auto* d = qobject_cast<QDoubleSpinBox*>(spin)) lo = d->minimum(), hi = d->maximum();
            hi = capFor(name, hi);
            spin->setFocus(Qt::OtherFocusReason);
            switch (below(4)) {
            case 0: {   // arrow keys (a held key)
                const int n = 1 + below(4);
                const Qt::Key key = chance(0.5) ? Qt::Key_Up : Qt::Key_Down;
                note(QStringLiteral("%1: %2 %3 x%4").arg(where, name, key == Qt::Key_Up ? "Up" : "Down").arg(n));
                for (int i = 0; i < n; ++i)
                    if (!(key == Qt::Key_Up && spinValue(spin) + 1e-9 >= hi)) QTest::keyClick(spin, key);
                break;
            }
            case 1: {   // text typed over the value (maybe nonsense), then Enter
                const double v = pickValue(lo, hi);
                const QString texts[] = {QString::number(v, 'g', 8), QString::number(v, 'f', 2), QStringLiteral("-"), QStringLiteral("1e308"),
                                         QStringLiteral("abc")};
                QString text = texts[below(chance(0.8) ? 2 : 5)];
                if (text == "1e308" && hi < 1e308) text = QString::number(hi);
                // Sizes that take memory: the number itself (a typed "12.5" is 125 in an integer box). Two renders of
                // 16384 x 16384 at once take more than 23 GB.
                static const std::set<QString> memory = {"renderWidth", "renderHeight", "species.grid", "cloud.resolution",
                                                         "smoke.cells.x", "smoke.cells.y", "smoke.cells.z", "tiles.size"};
                if (memory.count(name)) text = QString::number(std::llround(v));
                note(QStringLiteral("%1: %2 typed \"%3\" + Enter").arg(where, name, text));
                QTest::keyClick(spin, Qt::Key_A, Qt::ControlModifier);
                typeText(spin, text);
                QTest::keyClick(spin, Qt::Key_Return);
                break;
            }
            default: {   // a value set (what a drag of the field or a paste gives)
                const double v = pickValue(lo, hi);
                note(QStringLiteral("%1: %2 set to %3").arg(where, name).arg(v, 0, 'g', 10));
                if (auto* s = qobject_cast<QSpinBox*>(spin)) s->setValue(int(std::llround(std::clamp(v, lo, hi))));
                else if (auto* d = qobject_cast<QDoubleSpinBox*>(spin)) d->setValue(v);
                QTest::keyClick(spin, Qt::Key_Return);
                break;
            }
            }
        } else if (auto* combo = qobject_cast<QComboBox*>(w)) {
            combo->setFocus(Qt::OtherFocusReason);
            const Qt::Key keys[] = {Qt::Key_Down, Qt::Key_Up, Qt::Key_Home, Qt::Key_End};
            const Qt::Key key = keys[below(4)];
            note(QStringLiteral("%1: %2 key %3 (now %4)").arg(where, name).arg(int(key), 0, 16).arg(combo->currentText()));
            QTest::keyClick(combo, key);
        } else if (auto* box = qobject_cast<QCheckBox*>(w)) {
            note(QStringLiteral("%1: click %2 (%3)").arg(where, name, box->isChecked() ? "on" : "off"));
            QTest::mouseClick(box, Qt::LeftButton, {}, QPoint(8, box->height() / 2));
        } else if (auto* slider = qobject_cast<QAbstractSlider*>(w)) {
            slider->setFocus(Qt::OtherFocusReason);
            const Qt::Key keys[] = {Qt::Key_PageUp, Qt::Key_PageDown, Qt::Key_Home, Qt::Key_End, Qt::Key_Left, Qt::Key_Right};
            const Qt::Key key = keys[below(6)];
            note(QStringLiteral("%1: %2 key %3").arg(where, name).arg(int(key), 0, 16));
            QTest::keyClick(slider, key);
        } else if (auto* button = qobject_cast<QPushButton*>(w)) {
            note(QStringLiteral("%1: click button %2 \"%3\"").arg(where, name, button->text()));
            QTest::mouseClick(button, Qt::LeftButton);
        } else if (auto* edit = qobject_cast<QLineEdit*>(w)) {
            const QString texts[] = {QStringLiteral("oak"), QString(), QStringLiteral("  "), QString(300, QChar('x')), QStringLiteral("a/b\\c\"{}"),
                                     QString::fromUtf8("\xc3\xa9t\xc3\xa9 \xe6\xa3\xae"), QStringLiteral("18446744073709551615")};
            const QString text = texts[below(7)];
            note(QStringLiteral("%1: %2 typed \"%3\" + Enter").arg(where, name, text.left(40)));
            edit->setFocus(Qt::OtherFocusReason);
            QTest::keyClick(edit, Qt::Key_A, Qt::ControlModifier);
            QTest::keyClick(edit, Qt::Key_Delete);
            typeText(edit, text);
            QTest::keyClick(edit, Qt::Key_Return);
        }
    }

    // Types text as key events (QTest::keyClicks knows only ASCII: other characters go as key events with their text).
    static void typeText(QWidget* w, const QString& text)
    {
        for (const QChar c : text) {
            if (c.unicode() >= 0x20 && c.unicode() < 0x7f) {
                QTest::keyClick(w, char(c.unicode()));
                continue;
            }
            QKeyEvent press(QEvent::KeyPress, Qt::Key_unknown, Qt::NoModifier, QString(c));
            QKeyEvent release(QEvent::KeyRelease, Qt::Key_unknown, Qt::NoModifier, QString(c));
            QApplication::sendEvent(w, &press);
            QApplication::sendEvent(w, &release);
        }
    }

    static double spinValue(QAbstractSpinBox* spin)
    {
        if (auto* s = qobject_cast<QSpinBox*>(spin)) return s->value();
        if (auto* d = qobject_cast<QDoubleSpinBox*>(spin)) return d->value();
        return 0.0;
    }

    QPoint viewportPoint()
    {
        const Viewport* v = m_w.viewport();
        return {below(v->width()), below(v->height())};
    }

    void clickViewport()
    {
        const QPoint p = viewportPoint();
        const Qt::MouseButton buttons[] = {Qt::LeftButton, Qt::LeftButton, Qt::MiddleButton, Qt::RightButton};
        const Qt::MouseButton b = buttons[below(4)];
        const Qt::KeyboardModifiers mods = chance(0.2) ? Qt::ShiftModifier : Qt::NoModifier;
        note(QStringLiteral("viewport: click button %1 at %2,%3%4").arg(int(b)).arg(p.x()).arg(p.y()).arg(mods ? " +Shift" : ""));
        QTest::mouseClick(m_w.viewport(), b, mods, p);
    }

    void dragViewport()
    {
        Viewport* v = m_w.viewport();
        QPoint p = viewportPoint();
        const Qt::MouseButton b = chance(0.75) ? Qt::LeftButton : Qt::MiddleButton;
        // Shift pans, Ctrl slides the tree under the cursor over the ground.
        const int m = below(10);
        const Qt::KeyboardModifiers mods = m < 3 ? Qt::ShiftModifier : m < 5 ? Qt::ControlModifier : Qt::NoModifier;
        const int moves = 1 + below(6);
        note(QStringLiteral("viewport: drag button %1 from %2,%3, %4 moves%5")
                 .arg(int(b)).arg(p.x()).arg(p.y()).arg(moves).arg(m < 3 ? " +Shift" : m < 5 ? " +Ctrl" : ""));
        QTest::mousePress(v, b, mods, p);
        for (int i = 0; i < moves; ++i) {
            // Mostly small steps; now and then far outside the widget.
            p += chance(0.9) ? QPoint(below(41) - 20, below(41) - 20) : QPoint(below(4001) - 2000, below(4001) - 2000);
            QTest::mouseMove(v, p);
        }
        QTest::mouseRelease(v, b, mods, p);
    }

    void wheelViewport()
    {
        const QPoint p = viewportPoint();
        const int deltas[] = {120, -120, 360, -720, 1, 12000, -12000};
        const int n = 1 + below(3);
        // Plain: zoom; Ctrl: turn the selected tree; Ctrl + Shift: scale it.
        const int m = below(10);
        const Qt::KeyboardModifiers mods = m < 2 ? Qt::ControlModifier : m < 3 ? (Qt::ControlModifier | Qt::ShiftModifier) : Qt::NoModifier;
        for (int i = 0; i < n; ++i) {
            const int d = deltas[below(7)];
            note(QStringLiteral("viewport: wheel %1 at %2,%3%4").arg(d).arg(p.x()).arg(p.y()).arg(m < 2 ? " +Ctrl" : m < 3 ? " +Ctrl+Shift" : ""));
            QWheelEvent e(QPointF(p), m_w.viewport()->mapToGlobal(QPointF(p)), QPoint(), QPoint(0, d), Qt::NoButton, mods,
                          Qt::NoScrollPhase, false);
            QApplication::sendEvent(m_w.viewport(), &e);
        }
    }

    void keyViewport()
    {
        const Qt::Key keys[] = {Qt::Key_F, Qt::Key_W, Qt::Key_A, Qt::Key_S, Qt::Key_D, Qt::Key_Q, Qt::Key_E, Qt::Key_W, Qt::Key_Home, Qt::Key_Escape};
        const int n = 1 + below(4);
        m_w.viewport()->setFocus(Qt::OtherFocusReason);
        for (int i = 0; i < n; ++i) {
            const Qt::Key k = keys[below(10)];
            const Qt::KeyboardModifiers mods = chance(0.2) ? Qt::ShiftModifier : Qt::NoModifier;
            note(QStringLiteral("viewport: key %1%2").arg(QKeySequence(k).toString(), mods ? " +Shift" : ""));
            QTest::keyClick(m_w.viewport(), k, mods);
        }
    }

    // A random action of the menus (submenus too), as the menu would trigger it.
    void menuAction()
    {
        std::vector<QAction*> all;
        std::function<void(QMenu*)> walk = [&](QMenu* m) {
            Q_EMIT m->aboutToShow();   // what a menu fills in as it opens (the recent files, view transforms)
            for (QAction* a : m->actions()) {
                if (a->isSeparator()) continue;
                if (a->menu()) {
                    walk(a->menu());
                    continue;
                }
                // Quit ends the run; automatic lighting would start a lighting job after every edit (its own test is
                // tst_studio_forest).
                if (a->objectName() == "actionQuit" || a->objectName() == "actionAutoLighting") continue;
                all.push_back(a);
            }
        };
        for (QAction* a : m_w.menuBar()->actions())
            if (a->menu()) walk(a->menu());
        if (all.empty()) return;
        // The expensive ones less often: the example forest (962 instances: every later edit, drag and outliner
        // reset costs more until the next New or Open) and what starts a job.
        auto weight = [](const QAction* a) {
            static const std::map<QString, int> w = {
                {"actionExample", 1},     {"actionLight", 4},        {"actionReload", 4},      {"actionRelightBasis", 4},
                {"actionRenderImage", 4}, {"actionExport", 4},       {"actionExportGrids", 4}, {"actionExportGridsVdb", 4},
                {"actionSimulateSmoke", 4},
            };
            const auto it = w.find(a->objectName());
            return it == w.end() ? 10 : it->second;
        };
        int total = 0;
        for (const QAction* a : all) total += weight(a);
        int r = below(total);
        QAction* a = all.back();
        for (QAction* c : all) {
            if (r < weight(c)) {
                a = c;
                break;
            }
            r -= weight(c);
        }
        note(QStringLiteral("menu: %1%2").arg(a->text().remove('&'), a->isEnabled() ? QString() : QStringLiteral(" (disabled)")));
        if (a->isEnabled()) a->trigger();
    }

    void saveKey()
    {
        note(QStringLiteral("save: File > Save (file %1)").arg(doc()->filePath().isEmpty() ? QStringLiteral("untitled") : QFileInfo(doc()->filePath()).fileName()));
        m_w.findChild<QAction*>("actionSave")->trigger();
    }

    // File > Quit: the unsaved-changes question may cancel it; a closed window is opened again (as the next start would).
    void quit()
    {
        note(QStringLiteral("menu: Quit"));
        m_w.findChild<QAction*>("actionQuit")->trigger();
        if (m_w.isVisible()) return;
        note(QStringLiteral("  closed: shown again"));
        m_w.show();
        (void)QTest::qWaitForWindowExposed(&m_w);
    }

    // Closes the tool windows (render window, manual, shortcut sheet) a user left open.
    void closeTools()
    {
        for (QWidget* t : QApplication::topLevelWidgets()) {
            if (t == &m_w || !t->isVisible()) continue;
            note(QStringLiteral("close window %1").arg(t->windowTitle()));
            t->close();
        }
    }

    // ---- jobs: each one cancelled half-way (after its first progress) or, now and then, let run a while ----

    QString settleJobs()
    {
        JobManager* jobs = m_w.jobs();
        if (!jobs->isBusy()) {
            m_carry = 0;
            return {};
        }
        const QList<Job*> running = jobs->running();
        QStringList names;
        for (Job* j : running) names << j->title();
        // Now and then the next few actions come while the jobs run (what a user does while the lighting runs).
        if (m_carry > 0 || chance(0.2)) {
            if (m_carry == 0) m_carry = 1 + below(3);
            --m_carry;
            note(QStringLiteral("  jobs: %1 (left running)").arg(names.join(", ")));
            return {};
        }
        const bool letRun = chance(0.15);
        note(QStringLiteral("  jobs: %1 (%2)").arg(names.join(", "), letRun ? "let run up to 1 s" : "cancel half-way"));
        if (letRun) {
            (void)QTest::qWaitFor([&] { return !jobs->isBusy(); }, 1000);
        } else {
            QPointer<Job> first = running.first();
            QSignalSpy progressed(first.data(), &Job::progressChanged);
            (void)QTest::qWaitFor(
                [&] {
                    const Job* j = first.data();
                    return !j || !j->isRunning() || !progressed.isEmpty();
                },
                3000);
        }
        if (jobs->isBusy()) {
            if (chance(0.5)) {
                note(QStringLiteral("  Render > Cancel All Jobs (Escape)"));
                m_w.findChild<QAction*>("actionCancelJobs")->trigger();
            } else {
                note(QStringLiteral("  cancel all jobs"));
                jobs->cancelAll();
            }
        }
        if (!QTest::qWaitFor([&] { return !jobs->isBusy(); }, 60000)) return QStringLiteral("a cancelled job did not end within 60 s");
        return {};
    }

    // ---- modal dialogs: filled with random values and accepted, or cancelled ----

    // Called every 5 ms: a new modal window gets its answer from a queued call, so that a question the answer
    // raises (replace the file?) finds this timer free to fire again in its own event loop.
    void handleModal()
    {
        QWidget* m = QApplication::activeModalWidget();
        if (!m || m_handling.count(m)) return;
        m_handling.insert(m);
        QMetaObject::invokeMethod(
            &m_modal,
            [this, m, alive = QPointer<QWidget>(m)] {
                if (alive) {
                    if (auto* fd = qobject_cast<QFileDialog*>(m)) fileDialog(fd);
                    else if (auto* box = qobject_cast<QMessageBox*>(m)) messageBox(box);
                    else if (auto* d = qobject_cast<QDialog*>(m)) dialog(d);
                    else note(QStringLiteral("  modal %1 left alone").arg(nameOf(m)));
                }
                m_handling.erase(m);   // (only a key: the widget may be gone)
            },
            Qt::QueuedConnection);
    }

    void fileDialog(QFileDialog* fd)
    {
        // A second visit: the dialog refused the first answer (no such file): cancel.
        const int tries = fd->property("monkeyTries").toInt();
        fd->setProperty("monkeyTries", tries + 1);
        if (chance(0.25) || tries > 0) {
            note(QStringLiteral("  file dialog \"%1\": cancel").arg(fd->windowTitle()));
            fd->reject();
            return;
        }
        QString path;
        if (fd->fileMode() == QFileDialog::Directory) {
            const QString dirs[] = {m_folder + "/grids", m_folder + "/locked", m_folder};
            path = dirs[below(3)];
            QDir().mkpath(m_folder + "/grids");
        } else if (fd->acceptMode() == QFileDialog::AcceptSave) {
            const QString names[] = {"scene_a.sylva.json", "scene_b.sylva.json", "scene_c", "locked/scene.sylva.json", "missing/scene.sylva.json",
                                     "render.png", "render.exr", "render.tif"};
            path = m_folder + '/' + names[below(8)];
        } else {
            const QString names[] = {m_folder + "/scene_a.sylva.json", m_folder + "/scene_b.sylva.json", m_folder + "/scene_c.sylva.json",
                                     m_folder + "/broken.sylva.json", m_folder + "/empty.sylva.json", m_folder + "/none.sylva.json",
                                     sharedTree(), QStringLiteral(SYLVA_RESOURCES "/hdri") , m_folder + "/broken.sylva.json"};
            path = names[below(9)];
        }
        note(QStringLiteral("  file dialog \"%1\": %2").arg(fd->windowTitle(), path));
        fd->selectFile(path);
        static_cast<QDialog*>(fd)->accept();   // (QFileDialog makes it protected)
    }

    void messageBox(QMessageBox* box)
    {
        const QList<QAbstractButton*> buttons = box->buttons();
        note(QStringLiteral("  message box \"%1\": %2").arg(box->windowTitle(), box->text().left(120)));
        if (buttons.isEmpty()) {
            box->reject();
            return;
        }
        QAbstractButton* b = buttons[below(int(buttons.size()))];
        note(QStringLiteral("  message box: %1").arg(b->text().remove('&')));
        QTest::mouseClick(b, Qt::LeftButton);
    }

    void dialog(QDialog* d)
    {
        if (chance(0.3)) {
            note(QStringLiteral("  dialog \"%1\": cancel%2").arg(d->windowTitle(), chance(0.5) ? " (Escape)" : ""));
            if (chance(0.5)) QTest::keyClick(d, Qt::Key_Escape);
            else d->reject();
            return;
        }
        // Every field of the form, a random and often extreme value; what makes the work expensive kept modest.
        for (QWidget* w : d->findChildren<QWidget*>()) {
            if (!w->isVisible() || !w->isEnabled()) continue;
            if (qobject_cast<QPushButton*>(w) || qobject_cast<QDialogButtonBox*>(w)) continue;   // Browse..., OK, Cancel
            if (!chance(0.7)) continue;
            if (auto* spin = qobject_cast<QAbstractSpinBox*>(w)) {
                double hi = capFor(nameOf(spin), 1e300);
                if (qobject_cast<GrowDialog*>(d)) hi = std::min(hi, 20000.0);   // triangles
                if (qobject_cast<ExportDialog*>(d)) hi = std::min(hi, 160.0);   // width, height, samples
                if (auto* s = qobject_cast<ScatterDialog*>(d); s && spin == s->countBox()) hi = 150;
                double lo = 0, top = 0;
                if (auto* s = qobject_cast<QSpinBox*>(spin)) lo = s->minimum(), top = s->maximum();
                else if (auto* x = qobject_cast<QDoubleSpinBox*>(spin)) lo = x->minimum(), top = x->maximum();
                const double v = pickValue(lo, std::min(top, std::max(lo, hi)));
                note(QStringLiteral("  dialog field %1 = %2").arg(nameOf(spin)).arg(v, 0, 'g', 10));
                if (auto* s = qobject_cast<QSpinBox*>(spin)) s->setValue(int(std::llround(v)));
                else if (auto* x = qobject_cast<QDoubleSpinBox*>(spin)) x->setValue(v);
            } else if (auto* combo = qobject_cast<QComboBox*>(w)) {
                if (combo->count() > 0) combo->setCurrentIndex(below(combo->count()));
                note(QStringLiteral("  dialog field %1 = %2").arg(nameOf(combo), combo->currentText()));
            } else if (auto* box = qobject_cast<QCheckBox*>(w)) {
                box->setChecked(!box->isChecked());
                note(QStringLiteral("  dialog field %1 = %2").arg(nameOf(box), box->isChecked() ? "on" : "off"));
            } else if (auto* edit = qobject_cast<QLineEdit*>(w); edit && !qobject_cast<QAbstractSpinBox*>(edit->parentWidget()) &&
                                                                 !qobject_cast<QComboBox*>(edit->parentWidget())) {
                QString text;
                if (qobject_cast<ExportDialog*>(d)) {
                    const QString files[] = {"render.png", "render.exr", "render.tif", "render.bmp", "locked/render.png", "missing/render.png"};
                    text = m_folder + '/' + files[below(6)];
                } else {
                    const QString texts[] = {"cloud", "", "18446744073709551615", "-1", "a name with spaces", QString(200, QChar('z'))};
                    text = texts[below(6)];
                }
                edit->setText(text);
                note(QStringLiteral("  dialog field %1 = \"%2\"").arg(nameOf(edit), text.left(60)));
            }
        }
        note(QStringLiteral("  dialog \"%1\": OK").arg(d->windowTitle()));
        if (auto* buttons = d->findChild<QDialogButtonBox*>()) {
            QPushButton* ok = buttons->button(QDialogButtonBox::Ok);
            if (ok && ok->isEnabled()) {
                QTest::mouseClick(ok, Qt::LeftButton);
                if (d->isVisible()) d->reject();   // refused its values: cancel
                return;
            }
        }
        d->accept();
    }

    MainWindow& m_w;
    std::mt19937_64 m_rng;
    const quint64 m_seed;
    const QString m_folder;
    QFile m_log;
    std::deque<QString> m_recent;
    int m_count = 0;
    int m_carry = 0;
    std::vector<std::pair<QString, std::string>> m_saved;   // files saved during the action, with the scene saved   // actions still to come while the jobs run
    std::string m_base;
    QTimer m_modal;
    QTimer m_watchdog;
    QElapsedTimer m_sinceStep;
    std::set<QWidget*> m_handling;
};

// The seeds of a run: SYLVA_MONKEY_SEED (comma-separated) or the fixed list.
QList<quint64> seeds(const QList<quint64>& fixed)
{
    const QString env = qEnvironmentVariable("SYLVA_MONKEY_SEED");
    if (env.isEmpty()) return fixed;
    QList<quint64> out;
    for (const QString& s : env.split(',', Qt::SkipEmptyParts)) out << s.trimmed().toULongLong();
    return out;
}

int actionCount(int fallback)
{
    bool ok = false;
    const int n = qEnvironmentVariableIntValue("SYLVA_MONKEY_ACTIONS", &ok);
    return ok && n > 0 ? n : fallback;
}

// The monkey's starting scene: two small grown shrubs (grid 16) on the ground, a small render.
Scene startScene()
{
    Scene s = twoShrubs();
    loadSceneSky(s);
    return s;
}

} // namespace

class TstStudioMonkey : public QObject {
    Q_OBJECT

    std::unique_ptr<QTemporaryDir> m_dir;

    // The window as the monkey finds it: the start scene lit, no automatic lighting, errors collected.
    std::unique_ptr<MainWindow> window(QStringList* errors)
    {
        auto w = std::make_unique<MainWindow>();
        quietWindow(*w, errors);
        w->lighting()->setAutoLighting(false);
        w->autosave()->setRecoveryPrompt([](const QString&, const QDateTime&) { return false; });
        w->autosave()->setInterval(0);
        w->resize(1100, 760);
        if (!showWithViewport(*w, 240, 150)) return nullptr;
        QCoreApplication::processEvents();   // the start-up recovery check (nothing to offer)
        w->document()->reset(startScene(), QString());
        return w;
    }

    // The settings every seed starts from (a seed's run changes them: recent files, folders, view toggles), so that a
    // seed does the same alone and after others: the tests' isolation, species grown at a small grid.
    void freshSettings()
    {
        isolate(*m_dir);
        QSettings().setValue("import/grid", 16);
    }

    static QString logPath(const QString& kind, quint64 seed)
    {
        const QString dir = QStringLiteral(SYLVA_TEST_OUTPUT "/monkey");
        QDir().mkpath(dir);
        return QStringLiteral("%1/%2-%3.log").arg(dir, kind).arg(seed);
    }

private Q_SLOTS:
    void initTestCase()
    {
        SYLVA_SKIP_WITHOUT_X();
        // The child of killAndRecover works in its parent's folder (a kill leaves its own behind).
        const QString child = qEnvironmentVariable("SYLVA_MONKEY_CHILD");
        m_dir = child.isEmpty() ? std::make_unique<QTemporaryDir>()
                                : std::make_unique<QTemporaryDir>(QFileInfo(child).absolutePath() + "/child-XXXXXX");
        QVERIFY(m_dir->isValid());
        freshSettings();
        // Qt's own file dialogs (the monkey fills them in).
        QCoreApplication::setAttribute(Qt::AA_DontUseNativeDialogs);
        g_previousHandler = qInstallMessageHandler(monkeyMessageHandler);
    }

    void cleanupTestCase() { qInstallMessageHandler(g_previousHandler); }

    void monkey_data()
    {
        QTest::addColumn<quint64>("seed");
        QTest::addColumn<int>("actions");
        if (qEnvironmentVariableIsSet("SYLVA_MONKEY_SEED")) {
            for (quint64 s : seeds({})) QTest::addRow("seed %llu", s) << s << actionCount(800);
        } else {
            for (const auto& [s, n] : kSeeds) QTest::addRow("seed %llu", s) << s << actionCount(n);
        }
    }

    // Random actions; no warning, no hang; every kCheckEvery actions and at the end, undoing to the start gives
    // the starting scene back and redoing the scene before.
    void monkey()
    {
        QFETCH(quint64, seed);
        QFETCH(int, actions);
        const int n = actions;
        freshSettings();
        QStringList errors;
        auto w = window(&errors);
        QVERIFY(w);
        const QString folder = m_dir->filePath(QStringLiteral("monkey-%1").arg(seed));
        Monkey monkey(*w, seed, folder, logPath("seed", seed));
        qInfo("monkey: seed %llu, %d actions, log %s; reproduce: SYLVA_MONKEY_SEED=%llu SYLVA_MONKEY_ACTIONS=%d ctest -R tst_studio_monkey",
              seed, n, qPrintable(logPath("seed", seed)), seed, n);
        QVERIFY(monkey.lightFully());
        QVERIFY2(takeWarnings().isEmpty(), "warnings before the first action");
        for (int i = 0; i < n; ++i) {
            const QString problem = monkey.step();
            QVERIFY2(problem.isEmpty(), qPrintable(monkey.report(problem)));
            if ((i + 1) % kCheckEvery == 0 || i + 1 == n) {
                const QString undo = monkey.checkUndo();
                QVERIFY2(undo.isEmpty(), qPrintable(monkey.report(undo)));
            }
        }
        qInfo("monkey: seed %llu done, %d actions, %lld errors reported to the user (expected: bad files, refused values)", seed, n,
              qlonglong(errors.size()));
    }

    // The bugs the monkey found, each through the editors it went through, each time: a scene the studio accepted
    // that the scene file refuses (its saved file could not be opened again, its autosave not recovered). The seeds
    // that found them are in the lists above; what runs in the background may take a seed's later actions elsewhere.
    void regressions()
    {
        freshSettings();
        QStringList errors;
        auto w = window(&errors);
        QVERIFY(w);
        const QString file = m_dir->filePath("regression.sylva.json");
        auto readsBack = [&] {
            errors.clear();
            if (!w->saveFile(file)) return QStringLiteral("not saved: ") + errors.join(' ');
            try {
                if (json(readSceneFile(file.toStdString())) != json(w->document()->scene())) return QStringLiteral("read back as another scene");
            } catch (const std::exception& e) {
                return QString::fromUtf8(e.what());
            }
            return QString();
        };
        auto type = [](QAbstractSpinBox* box, const QString& text) {
            box->setFocus(Qt::OtherFocusReason);
            QTest::keyClick(box, Qt::Key_A, Qt::ControlModifier);
            QTest::keyClicks(box, text);
            QTest::keyClick(box, Qt::Key_Return);
        };
        const SkyDesc& sky = w->document()->scene().skyModel;

        // Kill seed 13: sample groups typed above the sky's lights; then the lights lowered below the groups.
        type(w->skyPanel()->interleave(), "64579");
        QVERIFY2(sky.interleave <= sky.lights, qPrintable(QStringLiteral("%1 groups of %2 lights").arg(sky.interleave).arg(sky.lights)));
        type(w->skyPanel()->findChild<QSpinBox*>("sky.lights"), "1");
        QCOMPARE(sky.lights, 1);
        QCOMPARE(sky.interleave, 1);
        QCOMPARE(w->skyPanel()->interleave()->maximum(), 1);
        QCOMPARE(readsBack(), QString());

        // Seed 41: the render window's samples typed above 4096, then Render.
        RenderWindow* r = w->renderImage();
        type(r->findChild<QSpinBox*>("renderSamples"), "7781");
        QTest::mouseClick(r->findChild<QPushButton*>("renderButton"), Qt::LeftButton);
        w->jobs()->cancelAll();
        QTRY_VERIFY_WITH_TIMEOUT(!w->jobs()->isBusy(), 60000);
        QVERIFY2(w->document()->scene().render.spp <= 4096, qPrintable(QString::number(w->document()->scene().render.spp)));
        QCOMPARE(readsBack(), QString());
        r->close();

        // Seed 44: the camera page's target put straight below the eye (the view along up): not applied.
        w->propertyPanel()->showItem({OutlinerItem::Kind::Camera, -1});
        const CameraDesc before = w->document()->scene().camera;
        type(w->propertyPanel()->findChild<QDoubleSpinBox*>("camera.target.x"), QString::number(before.position.x, 'f', 3));
        type(w->propertyPanel()->findChild<QDoubleSpinBox*>("camera.target.z"), QString::number(before.position.z, 'f', 3));
        QVERIFY(cameraUsable(w->document()->scene().camera));
        QCOMPARE(readsBack(), QString());

        // Seed 48: wheel zooms about picked points took the eye and the target 1e20 m out, where they became one point
        // in double. Which points the wheel picks depends on the frames drawn by then, so the check hands the window
        // such a navigation's camera as the viewport reports it: not applied.
        CameraDesc far = w->document()->scene().camera;
        far.position = glm::dvec3(-8.9e19, -3.6e17, -1.1e20);
        far.target = far.position;
        Q_EMIT w->viewport()->navigated(far);
        QVERIFY(cameraUsable(w->document()->scene().camera));
        QCOMPARE(readsBack(), QString());
        QVERIFY(takeWarnings().isEmpty());
    }

    void killAndRecover_data()
    {
        QTest::addColumn<quint64>("seed");
        for (quint64 s : seeds(kKillSeeds)) QTest::addRow("seed %llu", s) << s;
    }

    // The studio killed (SIGKILL) at a random point of a monkey run in a child process (this program again,
    // SYLVA_MONKEY_CHILD set); a new window recovers the scene of the last autosave before the kill exactly,
    // or offers nothing when there was none to keep.
    void killAndRecover()
    {
        QFETCH(quint64, seed);
        if (qEnvironmentVariableIsSet("SYLVA_MONKEY_CHILD")) {
            child(seed, qEnvironmentVariable("SYLVA_MONKEY_CHILD"));
            return;
        }
        freshSettings();
        const QString want = m_dir->filePath(QStringLiteral("autosaved-%1.json").arg(seed));
        QFile::remove(want);
        QProcessEnvironment env = QProcessEnvironment::systemEnvironment();
        env.insert("SYLVA_MONKEY_CHILD", want);
        env.insert("SYLVA_MONKEY_SEED", QString::number(seed));
        const Run run = runProgram(QCoreApplication::applicationFilePath(), {QStringLiteral("killAndRecover:seed %1").arg(seed)}, env, 240000);
        // Killed: no normal exit (a normal exit is a failure in the child, or no kill).
        QVERIFY2(run.code == -1 && !run.err.contains("timed out"), qPrintable(QStringLiteral("the child was not killed (exit %1):\n%2\n%3")
                                                                                      .arg(run.code)
                                                                                      .arg(run.out.right(6000), run.err.right(3000))));
        QVERIFY2(run.out.contains("monkey child: kill"), qPrintable(run.out.right(6000)));
        for (const QString& line : run.out.split('\n'))
            if (line.startsWith("monkey child: kill")) qInfo("%s", qPrintable(line));
        const QString rec = AutosaveController::recoveryFilePath();
        QFile f(want);
        const bool autosaved = f.open(QIODevice::ReadOnly);
        const QByteArray wantJson = autosaved ? f.readAll() : QByteArray();
        QCOMPARE(QFileInfo::exists(rec), autosaved);

        int offered = 0;
        QStringList errors;
        auto w = std::make_unique<MainWindow>();
        quietWindow(*w, &errors);
        w->lighting()->setAutoLighting(false);
        w->autosave()->setRecoveryPrompt([&](const QString&, const QDateTime&) { return ++offered > 0; });
        QTRY_VERIFY(!QFileInfo::exists(rec));   // offered (and deleted) at start-up
        QCOMPARE(offered, autosaved ? 1 : 0);
        QVERIFY2(errors.isEmpty(), qPrintable(errors.join('\n')));
        if (autosaved) {
            QCOMPARE(QString::fromStdString(json(w->document()->scene())), QString::fromUtf8(wantJson));
            QVERIFY(w->document()->isModified());
        } else {
            QVERIFY(w->document()->scene().species.empty());
        }
        QVERIFY(takeWarnings().isEmpty());
    }

private:
    // The child's run: the monkey with autosave every 100 ms; each autosave's scene (sceneToJson) written to `want`
    // (removed with the recovery file), then a SIGKILL at a random action.
    void child(quint64 seed, const QString& want)
    {
        QStringList errors;
        auto w = window(&errors);
        QVERIFY(w);
        Monkey monkey(*w, seed, m_dir->filePath(QStringLiteral("child-%1").arg(seed)), logPath("kill", seed));
        QVERIFY(monkey.lightFully());
        const int n = actionCount(kKillActions);
        const int killAt = n / 4 + monkey.below(n - n / 4);
        const QString rec = AutosaveController::recoveryFilePath();
        auto keep = [&] {
            QFile::remove(want);
            if (!QFileInfo::exists(rec)) return;
            QFile f(want);
            QVERIFY(f.open(QIODevice::WriteOnly));
            f.write(QByteArray::fromStdString(json(w->document()->scene())));
        };
        connect(w->autosave(), &AutosaveController::autosaved, this, keep);
        // After the autosave controller's own handler: a clean document has no recovery file left.
        connect(w->document(), &SceneDocument::modifiedChanged, this, [&](bool modified) {
            if (!modified && !QFileInfo::exists(rec)) QFile::remove(want);
        });
        w->autosave()->setInterval(100);
        for (int i = 0; i < killAt; ++i) {
            const QString problem = monkey.step();
            QVERIFY2(problem.isEmpty(), qPrintable(monkey.report(problem)));
            if (monkey.chance(0.1)) {
                monkey.note(QStringLiteral("autosave now"));
                w->autosave()->autosaveNow();
            }
            if (!QFileInfo::exists(rec)) QFile::remove(want);
        }
        monkey.note(QStringLiteral("kill"));
        printf("monkey child: kill after %d actions (recovery file %s)\n", killAt, QFileInfo::exists(rec) ? "present" : "absent");
        fflush(stdout);
        ::kill(::getpid(), SIGKILL);
    }
};

QTEST_MAIN(TstStudioMonkey)
#include "tst_studio_monkey.moc"
