// Tests of scene files: exact round trips, documented defaults, and key-path messages for malformed scenes.
#include <cmath>
#include <filesystem>
#include <functional>
#include <limits>

#include <QDir>
#include <QElapsedTimer>
#include <QFile>
#include <QJsonArray>
#include <QJsonDocument>
#include <QJsonObject>
#include <QTemporaryDir>
#include <QTest>

#include "core/base/error.h"
#include "core/scene/quality.h"
#include "pipeline/render/render_job.h"
#include "pipeline/scene/scene_fields.h"
#include "pipeline/scene/scene_file.h"
#include "tests/common/files.h"

using namespace sylva;
using test::errorOf;
using test::writeText;

namespace {

const char* kName = "scene.json";

QString sharedTree() { return QStringLiteral(SYLVA_RESOURCES "/trees/quaternius/OBJ/Tree_1.obj"); }

// One triangle: enough for a file that exists and reads as a mesh.
void writeTinyObj(const QString& path) { writeText(path, "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n"); }

void compareLb(const lb::LbParams& a, const lb::LbParams& b)
{
    for (size_t c = 0; c < 3; ++c) {
        QCOMPARE(a.channels[c].sigmaA, b.channels[c].sigmaA);
        QCOMPARE(a.channels[c].sigmaS, b.channels[c].sigmaS);
        QCOMPARE(a.channels[c].g, b.channels[c].g);
    }
    QCOMPARE(a.zeroF0, b.zeroF0);
    QCOMPARE(a.sun, b.sun);
    QCOMPARE(a.intensity, b.intensity);
    QCOMPARE(a.steps, b.steps);
    QCOMPARE(a.stepsPerEdge, b.stepsPerEdge);
    QCOMPARE(a.storage, b.storage);
    QCOMPARE(a.tolerance, b.tolerance);
    QCOMPARE(a.checkEvery, b.checkEvery);
    QCOMPARE(a.maxSteps, b.maxSteps);
    QCOMPARE(a.warmStart, b.warmStart);
    QCOMPARE(a.solvesPerPass, b.solvesPerPass);
    QCOMPARE(a.blockSteps, b.blockSteps);
    QCOMPARE(a.brownThreshold, b.brownThreshold);
    QCOMPARE(a.storage, b.storage);
}

void compareSpecies(const SpeciesDesc& a, const SpeciesDesc& b)
{
    QCOMPARE(a.name, b.name);
    QCOMPARE(a.meshPath, b.meshPath);
    QCOMPARE(a.grow.has_value(), b.grow.has_value());
    if (a.grow) {
        QCOMPARE(a.grow->species, b.grow->species);
        QCOMPARE(a.grow->seed, b.grow->seed);
        QCOMPARE(a.grow->triangles, b.grow->triangles);
        QCOMPARE(a.grow->height, b.grow->height);
    }
    QCOMPARE(a.leafMaterials, b.leafMaterials);
    QCOMPARE(a.preset, b.preset);
    compareLb(a.lighting, b.lighting);
    QCOMPARE(a.grid, b.grid);
}

// Every field, exactly (==, not fuzzy: the writer promises exact numbers).
void compareScenes(const Scene& a, const Scene& b)
{
    QCOMPARE(a.version, b.version);
    QCOMPARE(a.species.size(), b.species.size());
    for (size_t i = 0; i < a.species.size(); ++i) {
        compareSpecies(a.species[i], b.species[i]);
        if (QTest::currentTestFailed()) {
            qWarning("species[%zu] differs", i);
            return;
        }
    }
    QCOMPARE(a.instances.size(), b.instances.size());
    for (size_t i = 0; i < a.instances.size(); ++i) {
        const InstanceDesc &x = a.instances[i], &y = b.instances[i];
        if (x.species != y.species || x.position != y.position || x.rotationDeg != y.rotationDeg || x.scale != y.scale)
            QFAIL(qPrintable(QStringLiteral("instances[%1] differs").arg(i)));
    }
    QCOMPARE(a.ground.enabled, b.ground.enabled);
    QCOMPARE(a.ground.height, b.ground.height);
    QCOMPARE(a.ground.color, b.ground.color);
    QCOMPARE(a.sun.direction, b.sun.direction);
    QCOMPARE(a.sun.temperature, b.sun.temperature);
    QCOMPARE(a.sun.intensity, b.sun.intensity);
    QCOMPARE(a.sun.place.has_value(), b.sun.place.has_value());
    if (a.sun.place) {
        QCOMPARE(a.sun.place->year, b.sun.place->year);
        QCOMPARE(a.sun.place->month, b.sun.place->month);
        QCOMPARE(a.sun.place->day, b.sun.place->day);
        QCOMPARE(a.sun.place->hour, b.sun.place->hour);
        QCOMPARE(a.sun.place->timeZoneHours, b.sun.place->timeZoneHours);
        QCOMPARE(a.sun.place->latitudeDeg, b.sun.place->latitudeDeg);
        QCOMPARE(a.sun.place->longitudeDeg, b.sun.place->longitudeDeg);
    }
    QCOMPARE(a.sky, b.sky);
    QCOMPARE(a.camera.position, b.camera.position);
    QCOMPARE(a.camera.target, b.camera.target);
    QCOMPARE(a.camera.up, b.camera.up);
    QCOMPARE(a.camera.fovY, b.camera.fovY);
    QCOMPARE(a.render.width, b.render.width);
    QCOMPARE(a.render.height, b.render.height);
    QCOMPARE(a.render.spp, b.render.spp);
    QCOMPARE(a.render.mode, b.render.mode);
    QCOMPARE(a.render.accel, b.render.accel);
    QCOMPARE(a.render.shadows, b.render.shadows);
    QCOMPARE(a.render.indirectScale, b.render.indirectScale);
    QCOMPARE(a.render.exposureKey, b.render.exposureKey);
    QCOMPARE(a.render.alphaDistance, b.render.alphaDistance);
    QCOMPARE(a.render.pruneDistance, b.render.pruneDistance);
    QCOMPARE(a.render.view, b.render.view);
    QCOMPARE(a.render.display, b.render.display);
}

// Sets (or, with an undefined value, removes) the value at PATH ("instances", "0", "scale": keys and
// array indices) inside a JSON document.
QJsonValue edited(const QJsonValue& node, const QStringList& path, int depth, const QJsonValue& value)
{
    if (depth == path.size()) return value;
    const QString& step = path[depth];
    if (node.isArray()) {
        QJsonArray a = node.toArray();
        const int i = step.toInt();
        const QJsonValue child = edited(a.at(i), path, depth + 1, value);
        if (child.isUndefined()) a.removeAt(i);
        else a.replace(i, child);
        return a;
    }
    QJsonObject o = node.toObject();
    const QJsonValue child = edited(o.value(step), path, depth + 1, value);
    if (child.isUndefined()) o.remove(step);
    else o.insert(step, child);
    return o;
}

// A small valid scene: a mesh species "oak" (tiny.obj beside the scene), a grown "birch", two instances.
QJsonObject validScene()
{
    const QByteArray text = R"({
        "version": 1,
        "species": [
            {"name": "oak", "mesh": "tiny.obj", "lighting": {"preset": "leaf", "grid": 32}},
            {"name": "birch", "grow": {"species": "birch", "seed": 3, "triangles": 2000}}
        ],
        "instances": [
            {"species": "oak", "position": [0, 0, 0], "rotation": 30, "scale": 1.5},
            {"species": "birch", "position": [5, 0, 2]}
        ],
        "sun": {"direction": [0.3, 1, 0.2]},
        "camera": {"position": [0, 2, -20], "target": [0, 2, 0]},
        "render": {"width": 64, "height": 32}
    })";
    return QJsonDocument::fromJson(text).object();
}

QByteArray compact(const QJsonObject& o) { return QJsonDocument(o).toJson(QJsonDocument::Compact); }

QByteArray with(const QStringList& path, const QJsonValue& value)
{
    return compact(edited(validScene(), path, 0, value).toObject());
}

QByteArray without(const QStringList& path) { return with(path, QJsonValue(QJsonValue::Undefined)); }

// The valid scene's compact text with one piece of text replaced (for what QJsonObject cannot hold).
QByteArray replaced(const char* from, const char* to)
{
    QByteArray text = compact(validScene());
    const qsizetype at = text.indexOf(from);
    if (at < 0) qFatal("replaced(): '%s' is not in the valid scene's text", from);
    return text.replace(at, qsizetype(std::strlen(from)), to);
}

// A scene with every field away from its default; meshes: one beside the scene, one elsewhere.
Scene fullScene(const QString& sceneDir)
{
    Scene s;
    SpeciesDesc oak;
    oak.name = "red \"maple\" \\ \xc3\xa9rable";
    oak.meshPath = std::filesystem::path((sceneDir + "/meshes/tiny.obj").toStdString()).lexically_normal().string();
    oak.leafMaterials = {"leaf", "leaves 2"};
    oak.preset = "dogrose";
    oak.lighting = lb::paramsFromPreset(*lb::findPreset("dogrose"));
    oak.lighting.channels[0] = {0.1f, 0.7f, -0.25f};
    oak.lighting.channels[2].g = 0.123456789f;
    oak.lighting.zeroF0 = false;
    oak.lighting.tolerance = 1e-4;
    oak.lighting.storage = lb::Storage::Fp16;
    oak.grid = 96;
    s.species.push_back(oak);

    SpeciesDesc shared;
    shared.name = "tree one";
    shared.meshPath = sharedTree().toStdString();
    shared.preset = "cloud";
    shared.lighting = lb::paramsFromPreset(*lb::findPreset("cloud"));
    shared.lighting.steps = 300;
    shared.grid = 8;
    s.species.push_back(shared);

    SpeciesDesc birch;
    birch.name = "birch";
    birch.grow = GrowSpec{"birch", (uint64_t(1) << 62) - 3, 123457, 17.25f};
    birch.lighting = lb::paramsFromPreset(*lb::findPreset("leaf"));
    birch.grid = 512;
    s.species.push_back(birch);

    const float awkward[] = {0.1f, 1e-7f, 3.4e38f, -0.0f, 1.0f / 3.0f, 16777217.0f, 2.5e-38f};
    for (int i = 0; i < 40; ++i) {
        InstanceDesc inst;
        inst.species = uint32_t(i % 3);
        inst.position = {1234567.891011 + i * 0.1, -0.3 * i, 1.0 / (i + 3.0)};
        inst.rotationDeg = i % 2 ? glm::vec3(0.0f, awkward[(i + 3) % 7], 0.0f) : glm::vec3(awkward[i % 7], 33.3f, -0.1f * float(i));
        inst.scale = 0.05f + 0.123f * float(i);
        s.instances.push_back(inst);
    }
    s.ground = {false, -1.25, {0.3f, 0.2f, 0.1f}};
    s.sun = {{-0.2f, 0.9f, 0.1f}, 5200.5, 3.25f, {}};
    s.sky = {0.1f, 0.2f, 1.7f};
    s.camera = {{10.5, 3.25, -40.0}, {1.0, 4.0, 2.0}, {0.0f, 1.0f, 0.1f}, 33.3f};
    s.render = {.width = 1920,
                .height = 1080,
                .spp = 64,
                .mode = RenderMode::Lb,
                .accel = AccelKind::KdTree,
                .shadows = false,
                .indirectScale = 0.75f,
                .exposureKey = 0.3f,
                .leafTint = {0.8f, 1.25f, 0.5f},
                .alphaDistance = 87.5f,
                .pruneDistance = 33.25f,
                .view = "ACES 1.0 SDR-video",
                .display = "sRGB"};
    return s;
}

// The rows of the "Fields" table of docs/SCENE.md: | `key` | type | default | rule |, keys under a bold
// section row (**`species[i]`**) written relative to it (`.name`), backticks dropped from defaults.
std::vector<json::FieldDoc> documentedFields(const QString& markdown)
{
    std::vector<json::FieldDoc> rows;
    const QStringList lines = markdown.split(QLatin1Char('\n'));
    qsizetype at = lines.indexOf(QStringLiteral("| key | type | default | rule |"));
    if (at < 0) return rows;
    std::string section;
    for (at += 2; at < lines.size() && lines[at].startsWith(QLatin1String("| ")); ++at) {
        QString line = lines[at].trimmed().mid(1);
        if (line.endsWith(QLatin1Char('|'))) line.chop(1);
        const QStringList cells = line.split(QLatin1Char('|'));   // no cell of the table holds a '|'

        if (cells.size() != 4) {
            rows.push_back({"(malformed row) " + lines[at].toStdString(), "", "", "", false});
            continue;
        }
        json::FieldDoc d;
        QString key = cells[0].trimmed();
        d.section = key.startsWith(QLatin1String("**"));
        key.remove(QLatin1Char('*')).remove(QLatin1Char('`'));
        if (d.section) section = key.toStdString();
        if (key.startsWith(QLatin1Char('.'))) d.key = section + key.toStdString();
        else d.key = key.toStdString();
        if (!d.section && !key.startsWith(QLatin1Char('.'))) section.clear();
        d.type = cells[1].trimmed().toStdString();
        d.defaultValue = QString(cells[2].trimmed()).remove(QLatin1Char('`')).toStdString();
        d.rule = cells[3].trimmed().toStdString();
        rows.push_back(d);
    }
    return rows;
}

} // namespace

class TstSceneFile : public QObject {
    Q_OBJECT

    QTemporaryDir m_dir;

    QString dir() const { return m_dir.path(); }

private Q_SLOTS:
    void initTestCase()
    {
        QVERIFY(m_dir.isValid());
        writeTinyObj(dir() + "/tiny.obj");
        writeTinyObj(dir() + "/meshes/tiny.obj");
        QDir().mkpath(dir() + "/folder.obj");
        QVERIFY2(QFileInfo::exists(sharedTree()), qPrintable(sharedTree()));
    }

    void roundTrip()
    {
        const Scene s = fullScene(dir());
        const std::string text = sceneToJson(s, dir().toStdString());
        // Relative where the mesh lies near the scene, absolute where they share only the root.
        QVERIFY2(text.find("\"mesh\": \"meshes/tiny.obj\"") != std::string::npos, text.c_str());
        // The shared tree lies under the checkout's parent: absolute when that and the temporary folder
        // share only the root (/work/... and /tmp/...), relative when they share more (a clone in /tmp).
        const QString tree = QDir::cleanPath(QFileInfo(sharedTree()).absoluteFilePath()), base = QDir::cleanPath(QFileInfo(dir()).absoluteFilePath());
        const bool onlyRoot = tree.section('/', 1, 1) != base.section('/', 1, 1);
        const QString stored = onlyRoot ? tree : QDir(base).relativeFilePath(tree);
        QVERIFY2(text.find("\"mesh\": \"" + stored.toStdString() + "\"") != std::string::npos, text.c_str());
        const Scene back = parseScene(text, dir().toStdString(), kName);
        compareScenes(s, back);
        if (QTest::currentTestFailed()) return;
        // Writing the read scene gives the same text.
        QCOMPARE(sceneToJson(back, dir().toStdString()), text);
    }

    void roundTripThroughFiles()
    {
        const Scene s = fullScene(dir());
        // A scene in a sibling folder refers to the mesh as ../meshes/tiny.obj.
        const std::string path = (dir() + "/scenes/forest.sylva.json").toStdString();
        writeSceneFile(s, path);
        QFile f(QString::fromStdString(path));
        QVERIFY(f.open(QIODevice::ReadOnly));
        QVERIFY(f.readAll().contains("\"mesh\": \"../meshes/tiny.obj\""));
        compareScenes(s, readSceneFile(path));
        if (QTest::currentTestFailed()) return;
        // Nothing but the scene in its folder: no temporary file left behind.
        QCOMPARE(QDir(dir() + "/scenes").entryList(QDir::Files | QDir::Hidden), QStringList{"forest.sylva.json"});
        // Replacing works; a folder is not replaced.
        writeSceneFile(s, path);
        QVERIFY(errorOf([&] { writeSceneFile(s, (dir() + "/scenes").toStdString()); }).find("is a folder") != std::string::npos);
    }

    void writerRefusesWhatCannotBeRead()
    {
        Scene s = fullScene(dir());
        s.instances[7].position.y = std::numeric_limits<double>::infinity();
        QVERIFY(errorOf([&] { sceneToJson(s, dir().toStdString()); }).find("instances[7].position[1]") != std::string::npos);
        s = fullScene(dir());
        s.instances[2].species = 3;
        QVERIFY(errorOf([&] { sceneToJson(s, dir().toStdString()); }).find("instances[2].species") != std::string::npos);
    }

    void defaults()
    {
        const QByteArray text = R"({"version": 1,
            "species": [{"name": "a", "mesh": "tiny.obj"}, {"name": "b", "grow": {}}],
            "instances": [{"species": "b", "position": [1, 2, 3]}]})";
        const Scene s = parseScene(text.toStdString(), dir().toStdString(), kName);
        const Scene d;   // the defaults of core/scene/scene.h
        QCOMPARE(s.version, 1);
        QCOMPARE(s.species.size(), size_t(2));
        const SpeciesDesc defaultSpecies;
        QCOMPARE(s.species[0].meshPath, (dir() + "/tiny.obj").toStdString());
        QVERIFY(!s.species[0].grow);
        QVERIFY(s.species[0].leafMaterials.empty());
        QCOMPARE(s.species[0].preset, defaultSpecies.preset);
        QCOMPARE(s.species[0].grid, defaultSpecies.grid);
        compareLb(s.species[0].lighting, defaultSpeciesLighting(*lb::findPreset("leaf")));
        QCOMPARE(s.species[0].lighting.tolerance, 0.0);
        QCOMPARE(s.species[0].lighting.stepsPerEdge, kDefaultStepsPerEdge);
        QVERIFY(s.species[1].meshPath.empty());
        QVERIFY(s.species[1].grow);
        const GrowSpec g;
        QCOMPARE(s.species[1].grow->species, g.species);
        QCOMPARE(s.species[1].grow->seed, g.seed);
        QCOMPARE(s.species[1].grow->triangles, g.triangles);
        QCOMPARE(s.species[1].grow->height, g.height);
        QCOMPARE(s.instances.size(), size_t(1));
        QCOMPARE(s.instances[0].species, 1u);
        QCOMPARE(s.instances[0].position, glm::dvec3(1, 2, 3));
        QCOMPARE(s.instances[0].rotationDeg, glm::vec3(0.0f));
        QCOMPARE(s.instances[0].scale, 1.0f);
        Scene expected = d;
        expected.species = s.species;
        expected.instances = s.instances;
        compareScenes(s, expected);   // ground, sun, sky, camera, render: all defaults
    }

    // The default solve is kDefaultStepsPerEdge x the longest edge in fp16; steps_per_edge 2 is the
    // seed's count; a step count > 0 wins; a tolerance asks for tolerance mode instead.
    // A quality preset sets every species' grid, steps and storage and the render's samples and
    // distance knobs, leaving the optics alone.
    void qualityPresetsSetTheScene()
    {
        Scene s = defaultScene();
        const lb::LbParams before = s.species[0].lighting;
        for (const char* name : {"preview", "final", "reference"}) {
            const QualityPreset* q = findQualityPreset(name);
            QVERIFY(q);
            applyQuality(s, *q);
            for (const SpeciesDesc& sp : s.species) {
                QCOMPARE(sp.grid, q->grid);
                QCOMPARE(sp.lighting.steps, 0);
                QCOMPARE(sp.lighting.stepsPerEdge, 1);   // every preset's steps are "half": 1 x the longest edge
                QCOMPARE(sp.lighting.tolerance, 0.0);
                QVERIFY(sp.lighting.storage == (q->fp16 ? lb::Storage::Fp16 : lb::Storage::Fp32));
                QCOMPARE(sp.lighting.channels[1].sigmaS, before.channels[1].sigmaS);
            }
            QCOMPARE(s.render.spp, q->spp);
            QCOMPARE(s.render.bounceSamples, q->bounceSamples);
            QCOMPARE(s.render.alphaDistance, q->alphaDistance);
            QCOMPARE(s.render.pruneDistance, q->pruneDistance);
            QVERIFY(s.render.integrator == q->integrator);
            QCOMPARE(s.lighting.bounces, q->bounces);
            QVERIFY(s.lighting.direct == q->direct && s.lighting.boundary == q->boundary);
        }
        QVERIFY(!findQualityPreset("draft"));
        QCOMPARE(findQualityPreset("preview")->grid, 32);
        // reference is the path tracer; final the LB grid as a radiance cache after two bounces
        QVERIFY(findQualityPreset("reference")->integrator == Integrator::Path);
        QVERIFY(findQualityPreset("final")->integrator == Integrator::Lb && findQualityPreset("final")->bounces == 2);
    }

    void lightingStepsAndTolerance()
    {
        auto lighting = [&](const char* json) {
            const std::string text = std::string(R"({"version": 1, "species": [{"name": "b", "grow": {}, "lighting": )") + json +
                                     R"(}], "instances": [{"species": "b", "position": [0, 0, 0]}]})";
            return parseScene(text, dir().toStdString(), kName).species[0].lighting;
        };
        QCOMPARE(lighting("{}").tolerance, 0.0);
        QCOMPARE(lighting("{}").steps, 0);
        QCOMPARE(lighting("{}").stepsPerEdge, kDefaultStepsPerEdge);
        QVERIFY(lighting("{}").storage == lb::Storage::Fp16);
        QVERIFY(lighting(R"({"fp16": false})").storage == lb::Storage::Fp32);
        QCOMPARE(lb::fixedSteps(lighting("{}"), {40, 64, 30}), 64 * kDefaultStepsPerEdge);
        QCOMPARE(lb::fixedSteps(lighting(R"({"steps_per_edge": 2})"), {40, 64, 30}), lb::defaultSteps({40, 64, 30}));
        QCOMPARE(lb::fixedSteps(lighting(R"({"steps_per_edge": 2, "steps": 7})"), {40, 64, 30}), 7);
        QCOMPARE(lighting(R"({"steps": 0})").tolerance, 0.0);
        QCOMPARE(lighting(R"({"steps": 200})").steps, 200);
        QCOMPARE(lighting(R"({"steps": 200})").tolerance, 0.0);
        QCOMPARE(lighting(R"({"tolerance": 0})").tolerance, 0.0);
        QCOMPARE(lighting(R"({"tolerance": 1e-4})").tolerance, 1e-4);
    }

    void optionalForms()
    {
        // Preset without overrides keeps the preset's f_0; one number sets all channels; rotation as a
        // number turns about +Y; the sun from elevation and azimuth; case-insensitive grower species.
        const QByteArray text = R"({"version": 1,
            "species": [{"name": "c", "mesh": "meshes/../tiny.obj", "leaf_materials": ["Leaf"],
                         "lighting": {"preset": "cloud", "g": 0.5, "sigma_a": [0.01, 0.02, 0.03]}},
                        {"name": "d", "grow": {"species": "Conifer", "height": 0}}],
            "instances": [{"species": "c", "position": [0, 0, 0], "rotation": 45},
                          {"species": "c", "position": [0, 0, 1], "rotation": [1, 2, 3]}],
            "sun": {"elevation": 30, "azimuth": 90, "temperature": 4000, "intensity": 2}})";
        const Scene s = parseScene(text.toStdString(), dir().toStdString() + "/", kName);
        QCOMPARE(s.species[0].meshPath, (dir() + "/tiny.obj").toStdString());
        QCOMPARE(s.species[0].leafMaterials, std::vector<std::string>{"Leaf"});
        QCOMPARE(s.species[0].preset, std::string("cloud"));
        QCOMPARE(s.species[0].lighting.zeroF0, false);
        for (size_t c = 0; c < 3; ++c) {
            QCOMPARE(s.species[0].lighting.channels[c].g, 0.5f);
            QCOMPARE(s.species[0].lighting.channels[c].sigmaS, lb::findPreset("cloud")->channels[c].sigmaS);
        }
        QCOMPARE(s.species[0].lighting.channels[1].sigmaA, 0.02f);
        QCOMPARE(s.species[1].grow->species, std::string("conifer"));
        QCOMPARE(s.instances[0].rotationDeg, glm::vec3(0.0f, 45.0f, 0.0f));
        QCOMPARE(s.instances[1].rotationDeg, glm::vec3(1.0f, 2.0f, 3.0f));
        QCOMPARE(s.sun.direction, sunDirection(30.0, 90.0));
        QVERIFY(std::abs(s.sun.direction.x - std::cos(M_PI / 6)) < 1e-6);
        QCOMPARE(s.sun.temperature, 4000.0);
        QCOMPARE(s.sun.intensity, 2.0f);
    }

    void sunByDateAndPlace()
    {
        // The sun by date, time and place: the direction is NOAA's for that instant (core/sky/sun_position,
        // checked there against NREL SPA and Meeus), the file keeps the place (not the direction) and reads
        // back to the same scene and text.
        QJsonObject o = validScene();
        o.insert("sun", QJsonObject{{"date", "2003-10-17"}, {"time", "12:30:30"}, {"timezone", -7}, {"latitude", 39.742476},
                                    {"longitude", -105.1786}, {"temperature", 5800}});
        const Scene s = parseScene(compact(o).toStdString(), dir().toStdString(), kName);
        QVERIFY(s.sun.place.has_value());
        QCOMPARE(s.sun.place->hour, 12.0 + 30.5 / 60.0);
        const sky::SunPosition pos = sky::noaaSunPosition(*s.sun.place);
        QCOMPARE(s.sun.direction, pos.direction);
        // NREL SPA's example (Reda & Andreas 2004, Table A4-1): elevation 90 - 50.11162, bearing 194.34024.
        const double elevation = std::asin(double(s.sun.direction.y)) * 180.0 / M_PI;
        const double bearing = 180.0 - std::atan2(double(s.sun.direction.x), double(s.sun.direction.z)) * 180.0 / M_PI;
        QVERIFY2(std::abs(elevation - (90.0 - 50.11162)) < 0.02, qPrintable(QString::number(elevation)));
        QVERIFY2(std::abs(bearing - 194.34024) < 0.02, qPrintable(QString::number(bearing)));
        QCOMPARE(s.sun.temperature, 5800.0);
        const std::string text = sceneToJson(s, dir().toStdString());
        QVERIFY(text.find("\"date\": \"2003-10-17\"") != std::string::npos);
        QVERIFY(text.find("\"time\": \"12:30:30\"") != std::string::npos);
        const size_t sunAt = text.find("\"sun\"");
        QVERIFY(sunAt != std::string::npos && text.find("\"direction\"", sunAt) > text.find('}', sunAt));   // no direction in sun
        const Scene back = parseScene(text, dir().toStdString(), kName);
        compareScenes(back, s);
        QCOMPARE(sceneToJson(back, dir().toStdString()), text);
        // Another hour moves the sun: the morning sun stands east (+X) of the afternoon one.
        o.insert("sun", QJsonObject{{"date", "2003-10-17"}, {"time", "08:00"}, {"timezone", -7}, {"latitude", 39.74}, {"longitude", -105.18}});
        const Scene morning = parseScene(compact(o).toStdString(), dir().toStdString(), kName);
        QVERIFY(morning.sun.direction.x > 0.5f && s.sun.direction.x < 0.0f);
        QVERIFY(describeScene(morning).find("on 2003-10-17 at 08:00 UTC-7") != std::string::npos);
    }

    void malformed_data()
    {
        QTest::addColumn<QByteArray>("json");
        QTest::addColumn<QString>("expected");
        const QString tiny = dir();
        QTest::newRow("syntax") << QByteArray("{\n  \"version\": 1,\n  \"species\": [\n    {\"name\": \"a\",, }\n") << "line 4, column";
        QTest::newRow("syntax in path") << replaced("[5,0,2]", "[5,0,,2]") << "instances[1].position[2]: malformed JSON at line 1";
        QTest::newRow("empty") << QByteArray("") << "malformed JSON at line 1, column 1";
        QTest::newRow("not an object") << QByteArray("[1, 2]") << "must be a JSON object";
        QTest::newRow("missing mesh") << with({"species", "0", "mesh"}, "nope/none.obj")
                                      << "species[0].mesh: no such file: " + tiny + "/nope/none.obj";
        QTest::newRow("mesh is folder") << with({"species", "0", "mesh"}, "folder.obj") << "species[0].mesh: is a folder";
        QTest::newRow("empty mesh") << with({"species", "0", "mesh"}, "") << "species[0].mesh: must not be empty";
        QTest::newRow("negative scale") << with({"instances", "0", "scale"}, -1) << "instances[0].scale: must be > 0, got -1";
        QTest::newRow("zero scale") << with({"instances", "0", "scale"}, 0) << "instances[0].scale: must be > 0, got 0";
        QTest::newRow("float overflow") << with({"instances", "0", "scale"}, 1e300) << "instances[0].scale: 1e+300 is out of range";
        QTest::newRow("inf position") << replaced("[5,0,2]", "[1e999,0,2]") << "instances[1].position[0]: '1e999' is not a finite number";
        QTest::newRow("-inf position") << replaced("[5,0,2]", "[5,0,-1e400]") << "instances[1].position[2]: '-1e400' is not a finite";
        QTest::newRow("inf camera") << replaced("\"target\":[0,2,0]", "\"target\":[0,1e999,0]") << "camera.target[1]: '1e999'";
        QTest::newRow("NaN literal") << replaced("\"scale\":1.5", "\"scale\":NaN") << "instances[0].scale: 'NaN' is not a finite";
        QTest::newRow("unknown top") << with({"colour"}, 1) << "scene.json: colour: unknown field (known here: version, species";
        QTest::newRow("unknown nested") << with({"species", "0", "lighting", "sigma"}, 0.1) << "species[0].lighting.sigma: unknown field";
        QTest::newRow("unknown in instance") << with({"instances", "1", "rot"}, 0) << "instances[1].rot: unknown field";
        QTest::newRow("unknown in grow") << with({"species", "1", "grow", "leaves"}, 0) << "species[1].grow.leaves: unknown field";
        QTest::newRow("duplicate key") << replaced("\"scale\":1.5", "\"scale\":1.5,\"scale\":2") << "instances[0].scale: duplicate key";
        // Without species the instances name none that exists (a scene with neither: tst_bare_scene).
        QTest::newRow("zero species") << with({"species"}, QJsonArray()) << "instances[0].species: unknown species 'oak' (the scene declares no species)";
        QTest::newRow("no species") << without({"species"}) << "instances[0].species: unknown species 'oak'";
        QTest::newRow("species not array") << with({"species"}, QJsonObject()) << "species: expected an array, got an object";
        QTest::newRow("unknown species") << with({"instances", "1", "species"}, "elm")
                                         << "instances[1].species: unknown species 'elm' (declared: 'oak', 'birch')";
        QTest::newRow("instance without species") << without({"instances", "1", "species"}) << "instances[1].species: missing";
        QTest::newRow("instance without position") << without({"instances", "1", "position"}) << "instances[1].position: missing";
        QTest::newRow("instance not object") << with({"instances", "0"}, 5) << "instances[0]: expected an object, got a number";
        QTest::newRow("duplicate species") << with({"species", "1", "name"}, "oak")
                                           << "species[1].name: duplicate species name 'oak' (also species[0])";
        QTest::newRow("empty name") << with({"species", "0", "name"}, "") << "species[0].name: must not be empty";
        QTest::newRow("no name") << without({"species", "0", "name"}) << "species[0].name: missing";
        QTest::newRow("mesh and grow") << with({"species", "0", "grow"}, QJsonObject()) << "species[0]: has both \"mesh\" and \"grow\"";
        QTest::newRow("neither") << without({"species", "0", "mesh"}) << "species[0]: needs \"mesh\"";
        QTest::newRow("bad mode") << with({"render", "mode"}, "fast") << "render.mode: unknown mode 'fast' (known: full, local, ambient, lb)";
        QTest::newRow("bad accel") << with({"render", "accel"}, "octree") << "render.accel: unknown acceleration structure 'octree'";
        QTest::newRow("sun both") << with({"sun", "elevation"}, 30) << "sun: give either \"direction\" or";
        QTest::newRow("sun zero") << with({"sun", "direction"}, QJsonArray{0, 0, 0}) << "sun.direction: must be a non-zero vector";
        QTest::newRow("sun elevation alone") << with({"sun"}, QJsonObject{{"elevation", 30}}) << "sun.azimuth: missing";
        QTest::newRow("sun elevation range") << with({"sun"}, QJsonObject{{"elevation", 95}, {"azimuth", 0}})
                                             << "sun.elevation: must lie in [-90, 90]";
        QTest::newRow("sun temperature") << with({"sun", "temperature"}, 500) << "sun.temperature: must lie in [1000, 40000] kelvin, got 500";
        QTest::newRow("sun intensity") << with({"sun", "intensity"}, -1) << "sun.intensity: must be >= 0";
        const QJsonObject place{{"date", "2024-06-21"}, {"time", "08:30"}, {"timezone", 2}, {"latitude", 48.1}, {"longitude", 11.6}};
        auto placeWith = [&](const char* key, const QJsonValue& v) {
            QJsonObject p = place;
            if (v.isUndefined()) p.remove(key);
            else p.insert(key, v);
            return with({"sun"}, p);
        };
        QTest::newRow("sun place and direction") << placeWith("direction", QJsonArray{0, 1, 0}) << "sun: give one of \"direction\"";
        QTest::newRow("sun place missing") << placeWith("longitude", QJsonValue::Undefined) << "sun.longitude: missing";
        QTest::newRow("sun date form") << placeWith("date", "21.06.2024") << "sun.date: expected a date \"YYYY-MM-DD\"";
        QTest::newRow("sun date exists") << placeWith("date", "2023-02-29") << "sun: sun position: day must be in 1 .. 28";
        QTest::newRow("sun time form") << placeWith("time", "8h30") << "sun.time: expected a local clock time";
        QTest::newRow("sun latitude") << placeWith("latitude", 91) << "sun.latitude: must lie in [-90, 90], got 91";
        QTest::newRow("sun timezone") << placeWith("timezone", 15) << "sun.timezone: must lie in [-14, 14]";
        QTest::newRow("version 2") << with({"version"}, 2) << "version: unsupported version 2";
        QTest::newRow("version missing") << without({"version"}) << "version: missing";
        QTest::newRow("version string") << with({"version"}, "1") << "version: expected a number, got a string";
        QTest::newRow("sigma_t > 1") << with({"species", "0", "lighting", "sigma_a"}, 0.5)
                                     << "species[0].lighting: invalid LB parameter for channel R: sigma_t";
        QTest::newRow("negative sigma_s") << with({"species", "0", "lighting", "sigma_s"}, QJsonArray{0.5, -0.1, 0.5})
                                          << "species[0].lighting: invalid LB parameter for channel G: sigma_s";
        QTest::newRow("g > 1") << with({"species", "0", "lighting", "g"}, QJsonArray{0, 0, 1.5})
                               << "species[0].lighting: invalid LB parameter for channel B: g";
        QTest::newRow("sigma wrong length") << with({"species", "0", "lighting", "g"}, QJsonArray{0, 0})
                                            << "species[0].lighting.g: expected three numbers, got 2";
        QTest::newRow("sigma string") << with({"species", "0", "lighting", "sigma_a"}, "low")
                                      << "species[0].lighting.sigma_a: expected a number or [r, g, b], got a string";
        QTest::newRow("unknown preset") << with({"species", "0", "lighting", "preset"}, "glass")
                                        << "species[0].lighting.preset: unknown preset 'glass' (known: leaf, dogrose, cloud, pmma)";
        QTest::newRow("grid small") << with({"species", "0", "lighting", "grid"}, 4) << "species[0].lighting.grid: must lie in [8, 512], got 4";
        QTest::newRow("steps per edge 0") << with({"species", "0", "lighting", "steps_per_edge"}, 0)
                                          << "species[0].lighting.steps_per_edge: must lie in [1, 64], got 0";
        QTest::newRow("grid fraction") << with({"species", "0", "lighting", "grid"}, 32.5)
                                       << "species[0].lighting.grid: must be a whole number, got 32.5";
        QTest::newRow("steps and tolerance") << compact(edited(edited(validScene(), {"species", "0", "lighting", "steps"}, 0, 100).toObject(),
                                                               {"species", "0", "lighting", "tolerance"}, 0, 1e-3)
                                                            .toObject())
                                             << "species[0].lighting: \"steps\" and \"tolerance\" exclude each other";
        QTest::newRow("negative tolerance") << with({"species", "0", "lighting", "tolerance"}, -1) << "species[0].lighting.tolerance: must be >= 0";
        QTest::newRow("fp16 not bool") << with({"species", "0", "lighting", "fp16"}, 1) << "species[0].lighting.fp16: expected true or false";
        QTest::newRow("lighting not object") << with({"species", "0", "lighting"}, "leaf") << "species[0].lighting: expected an object";
        QTest::newRow("leaf materials") << with({"species", "0", "leaf_materials"}, "leaf") << "species[0].leaf_materials: expected an array";
        QTest::newRow("leaf material type") << with({"species", "0", "leaf_materials"}, QJsonArray{"leaf", 3})
                                            << "species[0].leaf_materials[1]: expected a string, got a number";
        QTest::newRow("grow triangles") << with({"species", "1", "grow", "triangles"}, 10)
                                        << "species[1].grow.triangles: must lie in [1000, 1000000], got 10";
        QTest::newRow("grow species") << with({"species", "1", "grow", "species"}, "palm")
                                      << "species[1].grow.species: unknown grower species 'palm' (known: broadleaf, birch, conifer, shrub)";
        QTest::newRow("grow height") << with({"species", "1", "grow", "height"}, 500) << "species[1].grow.height: must be 0";
        QTest::newRow("grow seed") << with({"species", "1", "grow", "seed"}, -1) << "species[1].grow.seed: must lie in [0, ";
        QTest::newRow("scale string") << with({"instances", "0", "scale"}, "big") << "instances[0].scale: expected a number, got a string";
        QTest::newRow("position short") << with({"instances", "0", "position"}, QJsonArray{1, 2})
                                        << "instances[0].position: expected three numbers, got 2";
        QTest::newRow("position element") << with({"instances", "0", "position"}, QJsonArray{1, "2", 3})
                                          << "instances[0].position[1]: expected a number, got a string";
        QTest::newRow("position null") << with({"instances", "0", "position"}, QJsonValue()) << "instances[0].position: expected an array";
        QTest::newRow("rotation type") << with({"instances", "0", "rotation"}, "north")
                                       << "instances[0].rotation: expected [rx, ry, rz] or a number";
        QTest::newRow("width 0") << with({"render", "width"}, 0) << "render.width: must lie in [1, 32768], got 0";
        QTest::newRow("height big") << with({"render", "height"}, 40000) << "render.height: must lie in [1, 32768], got 40000";
        QTest::newRow("width fraction") << with({"render", "width"}, 1.5) << "render.width: must be a whole number";
        QTest::newRow("spp") << with({"render", "spp"}, 5000) << "render.spp: must lie in [1, 4096]";
        QTest::newRow("shadows type") << with({"render", "shadows"}, "yes") << "render.shadows: expected true or false, got a string";
        QTest::newRow("key zero") << with({"render", "key"}, 0) << "render.key: must be > 0";
        QTest::newRow("indirect negative") << with({"render", "indirect"}, -0.5) << "render.indirect: must be >= 0";
        QTest::newRow("alpha distance negative") << with({"render", "alpha_distance"}, -1) << "render.alpha_distance: must be >= 0";
        QTest::newRow("prune distance type") << with({"render", "prune_distance"}, "far") << "render.prune_distance: expected a number";
        QTest::newRow("prune distance huge") << with({"render", "prune_distance"}, 1e300) << "render.prune_distance:";
        QTest::newRow("fov 180") << with({"camera", "fov"}, 180) << "camera.fov: must lie in (0, 180) degrees, got 180";
        QTest::newRow("fov 0") << with({"camera", "fov"}, 0) << "camera.fov: must lie in (0, 180)";
        QTest::newRow("camera same point") << with({"camera", "target"}, QJsonArray{0, 2, -20}) << "camera.target: must differ from camera.position";
        QTest::newRow("camera up parallel") << with({"camera", "up"}, QJsonArray{0, 0, 3}) << "camera.up: (0, 0, 3) is parallel to the view";
        QTest::newRow("camera up zero") << with({"camera", "up"}, QJsonArray{0, 0, 0}) << "camera.up: must be a non-zero vector";
        QTest::newRow("ground color") << with({"ground", "color"}, QJsonArray{1.5, 0, 0}) << "ground.color[0]: must lie in [0, 1], got 1.5";
        QTest::newRow("ground enabled") << with({"ground", "enabled"}, 1) << "ground.enabled: expected true or false";
        QTest::newRow("sky negative") << with({"sky", "color"}, QJsonArray{0.5, -1, 0}) << "sky.color[1]: must lie in [0, inf]";
        QTest::newRow("sky unknown") << with({"sky", "colour"}, QJsonArray{0.5, 1, 0}) << "sky.colour: unknown field";
        QTest::newRow("forest grid resolution 2") << with({"lighting", "forest_grid_resolution"}, 2)
                                                  << "lighting.forest_grid_resolution: expected 0 (automatic) or 4 .. 512, got 2";
        QTest::newRow("forest grid resolution big") << with({"lighting", "forest_grid_resolution"}, 513)
                                                    << "lighting.forest_grid_resolution: must lie in [0, 512], got 513";
    }

    void malformed()
    {
        QFETCH(QByteArray, json);
        QFETCH(QString, expected);
        const std::string message = errorOf([&] { parseScene(json.toStdString(), dir().toStdString(), kName); });
        QVERIFY2(message.rfind(std::string(kName) + ": ", 0) == 0, message.c_str());
        QVERIFY2(message.find(expected.toStdString()) != std::string::npos,
                 qPrintable(QString::fromStdString(message) + "\n  expected to contain: " + expected));
    }

    void validBaseParses()
    {
        // The base of the malformed table is itself valid, so each row tests exactly one fault.
        const Scene s = parseScene(compact(validScene()).toStdString(), dir().toStdString(), kName);
        QCOMPARE(s.species.size(), size_t(2));
        QCOMPARE(s.instances[1].species, 1u);
        QCOMPARE(s.instances[0].rotationDeg.y, 30.0f);
    }

    void fileErrors()
    {
        const std::string missing = (dir() + "/none.sylva.json").toStdString();
        QCOMPARE(errorOf([&] { readSceneFile(missing); }), missing + ": no such scene file");
        QVERIFY(errorOf([&] { readSceneFile(dir().toStdString()); }).find("is a folder") != std::string::npos);
        // Relative mesh paths start at the scene file's folder, not the current folder.
        const QString path = dir() + "/sub/bad.sylva.json";
        writeText(path, with({"species", "0", "mesh"}, "tiny.obj"));
        const std::string message = errorOf([&] { readSceneFile(path.toStdString()); });
        QCOMPARE(message, path.toStdString() + ": species[0].mesh: no such file: " + (dir() + "/sub/tiny.obj").toStdString());
        writeText(path, with({"species", "0", "mesh"}, "../tiny.obj"));
        QCOMPARE(readSceneFile(path.toStdString()).species[0].meshPath, (dir() + "/tiny.obj").toStdString());
    }

    void manyInstances()
    {
        // Species names are looked up by hash: a large forest parses in linear time.
        const int n = 200000;
        std::string text = "{\"version\": 1, \"species\": [{\"name\": \"oak\", \"mesh\": \"tiny.obj\"}, "
                           "{\"name\": \"birch\", \"grow\": {}}], \"instances\": [";
        for (int i = 0; i < n; ++i) {
            text += i ? ",\n" : "\n";
            text += "{\"species\": \"" + std::string(i % 3 ? "oak" : "birch") + "\", \"position\": [" + std::to_string(i) +
                    ", 0, 1.5], \"rotation\": 12.5, \"scale\": 1.1}";
        }
        text += "]}";
        QElapsedTimer timer;
        timer.start();
        const Scene s = parseScene(text, dir().toStdString(), kName);
        const qint64 parseMs = timer.elapsed();
        QCOMPARE(s.instances.size(), size_t(n));
        for (int i = 0; i < n; ++i)
            if (s.instances[size_t(i)].species != (i % 3 ? 0u : 1u) || s.instances[size_t(i)].position.x != double(i))
                QFAIL(qPrintable(QStringLiteral("instances[%1] read wrongly").arg(i)));
        timer.restart();
        const std::string written = sceneToJson(s, dir().toStdString());
        const qint64 writeMs = timer.elapsed();
        qInfo("%d instances: parse %lld ms, write %lld ms (%zu bytes)", n, parseMs, writeMs, written.size());
        // The last instance's error still names it.
        const size_t last = text.rfind("\"oak\"");
        text.replace(last, 5, "\"elm\"");
        QVERIFY(errorOf([&] { parseScene(text, dir().toStdString(), kName); }).find("instances[" + std::to_string(n - 1) + "].species") !=
                std::string::npos);
    }

    void describe()
    {
        const Scene s = fullScene(dir());
        const std::string d = describeScene(s);
        qInfo("%s", d.c_str());
        for (const char* part : {"3 species, 40 instances", "mesh ", "tiny.obj", "grown birch (seed", "123457 triangles", "LB dogrose modified",
                                 "grid 96", "tolerance 0.0001", "fp16", "300 steps", "ground: none", "sun: toward", "5200 K", "camera: at",
                                 "render: 1920x1080, 64 spp, mode lb, kdtree, shadows off"})
            QVERIFY2(d.find(part) != std::string::npos, part);
    }
    // docs/SCENE.md's field table is the scene field table: every key with its type, default and rule,
    // in the same order, and no key the table lacks.
    void sceneDocMatchesFieldTable()
    {
        QFile doc(QStringLiteral(SYLVA_SOURCE_DIR "/docs/SCENE.md"));
        QVERIFY2(doc.open(QIODevice::ReadOnly), qPrintable(doc.fileName()));
        const std::vector<json::FieldDoc> documented = documentedFields(QString::fromUtf8(doc.readAll()));
        const std::vector<json::FieldDoc> declared = sceneFieldDocs();
        QVERIFY(declared.size() > 40);
        auto find = [](const std::vector<json::FieldDoc>& rows, const std::string& key) {
            json::FieldDoc none;
            none.key = "(no such key)";
            for (const auto& r : rows)
                if (r.key == key) return r;
            return none;
        };
        for (const json::FieldDoc& d : declared) {
            const json::FieldDoc row = find(documented, d.key);
            QVERIFY2(row.key == d.key, qPrintable(QString::fromStdString("docs/SCENE.md does not document " + d.key)));
            QVERIFY2(row.defaultValue == d.defaultValue,
                     qPrintable(QString::fromStdString(d.key + ": SCENE.md says default '" + row.defaultValue + "', the table '" + d.defaultValue + "'")));
            QVERIFY2(row.type == d.type, qPrintable(QString::fromStdString(d.key + ": SCENE.md says type '" + row.type + "', the table '" + d.type + "'")));
            QVERIFY2(row.rule == d.rule, qPrintable(QString::fromStdString(d.key + ": SCENE.md says rule\n  '" + row.rule + "', the table\n  '" + d.rule + "'")));
            QVERIFY2(row.section == d.section, qPrintable(QString::fromStdString(d.key + ": a section row in one and not the other")));
        }
        for (const json::FieldDoc& row : documented)
            QVERIFY2(find(declared, row.key).key == row.key,
                     qPrintable(QString::fromStdString("docs/SCENE.md documents " + row.key + ", which the field table lacks")));
        QCOMPARE(documented.size(), declared.size());
        for (size_t i = 0; i < declared.size(); ++i)
            QVERIFY2(documented[i].key == declared[i].key,
                     qPrintable(QString::fromStdString("row " + std::to_string(i) + ": SCENE.md has " + documented[i].key + ", the table " + declared[i].key)));
        // The documented defaults are what a scene without those keys reads as.
        const Scene s = parseScene(R"({"version": 1, "species": [{"name": "b", "grow": {}}], "instances": [{"species": "b", "position": [0, 0, 0]}]})",
                                   dir().toStdString(), kName);
        QCOMPARE(find(declared, "render.width").defaultValue, std::to_string(s.render.width));
        QCOMPARE(find(declared, "species[i].lighting.grid").defaultValue, std::to_string(s.species[0].grid));
        QCOMPARE(find(declared, "species[i].lighting.steps_per_edge").defaultValue, std::to_string(s.species[0].lighting.stepsPerEdge));
        QCOMPARE(find(declared, "species[i].grow.seed").defaultValue, std::to_string(GrowSpec{}.seed));
        QCOMPARE(QString::fromStdString(find(declared, "render.mode").defaultValue), QStringLiteral("\"%1\"").arg(renderModeName(s.render.mode)));
    }
};

QTEST_GUILESS_MAIN(TstSceneFile)
#include "tst_scene_file.moc"
