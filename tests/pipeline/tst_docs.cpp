// The docs against the code, so they stay true:
//  - docs/TESTING.md's test table, with the studio's table in docs/STUDIO.md ("Tests (label `gui`)"), names
//    exactly the tests CTest registers in this build (`ctest -N`), one well-formed row each;
//  - docs/CLI.md gives each command exactly the options of its `sylva COMMAND --help`: every option the help
//    lists appears in that command's section, and every option the page gives a command (in its section, or
//    in a code span `sylva COMMAND ...` anywhere) is one its help lists;
//  - the option tables of `sylva volume cloud` and `sylva simulate` in docs/CLI.md are, row for row, the
//    parameters' declarations (core/volume: kCloudParams, kSmokeParams): help, default and range.
#include <QDir>
#include <QDirIterator>
#include <QFile>
#include <QRegularExpression>
#include <QTest>

#include <map>
#include <set>

#include "core/volume/pyroclastic.h"
#include "core/volume/smoke.h"
#include "tests/common/run_program.h"

namespace {

using sylva::test::Run;
using sylva::test::runProgram;
using sylva::test::sylvaHelpTable;

QString readText(const QString& path)
{
    QFile f(path);
    return f.open(QIODevice::ReadOnly) ? QString::fromUtf8(f.readAll()) : QString();
}

QString sourcePath(const QString& rel) { return QStringLiteral(SYLVA_SOURCE_DIR "/") + rel; }

// The cells of a Markdown table row: split at '|' outside code spans (and not escaped), the empty text before
// the first and after the last bar dropped.
QStringList tableCells(const QString& line)
{
    QStringList cells;
    QString cell;
    bool code = false;
    for (qsizetype i = 0; i < line.size(); ++i) {
        const QChar c = line[i];
        if (c == '\\' && i + 1 < line.size()) {
            cell += c;
            cell += line[++i];
            continue;
        }
        if (c == '`') code = !code;
        if (c == '|' && !code) {
            cells << cell.trimmed();
            cell.clear();
            continue;
        }
        cell += c;
    }
    cells << cell.trimmed();
    if (!cells.isEmpty() && cells.front().isEmpty()) cells.pop_front();
    if (!cells.isEmpty() && cells.back().isEmpty()) cells.pop_back();
    return cells;
}

// The lines of the Markdown section whose heading line starts with `heading` (up to the next heading of the
// same or a higher level); empty when there is none.
QStringList sectionLines(const QString& text, const QString& heading)
{
    static const QRegularExpression headingLine("^(#+) ");
    QStringList out;
    qsizetype level = 0;
    bool fenced = false;
    for (const QString& line : text.split('\n')) {
        if (line.trimmed().startsWith("```")) fenced = !fenced;
        const QRegularExpressionMatch h = fenced ? QRegularExpressionMatch() : headingLine.match(line);
        const qsizetype hashes = h.hasMatch() ? h.capturedLength(1) : 0;
        if (level > 0 && hashes > 0 && hashes <= level) break;
        if (level > 0) out << line;
        if (level == 0 && hashes > 0 && line.startsWith(heading)) level = hashes;
    }
    return out;
}

// A documented test table: the test names of its rows (the code spans of the first cell that name a test)
// and what is wrong with its shape.
struct TestTable {
    std::map<QString, int> rows;   // test -> how many rows name it
    QStringList problems;
};

// The table whose header line is `header`, inside `lines`. A name counts when it is registered or looks like a
// test's (tst_...), so a label in the first cell (`slow`) is not taken for a test.
TestTable readTestTable(const QStringList& lines, const QString& header, const QString& where, const std::set<QString>& registered)
{
    TestTable t;
    qsizetype at = lines.indexOf(header);
    if (at < 0) {
        t.problems << where + ": no table with the header '" + header + "'";
        return t;
    }
    const qsizetype columns = tableCells(header).size();
    static const QRegularExpression span("`([^`]+)`");
    for (qsizetype i = at + 2; i < lines.size() && lines[i].startsWith('|'); ++i) {
        const QStringList cells = tableCells(lines[i]);
        if (cells.size() != columns)
            t.problems << QString("%1: the row '%2' has %3 cells, the table %4").arg(where, lines[i].left(80)).arg(cells.size()).arg(columns);
        if (cells.isEmpty()) continue;
        int named = 0;
        for (const QRegularExpressionMatch& m : span.globalMatch(cells[0])) {
            const QString name = m.captured(1).trimmed();
            if (!registered.count(name) && !name.startsWith("tst_")) continue;
            ++t.rows[name];
            ++named;
        }
        if (named == 0) t.problems << where + ": the row '" + lines[i].left(80) + "' names no test";
    }
    return t;
}

// The tests CTest registers in this build: `ctest -N`'s "Test #N: name" lines.
std::set<QString> registeredTests()
{
    const Run r = runProgram(QStringLiteral(SYLVA_CTEST), {"-N", "--test-dir", QStringLiteral(SYLVA_BUILD_DIR)});
    std::set<QString> names;
    static const QRegularExpression line("Test\\s+#\\d+: (\\S+)");
    for (const QRegularExpressionMatch& m : line.globalMatch(r.out)) names.insert(m.captured(1));
    return names;
}

// Tests the CMake files of tests/ register, some only in some builds (MPI): "NAME <test>" of sylva_add_test,
// sylva_add_xvfb_test and add_test.
std::set<QString> testsInCMakeFiles()
{
    std::set<QString> names;
    static const QRegularExpression reg("\\b(?:sylva_add_test|sylva_add_xvfb_test|add_test)\\s*\\(\\s*NAME\\s+([A-Za-z0-9_]+)");
    QDirIterator it(sourcePath("tests"), {"CMakeLists.txt", "*.cmake"}, QDir::Files, QDirIterator::Subdirectories);
    while (it.hasNext()) {
        const QString text = readText(it.next());
        for (const QRegularExpressionMatch& m : reg.globalMatch(text)) names.insert(m.captured(1));
    }
    return names;
}

// `sylva --help`'s commands, each with the options its `sylva COMMAND --help` lists (as typed: "-h, --help"
// gives both; "--output FILE  output file (also -o)" gives --output and -o).
// One option CLI.md gives a command, and where.
struct Claim {
    QString command, option, section;
    bool own = false;   // in the command's own section
};

// The options a piece of text names: --long-names, and -o.
QStringList optionsIn(const QString& text)
{
    static const QRegularExpression option("(?<![\\w-])(--[a-z](?:[a-z0-9-]*[a-z0-9])?|-o)(?![\\w-])");
    QStringList out;
    for (const QRegularExpressionMatch& m : option.globalMatch(text)) out << m.captured(1);
    return out;
}

// CLI.md read into claims. Sections are the `## ` headings; a section whose heading is a code span
// `sylva COMMAND ...` of a known command is that command's. Text outside code spans gives its options to the
// section's command; inside a code span (or a fenced block's line), `sylva OTHER ...` gives what follows to
// OTHER up to the next `sylva WORD` (a word that is no command, as in `sylva COMMAND --help`, gives to nobody),
// and what comes before the first `sylva` to the section's command.
std::vector<Claim> readCliDoc(const QString& text, const std::map<QString, std::set<QString>>& commands, std::set<QString>* sectionsSeen,
                              QStringList* problems)
{
    std::vector<Claim> claims;
    static const QRegularExpression commandHeading("^## `sylva ([a-z][a-z0-9-]*)");
    static const QRegularExpression invocation("\\bsylva\\s+([A-Za-z][A-Za-z0-9_-]*)");
    QString section = "(top)", owner;   // owner: the section's command, empty for other sections
    QString body;
    auto flush = [&]() {
        // Pieces of the section: plain text and code (inline spans may wrap lines; fenced blocks by line).
        std::vector<std::pair<QString, bool>> pieces;
        QString plain;
        bool fenced = false;
        for (const QString& line : body.split('\n')) {
            if (line.trimmed().startsWith("```")) {
                fenced = !fenced;
                continue;
            }
            if (fenced) pieces.push_back({line, true});
            else plain += line + '\n';
        }
        const QStringList parts = plain.split('`');   // odd parts are code spans
        for (qsizetype i = 0; i < parts.size(); ++i) pieces.push_back({parts[i], i % 2 == 1});
        if (parts.size() % 2 == 0) problems->append("CLI.md, section " + section + ": an unclosed code span");
        for (const auto& [piece, code] : pieces) {
            if (!code) {
                if (!owner.isEmpty())
                    for (const QString& o : optionsIn(piece)) claims.push_back({owner, o, section, true});
                continue;
            }
            QString current = owner;
            qsizetype from = 0;
            for (const QRegularExpressionMatch& m : invocation.globalMatch(piece)) {
                if (!current.isEmpty())
                    for (const QString& o : optionsIn(piece.mid(from, m.capturedStart() - from))) claims.push_back({current, o, section, current == owner});
                current = commands.count(m.captured(1)) ? m.captured(1) : QString();
                from = m.capturedEnd();
            }
            if (!current.isEmpty())
                for (const QString& o : optionsIn(piece.mid(from))) claims.push_back({current, o, section, current == owner});
        }
        body.clear();
    };
    for (const QString& line : text.split('\n')) {
        if (line.startsWith("## ")) {
            flush();
            section = line.mid(3).trimmed();
            const QRegularExpressionMatch m = commandHeading.match(line);
            owner = m.hasMatch() && commands.count(m.captured(1)) ? m.captured(1) : QString();
            if (m.hasMatch() && owner.isEmpty()) problems->append("CLI.md has a section for `sylva " + m.captured(1) + "`, which is no command of sylva --help");
            if (!owner.isEmpty()) {
                if (sectionsSeen->count(owner)) problems->append("CLI.md has two sections for `sylva " + owner + "`");
                sectionsSeen->insert(owner);
            }
        }
        body += line + '\n';
    }
    flush();
    return claims;
}

} // namespace

class TestDocs : public QObject {
    Q_OBJECT

private Q_SLOTS:
    // docs/TESTING.md (and STUDIO.md for the studio's tests) name exactly the registered tests.
    void testingDocNamesEveryTest()
    {
        const std::set<QString> registered = registeredTests();
        QVERIFY2(registered.size() > 20 && registered.count("tst_docs"), "ctest -N lists too few tests (or not this one)");
        const std::set<QString> inCMake = testsInCMakeFiles();   // also those this build leaves out (MPI)

        const QStringList testing = readText(sourcePath("docs/TESTING.md")).split('\n');
        const QStringList studio = sectionLines(readText(sourcePath("docs/STUDIO.md")), "## Tests (label `gui`)");
        QVERIFY2(!testing.isEmpty() && !studio.isEmpty(), "docs/TESTING.md or STUDIO.md's \"Tests (label `gui`)\" is missing");
        const TestTable a = readTestTable(testing, "| test | label | oracle |", "docs/TESTING.md", registered);
        const TestTable b = readTestTable(studio, "| test | runs | checks |", "docs/STUDIO.md (Tests)", registered);

        QStringList problems = a.problems + b.problems;
        std::set<QString> documented;
        for (const TestTable* t : {&a, &b})
            for (const auto& [name, count] : t->rows) {
                documented.insert(name);
                if (count > 1) problems << QString("%1 has %2 rows in one table").arg(name).arg(count);
            }
        for (const QString& t : registered)
            if (!documented.count(t)) problems << "no row for the registered test " + t + " (docs/TESTING.md, or STUDIO.md for a gui test)";
        for (const QString& t : documented) {
            if (registered.count(t)) continue;
            if (inCMake.count(t)) qInfo("%s is documented and not registered in this build (registered only in some builds)", qPrintable(t));
            else problems << "a row for " + t + ", which no CMake file registers and ctest -N does not list";
        }
        qInfo("%zu tests registered, %zu documented", registered.size(), documented.size());
        QVERIFY2(problems.isEmpty(), qPrintable("\n  " + problems.join("\n  ")));
    }

    // docs/CLI.md against every command's --help, both ways.
    void cliDocMatchesHelp()
    {
        const std::map<QString, std::set<QString>> help = sylvaHelpTable(QStringLiteral(SYLVA_CLI_PATH));
        QVERIFY2(help.size() >= 10 && help.count("render") && help.at("render").count("--spp"),
                 "sylva --help / sylva render --help did not list what they should (the parse is stale)");
        const QString doc = readText(sourcePath("docs/CLI.md"));
        QVERIFY2(!doc.isEmpty(), "docs/CLI.md is missing");
        QStringList problems;
        std::set<QString> sections;
        const std::vector<Claim> claims = readCliDoc(doc, help, &sections, &problems);

        std::map<QString, std::set<QString>> inSection;   // command -> options its own section names
        for (const Claim& c : claims) {
            const std::set<QString>& options = help.at(c.command);
            if (!options.count(c.option))
                problems << "CLI.md gives `sylva " + c.command + "` the option " + c.option + " (section " + c.section.left(60) +
                                "), which sylva " + c.command + " --help does not list";
            if (c.own) inSection[c.command].insert(c.option);
        }
        for (const auto& [command, options] : help) {
            if (!sections.count(command)) {
                problems << "CLI.md has no section `sylva " + command + " ...`";
                continue;
            }
            std::set<QString> named = inSection[command];
            if (named.count("-o")) named.insert("--output");
            for (const QString& o : options) {
                if (o == "-h" || o == "--help" || o == "-o") continue;   // --help: the page's first line says it once for all
                if (!named.count(o)) problems << "CLI.md's section of `sylva " + command + "` does not mention " + o + ", which its --help lists";
            }
        }
        qInfo("%zu commands, %zu option mentions checked", help.size(), claims.size());
        QVERIFY2(problems.isEmpty(), qPrintable("\n  " + problems.join("\n  ")));
    }

    // docs/CLI.md's parameter tables against the declarations they document, row for row.
    void cliParamTablesMatchDeclarations()
    {
        const QString doc = readText(sourcePath("docs/CLI.md"));
        QVERIFY2(!doc.isEmpty(), "docs/CLI.md is missing");
        const QString header = "| option | meaning | default | range |";
        QStringList problems;
        auto check = [&](const QString& heading, const auto& specs) {
            const QStringList lines = sectionLines(doc, heading);
            const qsizetype at = lines.indexOf(header);
            if (at < 0) {
                problems << "CLI.md, section " + heading + ": no table with the header '" + header + "'";
                return;
            }
            QStringList rows;
            for (qsizetype i = at + 2; i < lines.size() && lines[i].startsWith('|'); ++i) rows << lines[i];
            QStringList want;
            for (const sylva::ParamSpec* s : specs) {
                const std::string range = sylva::paramRange(*s);
                want << QString::fromStdString("| `--" + std::string(s->key) + " " + s->metavar + "` | " + s->help + " | " +
                                               sylva::paramDefault(*s) + " | " + (range.empty() ? "-" : range) + " |");
            }
            for (qsizetype i = 0; i < std::max(rows.size(), want.size()); ++i) {
                const QString has = i < rows.size() ? rows[i] : "(no row)", should = i < want.size() ? want[i] : "(no parameter)";
                if (has != should) problems << "CLI.md, section " + heading + ", row " + QString::number(i + 1) + ":\n    has  " + has + "\n    want " + should;
            }
        };
        check("## `sylva volume cloud", sylva::volume::kCloudParams);
        check("## `sylva simulate", sylva::volume::kSmokeParams);
        QVERIFY2(problems.isEmpty(), qPrintable("\n  " + problems.join("\n  ")));
    }
};

QTEST_GUILESS_MAIN(TestDocs)
#include "tst_docs.moc"
