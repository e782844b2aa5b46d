// Scene files: QJsonDocument parses, a strict walk checks and names key paths, a hand-made writer keeps numbers exact.
#include "pipeline/scene/scene_file.h"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <string_view>
#include <unordered_set>
#include <utility>
#include <vector>

#include <QByteArray>
#include <QDir>
#include <QFile>
#include <QFileInfo>
#include <QHash>
#include <QJsonArray>
#include <QJsonDocument>
#include <QJsonObject>
#include <QJsonParseError>
#include <QSaveFile>
#include <QString>

#include "core/base/error.h"
#include "pipeline/grow/tree_grower.h"
#include "pipeline/io/output_path.h"

namespace sylva {

namespace fs = std::filesystem;

namespace {

// Limits of the format (docs/SCENE.md).
constexpr int kMinImageSize = 1, kMaxImageSize = 32768;
constexpr int kMinSpp = 1, kMaxSpp = 4096;
constexpr int kMinGrid = 8, kMaxGrid = 512;
constexpr int kMaxSteps = 1000000;
constexpr double kMinTemperature = 1000.0, kMaxTemperature = 40000.0;
constexpr long long kMaxSeed = 1LL << 62;
constexpr float kMinGrowHeight = 0.1f, kMaxGrowHeight = 150.0f;

// A JSON key path built on the stack while walking ("instances[3].scale"); text only for messages.
struct KeyPath {
    const KeyPath* parent = nullptr;
    const char* key = nullptr;   // member name; nullptr for an array element (or the root)
    qsizetype index = -1;        // array element index

    KeyPath field(const char* k) const { return KeyPath{this, k, -1}; }
    KeyPath at(qsizetype i) const { return KeyPath{this, nullptr, i}; }
    std::string text() const
    {
        std::string s = parent ? parent->text() : std::string();
        if (key) {
            if (!s.empty()) s += '.';
            s += key;
        } else if (index >= 0) {
            s += '[' + std::to_string(index) + ']';
        }
        return s;
    }
};

std::string joinPath(const std::string& path, const std::string& key) { return path.empty() ? key : path + "." + key; }

// Walks JSON text token by token, keeping the key path; QJsonDocument does the real parse. Names the
// key path at a syntax error's offset, and finds repeated keys (QJsonObject silently keeps the last).
class JsonScanner {
public:
    explicit JsonScanner(std::string_view text) : m_text(text) {}

    // Scans [0, end). With findDuplicates, stops at the first repeated key of an object and returns
    // false; path() then names that key.
    bool scan(size_t end, bool findDuplicates)
    {
        end = std::min(end, m_text.size());
        size_t i = 0;
        while (i < end) {
            const char c = m_text[i];
            if (c == '{' || c == '[') {
                push(c == '{');
                ++i;
            } else if (c == '}' || c == ']') {
                if (m_depth > 0) --m_depth;
                ++i;
            } else if (c == ',') {
                if (m_depth > 0) {
                    Frame& f = m_stack[m_depth - 1];
                    if (f.object) {
                        f.expectKey = true;
                        f.key = {};
                    } else {
                        ++f.index;
                    }
                }
                ++i;
            } else if (c == '"') {
                size_t j = i + 1;
                while (j < m_text.size() && m_text[j] != '"') j += m_text[j] == '\\' ? 2 : 1;
                j = std::min(j, m_text.size());
                if (m_depth > 0 && m_stack[m_depth - 1].object && m_stack[m_depth - 1].expectKey) {
                    Frame& f = m_stack[m_depth - 1];
                    f.key = m_text.substr(i + 1, j - i - 1);
                    f.expectKey = false;
                    if (findDuplicates && j < end && !f.addKey(f.key)) return false;
                }
                i = j + 1;
            } else {
                ++i;
            }
        }
        return true;
    }

    std::string path() const
    {
        std::string s;
        for (size_t d = 0; d < m_depth; ++d) {
            const Frame& f = m_stack[d];
            if (f.object) {
                if (f.expectKey) break;
                if (!s.empty()) s += '.';
                s += f.key;
            } else {
                s += '[' + std::to_string(f.index) + ']';
            }
        }
        return s;
    }

private:
    struct Frame {
        bool object = false;
        bool expectKey = false;
        size_t index = 0;
        std::string_view key;
        std::vector<std::string_view> keys;        // the keys seen, while few
        std::unordered_set<std::string_view> many;  // the keys seen, once many (no quadratic checks)

        bool addKey(std::string_view k)
        {
            if (many.empty() && keys.size() < 16) {
                if (std::find(keys.begin(), keys.end(), k) != keys.end()) return false;
                keys.push_back(k);
                return true;
            }
            if (many.empty()) many.insert(keys.begin(), keys.end());
            return many.insert(k).second;
        }
    };

    void push(bool object)
    {
        if (m_depth == m_stack.size()) m_stack.emplace_back();
        Frame& f = m_stack[m_depth++];
        f.object = object;
        f.expectKey = object;
        f.index = 0;
        f.key = {};
        f.keys.clear();
        f.many.clear();
    }

    std::string_view m_text;
    std::vector<Frame> m_stack;   // frames are reused, so a million small objects allocate nothing
    size_t m_depth = 0;
};

std::string lineColumn(std::string_view text, size_t offset)
{
    offset = std::min(offset, text.size());
    size_t line = 1, lineStart = 0;
    for (size_t i = 0; i < offset; ++i)
        if (text[i] == '\n') {
            ++line;
            lineStart = i + 1;
        }
    return "line " + std::to_string(line) + ", column " + std::to_string(offset - lineStart + 1);
}

const char* typeName(const QJsonValue& v)
{
    switch (v.type()) {
    case QJsonValue::Null: return "null";
    case QJsonValue::Bool: return "true/false";
    case QJsonValue::Double: return "a number";
    case QJsonValue::String: return "a string";
    case QJsonValue::Array: return "an array";
    case QJsonValue::Object: return "an object";
    case QJsonValue::Undefined: return "nothing";
    }
    return "something else";
}

// Shortest text that reads back as the same value (0.1f prints as 0.1, not 0.100000001).
template <class T>
std::string fmt(T v)
{
    char buf[64];
    const auto r = std::to_chars(buf, buf + sizeof buf, v);
    return std::string(buf, r.ptr);
}

template <class V>
std::string fmt3(const V& v)
{
    return "(" + fmt(v.x) + ", " + fmt(v.y) + ", " + fmt(v.z) + ")";
}

std::string quoted(const QString& s) { return "'" + s.toStdString() + "'"; }

template <class Names>
std::string nameList(const Names& names)
{
    std::string s;
    for (const auto& n : names) s += (s.empty() ? "" : ", ") + std::string(n);
    return s;
}

// The strict walk over a parsed document. Every failure throws Error "NAME: KEY.PATH: problem".
class SceneReader {
public:
    SceneReader(std::string name, fs::path baseDir) : m_name(std::move(name)), m_base(std::move(baseDir)) {}

    Scene read(const QJsonObject& root)
    {
        const KeyPath top;
        checkKeys(root, top, {"version", "species", "instances", "ground", "sun", "sky", "camera", "render"});
        Scene scene;
        const QJsonValue version = root.value(QLatin1String("version"));
        if (version.isUndefined()) fail(top.field("version"), "missing (required; this build reads version 1)");
        const double v = number(version, top.field("version"));
        if (v != double(kSceneFileVersion))
            fail(top.field("version"), "unsupported version " + fmt(v) + " (this build reads version " +
                                           std::to_string(kSceneFileVersion) + ")");
        scene.version = kSceneFileVersion;
        readSpecies(root, top, scene);
        readInstances(root, top, scene);
        readGround(root.value(QLatin1String("ground")), top.field("ground"), scene.ground);
        readSun(root.value(QLatin1String("sun")), top.field("sun"), scene.sun);
        readSky(root.value(QLatin1String("sky")), top.field("sky"), scene);
        readCamera(root.value(QLatin1String("camera")), top.field("camera"), scene.camera);
        readRender(root.value(QLatin1String("render")), top.field("render"), scene.render);
        return scene;
    }

private:
    [[noreturn]] void failText(const std::string& path, const std::string& problem) const
    {
        throw Error(m_name + ": " + (path.empty() ? "" : path + ": ") + problem);
    }
    [[noreturn]] void fail(const KeyPath& path, const std::string& problem) const { failText(path.text(), problem); }
    [[noreturn]] void wrongType(const QJsonValue& v, const KeyPath& path, const char* expected) const
    {
        fail(path, std::string("expected ") + expected + ", got " + typeName(v));
    }

    // Unknown keys are errors naming the key and the known ones.
    void checkKeys(const QJsonObject& o, const KeyPath& path, std::initializer_list<const char*> known) const
    {
        qsizetype found = 0;
        for (const char* k : known) found += o.contains(QLatin1String(k));
        if (found == o.size()) return;
        for (auto it = o.begin(); it != o.end(); ++it) {
            const QString key = it.key();
            bool ok = false;
            for (const char* k : known) ok = ok || key == QLatin1String(k);
            if (!ok) failText(joinPath(path.text(), key.toStdString()), "unknown field (known here: " + nameList(known) + ")");
        }
    }

    QJsonObject object(const QJsonValue& v, const KeyPath& path) const
    {
        if (!v.isObject()) wrongType(v, path, "an object");
        return v.toObject();
    }
    // An optional object: empty when absent.
    QJsonObject optionalObject(const QJsonValue& v, const KeyPath& path) const
    {
        return v.isUndefined() ? QJsonObject() : object(v, path);
    }
    QJsonArray requiredArray(const QJsonObject& o, const KeyPath& path, const char* key) const
    {
        const QJsonValue v = o.value(QLatin1String(key));
        if (v.isUndefined()) fail(path.field(key), "missing (required)");
        if (!v.isArray()) wrongType(v, path.field(key), "an array");
        return v.toArray();
    }

    double number(const QJsonValue& v, const KeyPath& path) const
    {
        if (!v.isDouble()) wrongType(v, path, "a number");
        const double d = v.toDouble();
        if (!std::isfinite(d)) fail(path, "must be a finite number");
        return d;
    }
    float toFloat(double d, const KeyPath& path) const
    {
        if (std::fabs(d) > double(std::numeric_limits<float>::max())) fail(path, fmt(d) + " is out of range");
        return float(d);
    }
    float floatNumber(const QJsonValue& v, const KeyPath& path) const { return toFloat(number(v, path), path); }
    long long integer(const QJsonValue& v, const KeyPath& path, long long lo, long long hi) const
    {
        const double d = number(v, path);
        if (d != std::floor(d)) fail(path, "must be a whole number, got " + fmt(d));
        const std::string range = "[" + std::to_string(lo) + ", " + std::to_string(hi) + "]";
        if (d < double(lo) || d > double(hi)) fail(path, "must lie in " + range + ", got " + fmt(d));
        const long long n = v.toInteger(lo - 1);
        if (n < lo || n > hi) fail(path, "must lie in " + range + ", got " + fmt(d));
        return n;
    }
    bool boolean(const QJsonValue& v, const KeyPath& path) const
    {
        if (!v.isBool()) wrongType(v, path, "true or false");
        return v.toBool();
    }
    QString string(const QJsonValue& v, const KeyPath& path) const
    {
        if (!v.isString()) wrongType(v, path, "a string");
        return v.toString();
    }
    QJsonArray triple(const QJsonValue& v, const KeyPath& path) const
    {
        if (!v.isArray()) wrongType(v, path, "an array of three numbers");
        const QJsonArray a = v.toArray();
        if (a.size() != 3) fail(path, "expected three numbers, got " + std::to_string(a.size()));
        return a;
    }
    glm::dvec3 dvec3(const QJsonValue& v, const KeyPath& path) const
    {
        const QJsonArray a = triple(v, path);
        return {number(a.at(0), path.at(0)), number(a.at(1), path.at(1)), number(a.at(2), path.at(2))};
    }
    glm::vec3 vec3(const QJsonValue& v, const KeyPath& path) const
    {
        const QJsonArray a = triple(v, path);
        return {floatNumber(a.at(0), path.at(0)), floatNumber(a.at(1), path.at(1)), floatNumber(a.at(2), path.at(2))};
    }
    // RGB with every channel in [lo, hi].
    glm::vec3 color(const QJsonValue& v, const KeyPath& path, float lo, float hi) const
    {
        const QJsonArray a = triple(v, path);
        glm::vec3 c;
        for (int i = 0; i < 3; ++i) {
            c[i] = floatNumber(a.at(i), path.at(i));
            if (!(c[i] >= lo && c[i] <= hi))
                fail(path.at(i), "must lie in [" + fmt(lo) + ", " + (hi == std::numeric_limits<float>::max() ? "inf" : fmt(hi)) +
                                     "], got " + fmt(c[i]));
        }
        return c;
    }
    // A number (all three channels) or [r, g, b].
    glm::vec3 perChannel(const QJsonValue& v, const KeyPath& path) const
    {
        if (v.isDouble()) return glm::vec3(floatNumber(v, path));
        if (!v.isArray()) wrongType(v, path, "a number or [r, g, b]");
        return vec3(v, path);
    }

    void readSpecies(const QJsonObject& root, const KeyPath& top, Scene& scene)
    {
        const KeyPath listPath = top.field("species");
        const QJsonArray list = requiredArray(root, top, "species");
        if (list.isEmpty()) fail(listPath, "needs at least one species");
        if (list.size() > qsizetype(std::numeric_limits<uint32_t>::max())) fail(listPath, "too many species");
        scene.species.reserve(size_t(list.size()));
        m_speciesIndex.reserve(list.size());
        for (qsizetype i = 0; i < list.size(); ++i) {
            const KeyPath p = listPath.at(i);
            const QJsonObject o = object(list.at(i), p);
            checkKeys(o, p, {"name", "mesh", "grow", "leaf_materials", "lighting"});
            SpeciesDesc d;
            const QJsonValue nameValue = o.value(QLatin1String("name"));
            if (nameValue.isUndefined()) fail(p.field("name"), "missing (required)");
            const QString name = string(nameValue, p.field("name"));
            if (name.isEmpty()) fail(p.field("name"), "must not be empty");
            const auto seen = m_speciesIndex.constFind(name);
            if (seen != m_speciesIndex.constEnd())
                fail(p.field("name"), "duplicate species name " + quoted(name) + " (also species[" + std::to_string(*seen) + "])");
            m_speciesIndex.insert(name, uint32_t(i));
            d.name = name.toStdString();

            const bool hasMesh = o.contains(QLatin1String("mesh")), hasGrow = o.contains(QLatin1String("grow"));
            if (hasMesh && hasGrow) fail(p, "has both \"mesh\" and \"grow\"; give exactly one");
            if (!hasMesh && !hasGrow) fail(p, "needs \"mesh\" (a mesh file) or \"grow\" (a procedural tree)");
            if (hasMesh) d.meshPath = meshPath(o.value(QLatin1String("mesh")), p.field("mesh"));
            else d.grow = grow(o.value(QLatin1String("grow")), p.field("grow"));

            const QJsonValue leaf = o.value(QLatin1String("leaf_materials"));
            if (!leaf.isUndefined()) {
                const KeyPath lp = p.field("leaf_materials");
                if (!leaf.isArray()) wrongType(leaf, lp, "an array of material names");
                const QJsonArray names = leaf.toArray();
                for (qsizetype k = 0; k < names.size(); ++k) {
                    const QString n = string(names.at(k), lp.at(k));
                    if (n.isEmpty()) fail(lp.at(k), "must not be empty");
                    d.leafMaterials.push_back(n.toStdString());
                }
            }
            readLighting(o.value(QLatin1String("lighting")), p.field("lighting"), d);
            scene.species.push_back(std::move(d));
        }
    }

    std::string meshPath(const QJsonValue& v, const KeyPath& path) const
    {
        const std::string text = string(v, path).toStdString();
        if (text.empty()) fail(path, "must not be empty");
        fs::path p(text);
        if (p.is_relative()) p = m_base / p;
        const std::string abs = p.lexically_normal().string();
        std::error_code ec;
        const fs::file_status st = fs::status(abs, ec);
        if (st.type() == fs::file_type::not_found) fail(path, "no such file: " + abs);
        if (ec) fail(path, "cannot access " + abs + " (" + ec.message() + ")");
        if (st.type() == fs::file_type::directory) fail(path, "is a folder, not a mesh file: " + abs);
        if (st.type() != fs::file_type::regular) fail(path, "not a regular file: " + abs);
        return abs;
    }

    GrowSpec grow(const QJsonValue& v, const KeyPath& path) const
    {
        const QJsonObject o = object(v, path);
        checkKeys(o, path, {"species", "seed", "triangles", "height"});
        GrowSpec g;
        const QJsonValue species = o.value(QLatin1String("species"));
        if (!species.isUndefined()) {
            const QString name = string(species, path.field("species"));
            TreeSpecies s;
            if (!parseSpecies(name.toStdString(), &s))
                fail(path.field("species"), "unknown grower species " + quoted(name) + " (known: " + nameList(speciesNames()) + ")");
            g.species = speciesName(s);
        }
        const QJsonValue seed = o.value(QLatin1String("seed"));
        if (!seed.isUndefined()) g.seed = uint64_t(integer(seed, path.field("seed"), 0, kMaxSeed));
        const QJsonValue triangles = o.value(QLatin1String("triangles"));
        if (!triangles.isUndefined())
            g.triangles = uint64_t(integer(triangles, path.field("triangles"), (long long)kMinGrowTriangles, (long long)kMaxGrowTriangles));
        const QJsonValue height = o.value(QLatin1String("height"));
        if (!height.isUndefined()) {
            g.height = floatNumber(height, path.field("height"));
            if (!(g.height == 0.0f || (g.height >= kMinGrowHeight && g.height <= kMaxGrowHeight)))
                fail(path.field("height"), "must be 0 (the species' default) or lie in [0.1, 150] metres, got " + fmt(g.height));
        }
        return g;
    }

    void readLighting(const QJsonValue& v, const KeyPath& path, SpeciesDesc& d) const
    {
        const QJsonObject o = optionalObject(v, path);
        checkKeys(o, path, {"preset", "sigma_a", "sigma_s", "g", "zero_f0", "grid", "steps", "steps_per_edge", "tolerance", "fp16"});
        const QJsonValue presetValue = o.value(QLatin1String("preset"));
        if (!presetValue.isUndefined()) d.preset = string(presetValue, path.field("preset")).toStdString();
        const lb::Preset* preset = lb::findPreset(d.preset);
        if (!preset) {
            std::vector<std::string> names;
            for (const auto& p : lb::presets()) names.push_back(p.name);
            fail(path.field("preset"), "unknown preset '" + d.preset + "' (known: " + nameList(names) + ")");
        }
        lb::LbParams params = defaultSpeciesLighting(*preset);
        auto applyOverride = [&](const char* key, float lb::ChannelParams::*member) {
            const QJsonValue value = o.value(QLatin1String(key));
            if (value.isUndefined()) return;
            const glm::vec3 rgb = perChannel(value, path.field(key));
            for (int c = 0; c < 3; ++c) params.channels[size_t(c)].*member = rgb[c];
        };
        applyOverride("sigma_a", &lb::ChannelParams::sigmaA);
        applyOverride("sigma_s", &lb::ChannelParams::sigmaS);
        applyOverride("g", &lb::ChannelParams::g);
        const QJsonValue zeroF0 = o.value(QLatin1String("zero_f0"));
        if (!zeroF0.isUndefined()) params.zeroF0 = boolean(zeroF0, path.field("zero_f0"));
        const QJsonValue grid = o.value(QLatin1String("grid"));
        if (!grid.isUndefined()) d.grid = int(integer(grid, path.field("grid"), kMinGrid, kMaxGrid));
        const QJsonValue steps = o.value(QLatin1String("steps"));
        if (!steps.isUndefined()) {
            // A step count (0: steps_per_edge x the longest edge) asks for fixed steps.
            params.steps = int(integer(steps, path.field("steps"), 0, kMaxSteps));
            params.tolerance = 0.0;
        }
        const QJsonValue perEdge = o.value(QLatin1String("steps_per_edge"));
        if (!perEdge.isUndefined()) params.stepsPerEdge = int(integer(perEdge, path.field("steps_per_edge"), 1, 64));
        const QJsonValue tolerance = o.value(QLatin1String("tolerance"));
        if (!tolerance.isUndefined()) {
            params.tolerance = number(tolerance, path.field("tolerance"));
            if (params.tolerance < 0.0) fail(path.field("tolerance"), "must be >= 0 (0: fixed step count), got " + fmt(params.tolerance));
        }
        if (params.steps > 0 && params.tolerance > 0.0)
            fail(path, "\"steps\" and \"tolerance\" exclude each other (give a fixed step count or a tolerance)");
        const QJsonValue fp16 = o.value(QLatin1String("fp16"));
        if (!fp16.isUndefined()) params.storage = boolean(fp16, path.field("fp16")) ? lb::Storage::Fp16 : lb::Storage::Fp32;
        try {
            lb::validate(params);
        } catch (const Error& e) {
            fail(path, e.what());
        }
        d.lighting = params;
    }

    void readInstances(const QJsonObject& root, const KeyPath& top, Scene& scene) const
    {
        const KeyPath listPath = top.field("instances");
        const QJsonArray list = requiredArray(root, top, "instances");
        if (list.isEmpty()) fail(listPath, "needs at least one instance");
        scene.instances.resize(size_t(list.size()));
        for (qsizetype i = 0; i < list.size(); ++i) {
            const KeyPath p = listPath.at(i);
            const QJsonObject o = object(list.at(i), p);
            checkKeys(o, p, {"species", "position", "rotation", "scale"});
            InstanceDesc& inst = scene.instances[size_t(i)];
            const QJsonValue species = o.value(QLatin1String("species"));
            if (species.isUndefined()) fail(p.field("species"), "missing (required: the name of a species)");
            const auto it = m_speciesIndex.constFind(string(species, p.field("species")));
            if (it == m_speciesIndex.constEnd()) {
                std::vector<std::string> names;
                for (const auto& s : scene.species) names.push_back("'" + s.name + "'");
                fail(p.field("species"), "unknown species " + quoted(species.toString()) + " (declared: " + nameList(names) + ")");
            }
            inst.species = *it;
            const QJsonValue position = o.value(QLatin1String("position"));
            if (position.isUndefined()) fail(p.field("position"), "missing (required)");
            inst.position = dvec3(position, p.field("position"));
            const QJsonValue rotation = o.value(QLatin1String("rotation"));
            if (rotation.isDouble()) inst.rotationDeg = glm::vec3(0.0f, floatNumber(rotation, p.field("rotation")), 0.0f);
            else if (rotation.isArray()) inst.rotationDeg = vec3(rotation, p.field("rotation"));
            else if (!rotation.isUndefined()) wrongType(rotation, p.field("rotation"), "[rx, ry, rz] or a number (degrees about +Y)");
            const QJsonValue scale = o.value(QLatin1String("scale"));
            if (!scale.isUndefined()) {
                inst.scale = floatNumber(scale, p.field("scale"));
                if (!(inst.scale > 0.0f)) fail(p.field("scale"), "must be > 0, got " + fmt(inst.scale));
            }
        }
    }

    void readGround(const QJsonValue& v, const KeyPath& path, GroundDesc& g) const
    {
        const QJsonObject o = optionalObject(v, path);
        checkKeys(o, path, {"enabled", "height", "color"});
        if (o.contains(QLatin1String("enabled"))) g.enabled = boolean(o.value(QLatin1String("enabled")), path.field("enabled"));
        if (o.contains(QLatin1String("height"))) g.height = number(o.value(QLatin1String("height")), path.field("height"));
        if (o.contains(QLatin1String("color"))) g.color = color(o.value(QLatin1String("color")), path.field("color"), 0.0f, 1.0f);
    }

    void readSun(const QJsonValue& v, const KeyPath& path, SunDesc& sun) const
    {
        const QJsonObject o = optionalObject(v, path);
        checkKeys(o, path, {"direction", "elevation", "azimuth", "temperature", "intensity"});
        const bool hasDirection = o.contains(QLatin1String("direction"));
        const bool hasElevation = o.contains(QLatin1String("elevation")), hasAzimuth = o.contains(QLatin1String("azimuth"));
        if (hasDirection && (hasElevation || hasAzimuth))
            fail(path, "give either \"direction\" or \"elevation\" and \"azimuth\", not both");
        if (hasDirection) {
            sun.direction = vec3(o.value(QLatin1String("direction")), path.field("direction"));
            if (!(glm::length(sun.direction) >= 1e-12f))
                fail(path.field("direction"), "must be a non-zero vector (length >= 1e-12)");
        } else if (hasElevation || hasAzimuth) {
            if (!hasAzimuth) fail(path.field("azimuth"), "missing (required with \"elevation\")");
            if (!hasElevation) fail(path.field("elevation"), "missing (required with \"azimuth\")");
            const double elevation = number(o.value(QLatin1String("elevation")), path.field("elevation"));
            const double azimuth = number(o.value(QLatin1String("azimuth")), path.field("azimuth"));
            if (elevation < -90.0 || elevation > 90.0)
                fail(path.field("elevation"), "must lie in [-90, 90] degrees, got " + fmt(elevation));
            sun.direction = sunDirection(elevation, azimuth);
        }
        if (o.contains(QLatin1String("temperature"))) {
            sun.temperature = number(o.value(QLatin1String("temperature")), path.field("temperature"));
            if (sun.temperature < kMinTemperature || sun.temperature > kMaxTemperature)
                fail(path.field("temperature"), "must lie in [1000, 40000] kelvin, got " + fmt(sun.temperature));
        }
        if (o.contains(QLatin1String("intensity"))) {
            sun.intensity = floatNumber(o.value(QLatin1String("intensity")), path.field("intensity"));
            if (sun.intensity < 0.0f) fail(path.field("intensity"), "must be >= 0, got " + fmt(sun.intensity));
        }
    }

    void readSky(const QJsonValue& v, const KeyPath& path, Scene& scene) const
    {
        const QJsonObject o = optionalObject(v, path);
        checkKeys(o, path, {"color"});
        if (o.contains(QLatin1String("color")))
            scene.sky = color(o.value(QLatin1String("color")), path.field("color"), 0.0f, std::numeric_limits<float>::max());
    }

    void readCamera(const QJsonValue& v, const KeyPath& path, CameraDesc& cam) const
    {
        const QJsonObject o = optionalObject(v, path);
        checkKeys(o, path, {"position", "target", "up", "fov"});
        if (o.contains(QLatin1String("position"))) cam.position = dvec3(o.value(QLatin1String("position")), path.field("position"));
        if (o.contains(QLatin1String("target"))) cam.target = dvec3(o.value(QLatin1String("target")), path.field("target"));
        if (o.contains(QLatin1String("up"))) cam.up = vec3(o.value(QLatin1String("up")), path.field("up"));
        if (o.contains(QLatin1String("fov"))) {
            cam.fovY = floatNumber(o.value(QLatin1String("fov")), path.field("fov"));
            if (!(cam.fovY > 0.0f && cam.fovY < 180.0f))
                fail(path.field("fov"), "must lie in (0, 180) degrees, got " + fmt(cam.fovY));
        }
        const glm::dvec3 view = cam.target - cam.position;
        const double viewLength = glm::length(view);
        if (!(viewLength > 0.0) || !std::isfinite(viewLength))
            fail(path.field("target"), "must differ from camera.position " + fmt3(cam.position));
        if (!(glm::length(cam.up) >= 1e-12f)) fail(path.field("up"), "must be a non-zero vector (length >= 1e-12)");
        const glm::dvec3 up(cam.up);
        const double upLength = glm::length(up);
        if (glm::length(glm::cross(view / viewLength, up / upLength)) < 1e-6)
            fail(path.field("up"), fmt3(up) + " is parallel to the view direction (target - position) " + fmt3(view));
    }

    void readRender(const QJsonValue& v, const KeyPath& path, RenderSettings& r) const
    {
        const QJsonObject o = optionalObject(v, path);
        checkKeys(o, path, {"width", "height", "spp", "mode", "accel", "shadows", "indirect", "key", "alpha_distance",
                            "prune_distance"});
        if (o.contains(QLatin1String("width")))
            r.width = int(integer(o.value(QLatin1String("width")), path.field("width"), kMinImageSize, kMaxImageSize));
        if (o.contains(QLatin1String("height")))
            r.height = int(integer(o.value(QLatin1String("height")), path.field("height"), kMinImageSize, kMaxImageSize));
        if (o.contains(QLatin1String("spp"))) r.spp = int(integer(o.value(QLatin1String("spp")), path.field("spp"), kMinSpp, kMaxSpp));
        if (o.contains(QLatin1String("mode"))) {
            const QString mode = string(o.value(QLatin1String("mode")), path.field("mode"));
            if (!parseRenderMode(mode.toStdString(), &r.mode))
                fail(path.field("mode"), "unknown mode " + quoted(mode) + " (known: full, local, ambient, lb)");
        }
        if (o.contains(QLatin1String("accel"))) {
            const QString accel = string(o.value(QLatin1String("accel")), path.field("accel"));
            if (!parseAccel(accel.toStdString(), &r.accel))
                fail(path.field("accel"), "unknown acceleration structure " + quoted(accel) + " (known: bvh, kdtree)");
        }
        if (o.contains(QLatin1String("shadows"))) r.shadows = boolean(o.value(QLatin1String("shadows")), path.field("shadows"));
        if (o.contains(QLatin1String("indirect"))) {
            r.indirectScale = floatNumber(o.value(QLatin1String("indirect")), path.field("indirect"));
            if (r.indirectScale < 0.0f) fail(path.field("indirect"), "must be >= 0, got " + fmt(r.indirectScale));
        }
        if (o.contains(QLatin1String("key"))) {
            r.exposureKey = floatNumber(o.value(QLatin1String("key")), path.field("key"));
            if (!(r.exposureKey > 0.0f)) fail(path.field("key"), "must be > 0, got " + fmt(r.exposureKey));
        }
        for (auto [key, field] : {std::pair{"alpha_distance", &r.alphaDistance}, std::pair{"prune_distance", &r.pruneDistance}}) {
            if (!o.contains(QLatin1String(key))) continue;
            *field = floatNumber(o.value(QLatin1String(key)), path.field(key));
            if (*field < 0.0f) fail(path.field(key), "must be >= 0 (metres; 0 = off), got " + fmt(*field));
        }
    }

    std::string m_name;
    fs::path m_base;
    QHash<QString, uint32_t> m_speciesIndex;   // species name -> index: one hash lookup per instance
};

fs::path absoluteFolder(const std::string& dir)
{
    fs::path p = fs::absolute(dir.empty() ? fs::path(".") : fs::path(dir)).lexically_normal();
    if (!p.has_filename() && p.has_parent_path() && p != p.root_path()) p = p.parent_path();   // "/a/b/" -> "/a/b"
    return p;
}

Scene parseText(std::string_view text, const std::string& baseDir, const std::string& name)
{
    QJsonParseError parseError;
    const QJsonDocument doc =
        QJsonDocument::fromJson(QByteArray::fromRawData(text.data(), qsizetype(text.size())), &parseError);
    if (doc.isNull()) {
        size_t offset = size_t(std::max(0, parseError.offset));
        JsonScanner scanner(text);
        if (parseError.error == QJsonParseError::IllegalNumber) {
            // Qt points after the number; name the number and where it starts.
            auto numberChar = [](char c) { return std::isalnum((unsigned char)c) || c == '+' || c == '-' || c == '.'; };
            offset = std::min(offset, text.size());
            size_t start = offset;
            while (start > 0 && numberChar(text[start - 1])) --start;
            size_t stop = start;
            while (stop < text.size() && numberChar(text[stop]) && stop - start < 40) ++stop;
            scanner.scan(start, false);
            const std::string path = scanner.path();
            throw Error(name + ": " + (path.empty() ? "" : path + ": ") + "'" + std::string(text.substr(start, stop - start)) +
                        "' is not a finite number within double range (" + lineColumn(text, start) + ")");
        }
        // Qt's offset is just past the offending character.
        offset = std::min(offset > 0 ? offset - 1 : 0, text.size());
        scanner.scan(offset, false);
        const std::string path = scanner.path();
        throw Error(name + ": " + (path.empty() ? "" : path + ": ") + "malformed JSON at " + lineColumn(text, offset) + ": " +
                    parseError.errorString().toStdString());
    }
    if (!doc.isObject()) throw Error(name + ": the scene must be a JSON object ({ \"version\": 1, ... })");
    JsonScanner scanner(text);
    if (!scanner.scan(text.size(), true))
        throw Error(name + ": " + scanner.path() + ": duplicate key (each key may appear once per object)");
    return SceneReader(name, absoluteFolder(baseDir)).read(doc.object());
}

// ---- writing ----

// Appends scene-file JSON; numbers in the shortest form that reads back exactly, checked finite.
class JsonOut {
public:
    std::string text;

    void raw(std::string_view s) { text += s; }
    void key(const char* k)
    {
        text += '"';
        text += k;
        text += "\": ";
    }
    void string(std::string_view s)
    {
        text += '"';
        for (const char c : s) {
            switch (c) {
            case '"': text += "\\\""; break;
            case '\\': text += "\\\\"; break;
            case '\n': text += "\\n"; break;
            case '\r': text += "\\r"; break;
            case '\t': text += "\\t"; break;
            default:
                if ((unsigned char)c < 0x20) {
                    char buf[8];
                    std::snprintf(buf, sizeof buf, "\\u%04x", unsigned((unsigned char)c));
                    text += buf;
                } else {
                    text += c;
                }
            }
        }
        text += '"';
    }
    void boolean(bool b) { text += b ? "true" : "false"; }
    void integer(long long n) { text += std::to_string(n); }
    void integer(uint64_t n) { text += std::to_string(n); }
    void number(double v, const KeyPath& path)
    {
        if (!std::isfinite(v)) throw Error("scene: " + path.text() + ": cannot write the non-finite number " + fmt(v));
        if (v == 0.0) v = 0.0;   // -0 reads back as 0: write 0, so rewriting a read scene gives the same text
        char buf[64];
        const auto r = std::to_chars(buf, buf + sizeof buf, v);
        text.append(buf, r.ptr);
    }
    void number(float v, const KeyPath& path)
    {
        if (!std::isfinite(v)) throw Error("scene: " + path.text() + ": cannot write the non-finite number " + fmt(v));
        if (v == 0.0f) v = 0.0f;
        char buf[64];
        auto r = std::to_chars(buf, buf + sizeof buf, v);
        // The shortest float text is read as a double, then rounded to float: keep it only when that
        // gives v back (double rounding could differ in rare cases), else write the double exactly.
        double back = 0.0;
        std::from_chars(buf, r.ptr, back);
        if (float(back) != v) r = std::to_chars(buf, buf + sizeof buf, double(v));
        text.append(buf, r.ptr);
    }
    template <class V>
    void vector3(const V& v, const KeyPath& path)
    {
        text += '[';
        for (int i = 0; i < 3; ++i) {
            if (i) text += ", ";
            number(v[i], path.at(i));
        }
        text += ']';
    }
};

// Mesh path relative to base when they share more than the root; absolute otherwise.
std::string storedMeshPath(const std::string& mesh, const fs::path& base)
{
    const fs::path m = fs::absolute(fs::path(mesh)).lexically_normal();
    const fs::path rel = m.lexically_relative(base);
    if (rel.empty()) return m.generic_string();
    size_t up = 0, depth = 0;
    for (const auto& part : rel) {
        if (part != "..") break;
        ++up;
    }
    for (const auto& part : base.relative_path())
        if (!part.empty()) ++depth;
    if (up >= depth) return m.generic_string();
    return rel.generic_string();
}

} // namespace

Scene parseScene(const std::string& jsonText, const std::string& baseDir, const std::string& nameForMessages)
{
    return parseText(jsonText, baseDir, nameForMessages);
}

Scene readSceneFile(const std::string& path)
{
    std::error_code ec;
    const fs::file_status st = fs::status(path, ec);
    if (st.type() == fs::file_type::not_found) throw Error(path + ": no such scene file");
    if (st.type() == fs::file_type::directory) throw Error(path + ": is a folder, not a scene file");
    QFile file(QString::fromStdString(path));
    if (!file.open(QIODevice::ReadOnly)) throw Error(path + ": cannot read the scene file (" + file.errorString().toStdString() + ")");
    std::string text;
    const qint64 size = file.size();
    if (size > 0 && file.isSequential() == false) {
        text.resize(size_t(size));
        if (file.read(text.data(), size) != size) throw Error(path + ": cannot read the scene file (" + file.errorString().toStdString() + ")");
    } else {
        const QByteArray bytes = file.readAll();
        text.assign(bytes.constData(), size_t(bytes.size()));
    }
    return parseText(text, fs::absolute(path).parent_path().string(), path);
}

std::string sceneToJson(const Scene& scene, const std::string& baseDir)
{
    const fs::path base = absoluteFolder(baseDir);
    const KeyPath top;
    JsonOut out;
    out.text.reserve(1024 + scene.instances.size() * 96);
    out.raw("{\n  ");
    out.key("version");
    out.integer((long long)kSceneFileVersion);
    out.raw(",\n  ");
    out.key("species");
    out.raw("[");
    const KeyPath speciesPath = top.field("species");
    for (size_t i = 0; i < scene.species.size(); ++i) {
        const SpeciesDesc& s = scene.species[i];
        const KeyPath p = speciesPath.at(qsizetype(i));
        out.raw(i ? ",\n    {\n      " : "\n    {\n      ");
        out.key("name");
        out.string(s.name);
        out.raw(",\n      ");
        if (s.grow) {
            const KeyPath gp = p.field("grow");
            out.key("grow");
            out.raw("{");
            out.key("species");
            out.string(s.grow->species);
            out.raw(", ");
            out.key("seed");
            out.integer(s.grow->seed);
            out.raw(", ");
            out.key("triangles");
            out.integer(s.grow->triangles);
            out.raw(", ");
            out.key("height");
            out.number(s.grow->height, gp.field("height"));
            out.raw("}");
        } else {
            if (s.meshPath.empty()) throw Error("scene: " + p.text() + ": has neither a mesh path nor a grow spec");
            out.key("mesh");
            out.string(storedMeshPath(s.meshPath, base));
        }
        out.raw(",\n      ");
        out.key("leaf_materials");
        out.raw("[");
        for (size_t k = 0; k < s.leafMaterials.size(); ++k) {
            if (k) out.raw(", ");
            out.string(s.leafMaterials[k]);
        }
        out.raw("],\n      ");
        const KeyPath lp = p.field("lighting");
        const lb::LbParams& l = s.lighting;
        out.key("lighting");
        out.raw("{");
        out.key("preset");
        out.string(s.preset);
        auto channels = [&](const char* key, float lb::ChannelParams::*member) {
            out.raw(", ");
            out.key(key);
            out.vector3(glm::vec3(l.channels[0].*member, l.channels[1].*member, l.channels[2].*member), lp.field(key));
        };
        channels("sigma_a", &lb::ChannelParams::sigmaA);
        channels("sigma_s", &lb::ChannelParams::sigmaS);
        channels("g", &lb::ChannelParams::g);
        out.raw(", ");
        out.key("zero_f0");
        out.boolean(l.zeroF0);
        out.raw(", ");
        out.key("grid");
        out.integer((long long)s.grid);
        out.raw(", ");
        out.key("steps");
        out.integer((long long)l.steps);
        out.raw(", ");
        out.key("steps_per_edge");
        out.integer((long long)l.stepsPerEdge);
        out.raw(", ");
        out.key("tolerance");
        out.number(l.tolerance, lp.field("tolerance"));
        out.raw(", ");
        out.key("fp16");
        out.boolean(l.storage == lb::Storage::Fp16);
        out.raw("}\n    }");
    }
    out.raw("\n  ],\n  ");
    out.key("instances");
    out.raw("[");
    const KeyPath instancesPath = top.field("instances");
    for (size_t i = 0; i < scene.instances.size(); ++i) {
        const InstanceDesc& inst = scene.instances[i];
        const KeyPath p = instancesPath.at(qsizetype(i));
        if (inst.species >= scene.species.size())
            throw Error("scene: " + p.text() + ".species: index " + std::to_string(inst.species) + " is out of range (" +
                        std::to_string(scene.species.size()) + " species)");
        out.raw(i ? ",\n    {" : "\n    {");
        out.key("species");
        out.string(scene.species[inst.species].name);
        out.raw(", ");
        out.key("position");
        out.vector3(inst.position, p.field("position"));
        out.raw(", ");
        out.key("rotation");
        if (inst.rotationDeg.x == 0.0f && inst.rotationDeg.z == 0.0f) out.number(inst.rotationDeg.y, p.field("rotation"));
        else out.vector3(inst.rotationDeg, p.field("rotation"));
        out.raw(", ");
        out.key("scale");
        out.number(inst.scale, p.field("scale"));
        out.raw("}");
    }
    out.raw("\n  ],\n  ");

    const KeyPath gp = top.field("ground");
    out.key("ground");
    out.raw("{");
    out.key("enabled");
    out.boolean(scene.ground.enabled);
    out.raw(", ");
    out.key("height");
    out.number(scene.ground.height, gp.field("height"));
    out.raw(", ");
    out.key("color");
    out.vector3(scene.ground.color, gp.field("color"));
    out.raw("},\n  ");

    const KeyPath sp = top.field("sun");
    out.key("sun");
    out.raw("{");
    out.key("direction");
    out.vector3(scene.sun.direction, sp.field("direction"));
    out.raw(", ");
    out.key("temperature");
    out.number(scene.sun.temperature, sp.field("temperature"));
    out.raw(", ");
    out.key("intensity");
    out.number(scene.sun.intensity, sp.field("intensity"));
    out.raw("},\n  ");

    out.key("sky");
    out.raw("{");
    out.key("color");
    out.vector3(scene.sky, top.field("sky").field("color"));
    out.raw("},\n  ");

    const KeyPath cp = top.field("camera");
    out.key("camera");
    out.raw("{");
    out.key("position");
    out.vector3(scene.camera.position, cp.field("position"));
    out.raw(", ");
    out.key("target");
    out.vector3(scene.camera.target, cp.field("target"));
    out.raw(", ");
    out.key("up");
    out.vector3(scene.camera.up, cp.field("up"));
    out.raw(", ");
    out.key("fov");
    out.number(scene.camera.fovY, cp.field("fov"));
    out.raw("},\n  ");

    const KeyPath rp = top.field("render");
    const RenderSettings& r = scene.render;
    out.key("render");
    out.raw("{");
    out.key("width");
    out.integer((long long)r.width);
    out.raw(", ");
    out.key("height");
    out.integer((long long)r.height);
    out.raw(", ");
    out.key("spp");
    out.integer((long long)r.spp);
    out.raw(", ");
    out.key("mode");
    out.string(renderModeName(r.mode));
    out.raw(", ");
    out.key("accel");
    out.string(accelName(r.accel));
    out.raw(", ");
    out.key("shadows");
    out.boolean(r.shadows);
    out.raw(", ");
    out.key("indirect");
    out.number(r.indirectScale, rp.field("indirect"));
    out.raw(", ");
    out.key("key");
    out.number(r.exposureKey, rp.field("key"));
    out.raw(", ");
    out.key("alpha_distance");
    out.number(r.alphaDistance, rp.field("alpha_distance"));
    out.raw(", ");
    out.key("prune_distance");
    out.number(r.pruneDistance, rp.field("prune_distance"));
    out.raw("}\n}\n");
    return std::move(out.text);
}

void writeSceneFile(const Scene& scene, const std::string& path)
{
    requireReplaceableFile(path);
    const std::string text = sceneToJson(scene, fs::absolute(path).parent_path().string());
    const QFileInfo info(QString::fromStdString(path));
    QDir().mkpath(info.absolutePath());
    QSaveFile file(QString::fromStdString(path));
    if (!file.open(QIODevice::WriteOnly))
        throw Error(path + ": cannot create the scene file (" + file.errorString().toStdString() + ")");
    if (file.write(text.data(), qint64(text.size())) != qint64(text.size())) {
        file.cancelWriting();
        throw Error(path + ": cannot write the scene file (" + file.errorString().toStdString() + ")");
    }
    if (!file.commit()) throw Error(path + ": cannot move the written scene file into place (" + file.errorString().toStdString() + ")");
}

namespace {

// Numbers for people: up to three decimals, trailing zeros dropped; tiny and huge ones in %g form.
std::string human(double v)
{
    char buf[64];
    if (v != 0.0 && (std::fabs(v) < 1e-3 || std::fabs(v) >= 1e9)) {
        std::snprintf(buf, sizeof buf, "%.4g", v);
        return buf;
    }
    std::snprintf(buf, sizeof buf, "%.3f", v);
    std::string t = buf;
    t.erase(t.find_last_not_of('0') + 1);
    if (t.back() == '.') t.pop_back();
    return t == "-0" ? "0" : t;
}

template <class V>
std::string human3(const V& v)
{
    return "(" + human(double(v.x)) + ", " + human(double(v.y)) + ", " + human(double(v.z)) + ")";
}

} // namespace

std::string describeScene(const Scene& scene)
{
    std::vector<size_t> counts(scene.species.size(), 0);
    glm::dvec3 lo(std::numeric_limits<double>::max()), hi(-std::numeric_limits<double>::max());
    float minScale = std::numeric_limits<float>::max(), maxScale = 0.0f;
    for (const InstanceDesc& inst : scene.instances) {
        if (inst.species < counts.size()) ++counts[inst.species];
        lo = glm::min(lo, inst.position);
        hi = glm::max(hi, inst.position);
        minScale = std::min(minScale, inst.scale);
        maxScale = std::max(maxScale, inst.scale);
    }
    std::string s = "scene version " + std::to_string(scene.version) + ": " + std::to_string(scene.species.size()) + " species, " +
                    std::to_string(scene.instances.size()) + " instances\n";
    for (size_t i = 0; i < scene.species.size(); ++i) {
        const SpeciesDesc& d = scene.species[i];
        s += "  species '" + d.name + "': ";
        if (d.grow) {
            s += "grown " + d.grow->species + " (seed " + std::to_string(d.grow->seed) + ", " + std::to_string(d.grow->triangles) +
                 " triangles, " + (d.grow->height > 0.0f ? human(d.grow->height) + " m tall" : std::string("default height")) + ")";
        } else {
            s += "mesh " + d.meshPath;
        }
        if (!d.leafMaterials.empty()) s += ", leaf materials " + nameList(d.leafMaterials);
        const lb::LbParams& l = d.lighting;
        s += "; LB " + d.preset;
        const lb::Preset* preset = lb::findPreset(d.preset);
        bool modified = !preset || preset->zeroF0 != l.zeroF0;
        for (size_t c = 0; preset && c < 3; ++c)
            modified = modified || preset->channels[c].sigmaA != l.channels[c].sigmaA ||
                       preset->channels[c].sigmaS != l.channels[c].sigmaS || preset->channels[c].g != l.channels[c].g;
        if (modified) {
            s += " modified (sigma_a " + human3(glm::vec3(l.channels[0].sigmaA, l.channels[1].sigmaA, l.channels[2].sigmaA)) +
                 ", sigma_s " + human3(glm::vec3(l.channels[0].sigmaS, l.channels[1].sigmaS, l.channels[2].sigmaS)) + ", g " +
                 human3(glm::vec3(l.channels[0].g, l.channels[1].g, l.channels[2].g)) + (l.zeroF0 ? ", zero f0)" : ", keep f0)");
        }
        s += ", grid " + std::to_string(d.grid);
        if (l.tolerance > 0.0) s += ", tolerance " + human(l.tolerance);
        else if (l.steps > 0) s += ", " + std::to_string(l.steps) + " steps";
        else s += ", " + std::to_string(l.stepsPerEdge) + " x the longest edge steps";
        if (l.storage == lb::Storage::Fp16) s += ", fp16";
        s += "; " + std::to_string(counts[i]) + " instances\n";
    }
    if (!scene.instances.empty())
        s += "instances: positions from " + human3(lo) + " to " + human3(hi) + " m, scale " + human(minScale) + " to " + human(maxScale) + "\n";
    if (scene.ground.enabled) s += "ground: plane at y = " + human(scene.ground.height) + " m, albedo " + human3(scene.ground.color) + "\n";
    else s += "ground: none\n";
    const glm::dvec3 sun(scene.sun.direction);   // elevation and azimuth in double
    const double len = glm::length(sun);
    const double elevation = len > 0.0 ? std::asin(std::clamp(sun.y / len, -1.0, 1.0)) * 180.0 / M_PI : 0.0;
    const double azimuth = std::atan2(sun.x, sun.z) * 180.0 / M_PI;
    char buf[256];
    std::snprintf(buf, sizeof buf, "sun: toward %s (elevation %.1f deg, azimuth %.1f deg), %.0f K, intensity %s\n",
                  human3(scene.sun.direction).c_str(),
                  elevation, azimuth < 0.0 ? azimuth + 360.0 : azimuth, scene.sun.temperature, human(scene.sun.intensity).c_str());
    s += buf;
    s += "sky: radiance " + human3(scene.sky) + "\n";
    s += "camera: at " + human3(scene.camera.position) + " looking at " + human3(scene.camera.target) + ", up " +
         human3(scene.camera.up) + ", vertical fov " + human(scene.camera.fovY) + " deg\n";
    const RenderSettings& r = scene.render;
    s += "render: " + std::to_string(r.width) + "x" + std::to_string(r.height) + ", " + std::to_string(r.spp) + " spp, mode " +
         renderModeName(r.mode) + ", " + accelName(r.accel) + ", shadows " + (r.shadows ? "on" : "off") + ", indirect " +
         human(r.indirectScale) + ", key " + human(r.exposureKey);
    if (r.alphaDistance > 0.0f) s += ", alpha tests within " + human(r.alphaDistance) + " m";
    if (r.pruneDistance > 0.0f) s += ", leaves pruned from " + human(r.pruneDistance) + " m";
    s += "\n";
    return s;
}

} // namespace sylva
