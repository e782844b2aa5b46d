// The extension points of docs/ARCHITECTURE.md that the renderer's lists do not cover, each checked by adding
// one small thing of its kind through the route the document gives, against an oracle of its own:
// - a source of volume density: a uniform ball with its ParamSpec table, its command's options and --help
//   generated from the table (pipeline/cli/param_options.h), values out of range refused naming the parameter,
//   the grid written and read back through the grid files, its total density the closed-form volume;
// - a scene field: a table over a struct of the test, nested as the scene file nests its sections, with a
//   ranged row through TableBuilder::param: exact text written, random values read back bit for bit, values
//   outside the bounds and unknown keys refused naming the key path, the documentation rows;
// - a command: a Command added to the table of `sylva` and run through the command line main.cpp runs
//   (runCommandLine): `sylva --help`, its --help, its result against the Gauss circle counts, the exit codes
//   and messages of bad usage, failure and cancellation, the man page and the bash completion;
// - a study scene: a function returning a TruthScene added to the list of `sylva study truth`, its key distinct
//   from the others' and picked by SYLVA_TRUTH_SCENES, Sylva's picture of it against the closed-form radiance
//   of a sunlit ground under the constant sky (the one tst_blender checks Cycles against), its Blender script.
#include <QTemporaryDir>
#include <QTest>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <random>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include <unistd.h>

#include "core/base/error.h"
#include "core/base/param_spec.h"
#include "core/grid/grid.h"
#include "core/render/render_cpu.h"
#include "pipeline/cli/cli_docs.h"
#include "pipeline/cli/cli_util.h"
#include "pipeline/cli/commands.h"
#include "pipeline/cli/common_options.h"
#include "pipeline/cli/param_options.h"
#include "pipeline/io/grid_file.h"
#include "pipeline/io/output_path.h"
#include "pipeline/render/render_job.h"
#include "pipeline/scene/field_table.h"
#include "pipeline/study/blender_scene.h"
#include "pipeline/study/study_truth.h"
#include "tests/common/scenes.h"

using namespace sylva;
using namespace sylva::cli;

namespace {

constexpr double kPi = 3.14159265358979323846;

// ---- a source of volume density: a uniform ball ----

inline constexpr ParamSpec kBallRadius{.key = "radius", .metavar = "R", .lo = 0.0, .loOpen = true, .def = {1.0},
                                       .help = "radius of the ball, metres"};
inline constexpr ParamSpec kBallDensity{.key = "density", .metavar = "D", .lo = 0.0, .hi = 1.0, .loOpen = true, .def = {0.5},
                                        .help = "density inside the ball"};
inline constexpr ParamSpec kBallResolution{.key = "resolution", .kind = ParamSpec::Kind::Integer, .metavar = "N", .lo = 8, .hi = 256,
                                           .def = {32}, .help = "nodes per axis of the cubic grid"};
inline constexpr ParamSpec kBallCentre{.key = "centre", .metavar = "X,Y,Z", .count = 3, .def = {0.0, 0.0, 0.0},
                                       .help = "world position of the ball's centre, metres"};
inline constexpr const ParamSpec* kBallParams[] = {&kBallRadius, &kBallDensity, &kBallResolution, &kBallCentre};

struct BallParams {
    float radius = float(kBallRadius.def[0]);
    float density = float(kBallDensity.def[0]);
    int resolution = int(kBallResolution.def[0]);
    glm::vec3 centre{float(kBallCentre.def[0]), float(kBallCentre.def[1]), float(kBallCentre.def[2])};
};

void validateBall(const BallParams& p)
{
    checkParam(kBallRadius, double(p.radius), "ball");
    checkParam(kBallDensity, double(p.density), "ball");
    checkParam(kBallResolution, p.resolution, "ball");
    for (int a = 0; a < 3; ++a) checkParam(kBallCentre, double(p.centre[a]), "ball", "centre");
}

// resolution^3 nodes, an empty one-node margin, the interior cells covering the cube of half side R around the
// centre; density D x clamp(0.5 + (R - |p|) / spacing, 0, 1) at each node p (a one-node anti-aliased edge).
DensityGrid makeBall(const BallParams& p)
{
    validateBall(p);
    DensityGrid g;
    const int n = p.resolution;
    g.geometry.dims = glm::ivec3(n);
    g.geometry.spacing = 2.0 * double(p.radius) / double(n - 3);
    g.geometry.origin = glm::dvec3(p.centre) - glm::dvec3(double(p.radius) + g.geometry.spacing);
    g.density.assign(g.geometry.nodeCount(), 0.0f);
    g.woodFraction.assign(g.geometry.nodeCount(), 0.0f);
    const double h = g.geometry.spacing;
    for (int i = 1; i < n - 1; ++i)
        for (int j = 1; j < n - 1; ++j)
            for (int k = 1; k < n - 1; ++k) {
                const glm::dvec3 w = g.geometry.origin + h * glm::dvec3(i, j, k);
                const double r = glm::length(w - glm::dvec3(p.centre));
                g.density[g.geometry.index(i, j, k)] = float(double(p.density) * std::clamp(0.5 + (double(p.radius) - r) / h, 0.0, 1.0));
            }
    return g;
}

// Its command, as volumeCommand declares `sylva volume cloud`: options and --help from the table, the values
// read into the struct, validated before any file is touched.
int runBall(const Args& args)
{
    BallParams p;
    readParam(args, kBallRadius, p.radius);
    readParam(args, kBallDensity, p.density);
    readParam(args, kBallResolution, p.resolution);
    readParam(args, kBallCentre, p.centre);
    const std::string out = outputFile(args, gridFileExtensions());
    validateBall(p);
    requireReplaceableFile(out);
    writeDensityFile(out, makeBall(p));
    std::printf("wrote %s\n", out.c_str());
    return kOk;
}

Command ballCommand()
{
    Command c{"ball", "[options] -o BALL.npy|.vdb", "make a density volume: a uniform ball", {}, 0, 0, &runBall};
    for (const ParamSpec* spec : kBallParams) c.options.push_back(paramOption(*spec));
    c.options.push_back(kOutput);
    return c;
}

// ---- a command: the lattice points in a disc ----

int runDisc(const Args& args)
{
    const double r = parseNumber("--radius", args.require("--radius"));
    if (r < 0.0) throw Error("radius " + std::to_string(r) + " must be >= 0");
    if (args.has("--cancel")) throw Cancelled();
    long long count = 0;
    const long long m = (long long)std::floor(r);
    for (long long x = -m; x <= m; ++x)
        for (long long y = -m; y <= m; ++y)
            if (double(x * x + y * y) <= r * r) ++count;
    std::printf("%lld lattice points\n", count);
    return kOk;
}

Command discCommand()
{
    return Command{"disc", "--radius R", "count the integer points (x, y) with x^2 + y^2 <= R^2",
                   {{"--radius", "R", "radius of the disc"}, {"--cancel", "", "stop as a cancelled job does"}}, 0, 0, &runDisc};
}

// The command line over a table, its stdout and stderr caught in files.
struct LineRun {
    int code = -1;
    std::string out, err;
};

std::string readAll(FILE* f)
{
    std::string s;
    std::rewind(f);
    char buf[4096];
    size_t n;
    while ((n = std::fread(buf, 1, sizeof buf, f)) > 0) s.append(buf, n);
    std::fclose(f);
    return s;
}

LineRun runLine(const std::vector<Command>& table, const std::vector<std::string>& args)
{
    LineRun r;
    FILE* out = std::tmpfile();
    FILE* err = std::tmpfile();
    std::fflush(stdout);
    std::fflush(stderr);
    const int savedOut = ::dup(1), savedErr = ::dup(2);
    ::dup2(fileno(out), 1);
    ::dup2(fileno(err), 2);
    r.code = runCommandLine(table, args);
    std::fflush(stdout);
    std::fflush(stderr);
    ::dup2(savedOut, 1);
    ::dup2(savedErr, 2);
    ::close(savedOut);
    ::close(savedErr);
    r.out = readAll(out);
    r.err = readAll(err);
    return r;
}

QString said(const LineRun& r)
{
    return QString("exit %1\nstdout: %2\nstderr: %3").arg(r.code).arg(QString::fromStdString(r.out), QString::fromStdString(r.err));
}

bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

// ---- a scene field: a mist section ----

inline constexpr ParamSpec kMistThickness{.key = "thickness", .metavar = "T", .lo = 0.0, .loOpen = true, .def = {2.5},
                                          .help = "height of the mist layer, metres"};

struct Mist {
    float thickness = float(kMistThickness.def[0]);
    int layers = 3;
    bool drifting = false;
};

struct Weather {   // stands for the scene: the top-level table holding the section
    int version = 1;
    Mist mist;
};

const json::Table<Mist>& mistTable()
{
    static const json::Table<Mist> table = [] {
        json::TableBuilder<Mist> b(json::Layout::Inline);
        b.param(kMistThickness, &Mist::thickness).summarized([](const Mist& m) { return "mist " + json::fmt(m.thickness) + " m"; });
        b.integer("layers", &Mist::layers, 1, 8).doc("integer", "layers of the mist, 1..8");
        b.boolean("drifting", &Mist::drifting).doc("bool", "whether the mist moves with the wind");
        return b.table;
    }();
    return table;
}

const json::Table<Weather>& weatherTable()
{
    static const json::Table<Weather> table = [] {
        json::TableBuilder<Weather> b(json::Layout::Block);
        b.integer("version", &Weather::version, 1, 1).doc("integer", "1").required("missing (required)");
        b.object("mist", &Weather::mist, mistTable()).doc("object", "a layer of mist; optional");
        return b.table;
    }();
    return table;
}

std::string writeWeather(const Weather& w)
{
    json::JsonWriter out;
    json::writeObject(out, w, json::KeyPath{}, weatherTable(), 0);
    return out.text;
}

Weather readWeather(const std::string& text)
{
    json::JsonReader r("weather.json");
    Weather w;
    json::readObject(r, json::parseObject(text, r.name(), "not a JSON object"), json::KeyPath{}, w, weatherTable());
    return w;
}

// The error readWeather throws on text, empty when it reads.
std::string refusal(const std::string& text)
{
    try {
        readWeather(text);
    } catch (const Error& e) {
        return e.what();
    }
    return {};
}

// The row type documentFields fills (a FieldDoc or a type holding one).
template <class F>
struct RowOf;
template <class T, class Row>
struct RowOf<void (*)(const json::Table<T>&, const std::string&, std::vector<Row>&)> {
    using type = Row;
};
using WeatherRow = RowOf<decltype(&json::documentFields<Weather>)>::type;

// ---- a study scene: a shrub on a sunlit ground, the camera looking down on the open ground beside it ----

study::TruthScene litGroundScene()
{
    study::TruthScene t;
    t.key = "lit_ground";
    t.title = "the open ground beside a shrub under the sun and the constant sky, seen from above";
    Scene& s = t.scene;
    s.species = {test::shrubSpecies(16, 7, 1500)};
    InstanceDesc shrub;
    shrub.position = {30.0, 0.0, 30.0};
    s.instances = {shrub};
    s.render.width = 16;
    s.render.height = 12;
    s.render.spp = 4;
    s.sun.direction = sunDirection(50.0, 30.0);
    s.sun.temperature = 5000.0;
    s.sky = {0.30f, 0.40f, 0.60f};
    s.ground.color = {0.50f, 0.30f, 0.20f};
    s.camera.position = {0.0, 6.0, 0.0};
    s.camera.target = {0.0, 0.0, 2.0};
    s.camera.fovY = 30.0f;
    t.refSamples = 64;
    t.sweep = {1, 4, 16};
    return t;
}

// Sets an environment variable for a scope.
struct EnvVar {
    EnvVar(const char* name, const char* value) : m_name(name) { qputenv(name, value); }
    ~EnvVar() { qunsetenv(m_name); }
    const char* m_name;
};

} // namespace

class TestExtensionPoints : public QObject {
    Q_OBJECT

private Q_SLOTS:
    // A source of volume density: the ball's table gives its command's options and --help; values are parsed,
    // refused outside their range (exit 1, naming the parameter) or when no number (exit 2); the written grid
    // holds D x (4/3) pi R^3 of density.
    void volumeSource()
    {
        const std::vector<Command> table = {ballCommand()};
        const LineRun help = runLine(table, {"ball", "--help"});
        QVERIFY2(help.code == kOk, qPrintable(said(help)));
        for (const ParamSpec* s : kBallParams) {
            const std::string line = "--" + std::string(s->key) + " " + s->metavar;
            QVERIFY2(contains(help.out, line), qPrintable("--help lacks " + QString::fromStdString(line) + "\n" + said(help)));
            QVERIFY2(contains(help.out, paramHelp(*s)), qPrintable(QString::fromStdString(paramHelp(*s))));
        }
        QVERIFY(contains(help.out, "radius of the ball, metres, > 0 (default 1)"));
        QVERIFY(contains(help.out, "nodes per axis of the cubic grid, 8..256 (default 32)"));
        QVERIFY(contains(help.out, "density inside the ball, (0, 1] (default 0.5)"));

        QTemporaryDir dir;
        const std::string path = dir.filePath("ball.npy").toStdString();
        auto refused = [&](std::vector<std::string> args, int code, const std::string& message) {
            args.insert(args.begin(), "ball");
            args.insert(args.end(), {"-o", path});
            const LineRun r = runLine(table, args);
            QVERIFY2(r.code == code && contains(r.err, message), qPrintable("want exit " + QString::number(code) + " and '" +
                                                                            QString::fromStdString(message) + "'\n" + said(r)));
            QVERIFY2(!std::ifstream(path).good(), "a refused value left a file");
        };
        refused({"--radius", "0"}, kFailure, "sylva ball: error: ball: radius 0 must be > 0");
        refused({"--radius", "-2"}, kFailure, "radius -2 must be > 0");
        refused({"--density", "1.5"}, kFailure, "density 1.5 must lie in (0, 1]");
        refused({"--resolution", "7"}, kFailure, "resolution 7 must lie in 8..256");
        refused({"--resolution", "257"}, kFailure, "resolution 257 must lie in 8..256");
        refused({"--radius", "wide"}, kUsage, "--radius");
        refused({"--resolution", "2.5"}, kUsage, "--resolution");
        refused({"--centre", "1,2"}, kUsage, "--centre");

        const double R = double(0.8f), D = double(0.25f);
        const glm::dvec3 c(0.5, -1.25, 2.0);
        for (int n : {24, 48}) {
            const LineRun r = runLine(table, {"ball", "--radius", "0.8", "--density", "0.25", "--resolution", std::to_string(n),
                                              "--centre", "0.5,-1.25,2", "-o", path});
            QVERIFY2(r.code == kOk && contains(r.out, "wrote " + path), qPrintable(said(r)));
            const DensityGrid g = readDensityFile(path);
            QVERIFY(g.geometry.dims == glm::ivec3(n));
            const double h = g.geometry.spacing;
            QVERIFY(std::fabs(h - 2.0 * R / (n - 3)) < 1e-12 * R);
            double total = 0.0;
            float most = 0.0f;
            for (float v : g.density) {
                QVERIFY(v >= 0.0f && v <= float(D));
                total += double(v);
                most = std::max(most, v);
            }
            QCOMPARE(most, float(D));
            total *= h * h * h;
            // The closed form: a ball of density D, its edge a linear ramp one spacing wide, holds
            // D x (4/3) pi (R^3 + R h^2 / 4); the nodes sample it to within a shell of 1/500 of a spacing.
            const double ball = D * 4.0 / 3.0 * kPi * R * R * R, ramped = D * 4.0 / 3.0 * kPi * (R * R * R + R * h * h / 4.0);
            const double shell = D * 4.0 * kPi * R * R * h;
            qInfo("resolution %d: total %.6f, ball %.6f, with its ramp %.6f (error %.2e of a one-spacing shell)", n, total, ball, ramped,
                  std::fabs(total - ramped) / shell);
            QVERIFY2(std::fabs(total - ramped) < shell / 500.0, qPrintable(QString::number(total)));
            QVERIFY2(std::fabs(total - ball) < 0.01 * ball, qPrintable(QString::number(total)));
            // Its centre lies where it was put: the density's centroid.
            glm::dvec3 m(0.0);
            double w = 0.0;
            for (int i = 0; i < n; ++i)
                for (int j = 0; j < n; ++j)
                    for (int k = 0; k < n; ++k) {
                        const double v = double(g.density[g.geometry.index(i, j, k)]);
                        m += v * (g.geometry.origin + h * glm::dvec3(i, j, k));
                        w += v;
                    }
            QVERIFY(glm::length(m / w - c) < 1e-6);
        }
    }

    // A scene field: a section with a ranged row (TableBuilder::param), an integer and a flag, nested in a
    // Block table as the scene file nests its sections.
    void sceneField()
    {
        // Written: the defaults, then other values, exactly.
        QCOMPARE(writeWeather(Weather{}), std::string("{\n  \"version\": 1,\n  \"mist\": {\"thickness\": 2.5, \"layers\": 3, \"drifting\": false}\n}"));
        Weather w;
        w.mist = {0.1f, 8, true};
        QCOMPARE(writeWeather(w), std::string("{\n  \"version\": 1,\n  \"mist\": {\"thickness\": 0.1, \"layers\": 8, \"drifting\": true}\n}"));
        // Read back: absent fields keep their defaults; random values come back bit for bit.
        const Weather absent = readWeather(R"({"version": 1})");
        QCOMPARE(absent.mist.thickness, 2.5f);
        QCOMPARE(absent.mist.layers, 3);
        std::mt19937 rng(7);
        std::uniform_real_distribution<float> exponent(-20.0f, 20.0f);
        std::uniform_int_distribution<int> layers(1, 8);
        for (int i = 0; i < 300; ++i) {
            Weather x;
            x.mist = {std::exp2(exponent(rng)), layers(rng), i % 2 == 0};
            const Weather y = readWeather(writeWeather(x));
            QVERIFY2(y.mist.thickness == x.mist.thickness && y.mist.layers == x.mist.layers && y.mist.drifting == x.mist.drifting,
                     qPrintable(QString::fromStdString(writeWeather(x))));
        }
        // Refused, naming the file, the key path and the bound.
        QCOMPARE(refusal(R"({"version": 1, "mist": {"thickness": 0}})"), std::string("weather.json: mist.thickness: must be > 0, got 0"));
        QCOMPARE(refusal(R"({"version": 1, "mist": {"thickness": -3}})"), std::string("weather.json: mist.thickness: must be > 0, got -3"));
        QVERIFY(refusal(R"({"version": 1, "mist": {"thickness": 1e-30}})").empty());
        QVERIFY(refusal(R"({"version": 1, "mist": {"layers": 8}})").empty());
        for (const char* bad : {R"({"version": 1, "mist": {"layers": 9}})", R"({"version": 1, "mist": {"layers": 0}})",
                                R"({"version": 1, "mist": {"layers": 2.5}})"}) {
            const std::string e = refusal(bad);
            QVERIFY2(contains(e, "weather.json: mist.layers:"), qPrintable(QString::fromStdString(bad) + " -> " + QString::fromStdString(e)));
        }
        QVERIFY(contains(refusal(R"({"version": 1, "mist": {"thickness": "thick"}})"), "weather.json: mist.thickness:"));
        const std::string unknown = refusal(R"({"version": 1, "mist": {"height": 2}})");
        QVERIFY2(contains(unknown, "mist.height") && contains(unknown, "thickness, layers, drifting"), unknown.c_str());
        QCOMPARE(refusal(R"({"mist": {}})"), std::string("weather.json: version: missing (required)"));
        // Its summary for people, and the rows of the field table documenting it (as docs/SCENE.md's).
        QCOMPARE(json::summarize(w.mist, mistTable()), std::string("mist 0.1 m"));
        std::vector<WeatherRow> rows;
        json::documentFields(weatherTable(), "", rows);
        const std::vector<std::vector<std::string>> want = {
            {"version", "integer", "1", "1"},
            {"mist", "object", "", "a layer of mist; optional"},
            {"mist.thickness", "number", "2.5", "height of the mist layer, metres, > 0"},
            {"mist.layers", "integer", "3", "layers of the mist, 1..8"},
            {"mist.drifting", "bool", "false", "whether the mist moves with the wind"},
        };
        QCOMPARE(rows.size(), want.size());
        for (size_t i = 0; i < rows.size(); ++i) {
            const std::vector<std::string> has = {rows[i].key, rows[i].type, rows[i].defaultValue, rows[i].rule};
            QVERIFY2(has == want[i], qPrintable(QString::fromStdString(rows[i].key + " | " + rows[i].type + " | " + rows[i].defaultValue +
                                                                       " | " + rows[i].rule)));
            QCOMPARE(rows[i].section, i == 1);
        }
    }

    // A command: one line added to the table of `sylva` (commandTable), run by the command line main.cpp runs.
    void command()
    {
        const std::vector<Command> real = commandTable();
        std::vector<Command> table = real;
        table.push_back(discCommand());

        const LineRun top = runLine(table, {"--help"});
        QVERIFY2(top.code == kOk, qPrintable(said(top)));
        QVERIFY(contains(top.out, "  disc       count the integer points (x, y) with x^2 + y^2 <= R^2\n"));
        for (const Command& c : real) QVERIFY2(contains(top.out, "  " + c.name + " "), c.name.c_str());
        QCOMPARE(runLine(table, {}).code, int(kUsage));

        const LineRun help = runLine(table, {"disc", "--help"});
        QVERIFY2(help.code == kOk, qPrintable(said(help)));
        QVERIFY(contains(help.out, "usage: sylva disc --radius R\n"));
        QVERIFY(contains(help.out, "  --radius R"));
        QVERIFY(contains(help.out, "radius of the disc"));

        // The Gauss circle problem's counts N(r) = #{(x, y) : x^2 + y^2 <= r^2} (OEIS A000328 at r = 0..5, 10).
        const std::vector<std::pair<std::string, long long>> counts = {{"0", 1}, {"1", 5}, {"2", 13}, {"3", 29}, {"4", 49},
                                                                        {"5", 81}, {"10", 317}, {"2.5", 21}};
        for (const auto& [r, n] : counts) {
            const LineRun run = runLine(table, {"disc", "--radius", r});
            QVERIFY2(run.code == kOk && run.out == std::to_string(n) + " lattice points\n", qPrintable(said(run)));
        }
        const LineRun inlineValue = runLine(table, {"disc", "--radius=3"});
        QCOMPARE(inlineValue.out, std::string("29 lattice points\n"));

        auto fails = [&](const std::vector<std::string>& args, int code, const std::string& message) {
            const LineRun r = runLine(table, args);
            QVERIFY2(r.code == code && contains(r.err, message) && r.out.empty(),
                     qPrintable("want exit " + QString::number(code) + " and '" + QString::fromStdString(message) + "'\n" + said(r)));
        };
        fails({"disc"}, kUsage, "sylva disc: ");
        fails({"disc"}, kUsage, "--radius");
        fails({"disc", "--radius", "many"}, kUsage, "sylva disc: ");
        fails({"disc", "--radius", "3", "--width", "2"}, kUsage, "--width");
        fails({"disc", "--radius", "3", "extra"}, kUsage, "sylva disc: ");
        fails({"disc", "--radius", "-1"}, kFailure, "sylva disc: error: radius -1.000000 must be >= 0");
        fails({"disc", "--radius", "3", "--cancel"}, kFailure, "sylva disc: cancelled");
        fails({"circle"}, kUsage, "sylva: unknown command 'circle' (see sylva --help)");

        // The man page and the bash completion follow the table.
        const LineRun man = runLine(table, {"--man"}), completion = runLine(table, {"--completion"});
        QCOMPARE(man.code, int(kOk));
        QCOMPARE(completion.code, int(kOk));
        QVERIFY(contains(man.out, "disc"));
        QVERIFY(contains(man.out, "radius of the disc"));
        QVERIFY(contains(completion.out, "disc"));
        QVERIFY(contains(completion.out, "--cancel"));
        QVERIFY(!contains(runLine(real, {"--man"}).out, "radius of the disc"));
        QVERIFY(!contains(runLine(real, {"--completion"}).out, "--cancel"));
    }

    // A study scene: added to the list of `sylva study truth`, picked by its key; what runs without Blender:
    // Sylva's picture of it against the closed form, its Blender script.
    void studyScene()
    {
        study::Options o;
        std::vector<study::TruthScene> scenes = study::truthSceneList(o);
        const size_t builtIn = scenes.size();
        QVERIFY(builtIn >= 4);
        scenes.push_back(litGroundScene());
        // Keys: distinct over the list (every pair), the same on every call.
        std::set<std::string> keys;
        for (const study::TruthScene& t : scenes) {
            QVERIFY2(!t.key.empty() && t.key.find(',') == std::string::npos, t.key.c_str());
            QVERIFY2(keys.insert(t.key).second, qPrintable("two scenes have the key " + QString::fromStdString(t.key)));
        }
        const std::vector<study::TruthScene> again = study::truthSceneList(o);
        for (size_t i = 0; i < builtIn; ++i) QCOMPARE(again[i].key, scenes[i].key);
        QCOMPARE(litGroundScene().key, scenes.back().key);
        {
            const EnvVar only("SYLVA_TRUTH_SCENES", "stand,lit_ground");
            const std::vector<study::TruthScene> picked = study::pickTruthScenes(scenes);
            QCOMPARE(picked.size(), size_t(2));
            QCOMPARE(picked[0].key, std::string("stand"));
            QCOMPARE(picked[1].key, std::string("lit_ground"));
            const EnvVar fewer("SYLVA_TRUTH_SAMPLE_DIVISOR", "4");
            const std::vector<study::TruthScene> divided = study::pickTruthScenes(scenes);
            QCOMPARE(divided[1].refSamples, 16);
            QVERIFY(divided[1].sweep == std::vector<int>({1, 4}));
        }
        {
            const EnvVar none("SYLVA_TRUTH_SCENES", "lit");
            QVERIFY(study::pickTruthScenes(scenes).empty());
        }
        QCOMPARE(study::pickTruthScenes(scenes).size(), scenes.size());

        // Sylva's picture, as `sylva render` draws it (full mode): the sunlit ground under the constant sky shows
        // albedo x (sunRadiance x cos + sky) in every pixel.
        const study::TruthScene t = scenes.back();
        const Scene& s = t.scene;
        const std::vector<SpeciesAssets> assets = loadSpeciesAssets(s, nullptr, false);
        QCOMPARE(assets.size(), size_t(1));
        const glm::vec3 rad = sunRadiance(s.sun);
        const RenderOutput rendered = renderScene(s, nullptr);
        const std::vector<glm::vec3> img = composeMode(rendered.film, RenderMode::Full, composeSky(s));
        QCOMPARE(img.size(), size_t(s.render.width * s.render.height));
        const double cosSun = double(glm::normalize(s.sun.direction).y);
        double worst = 0.0;
        for (const glm::vec3& px : img)
            for (int k = 0; k < 3; ++k) {
                const double expected = double(s.ground.color[k]) * (double(rad[k]) * cosSun + double(s.sky[k]));
                worst = std::max(worst, std::fabs(double(px[k]) / expected - 1.0));
            }
        qInfo("the lit ground against the closed form: largest relative difference %.2e", worst);
        QVERIFY2(worst < 1e-5, qPrintable(QString::number(worst)));

        // Its Blender script, as the study writes it for Cycles: the scene's resolution.
        QTemporaryDir dir;
        const std::string script = study::writeBlenderScene(s, assets, dir.path().toStdString() + "/" + t.key, study::BlenderOptions{});
        std::ifstream in(script);
        std::stringstream text;
        text << in.rdbuf();
        QVERIFY2(contains(text.str(), "sc.render.resolution_x = 16\nsc.render.resolution_y = 12\n"), script.c_str());
    }
};

QTEST_GUILESS_MAIN(TestExtensionPoints)
#include "tst_extension_points.moc"
