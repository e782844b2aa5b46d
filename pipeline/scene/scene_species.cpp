// Species and instance specifics of the scene file (scene_species.h).
#include "pipeline/scene/scene_species.h"

#include <algorithm>
#include <limits>
#include <vector>

#include "core/base/error.h"
#include "pipeline/grow/tree_grower.h"
#include "pipeline/scene/summary_text.h"

namespace sylva {

namespace fs = std::filesystem;
using json::fmt;
using json::KeyPath;
using json::nameList;
using json::quoted;

fs::path absoluteFolder(const std::string& dir)
{
    fs::path p = fs::absolute(dir.empty() ? fs::path(".") : fs::path(dir)).lexically_normal();
    if (!p.has_filename() && p.has_parent_path() && p != p.root_path()) p = p.parent_path();   // "/a/b/" -> "/a/b"
    return p;
}

// ---- species ----

void readSpeciesName(SceneReadContext& r, const QJsonValue& v, const KeyPath& path, SpeciesDesc& d)
{
    const QString name = r.string(v, path);
    if (name.isEmpty()) r.fail(path, "must not be empty");
    const auto seen = r.speciesIndex.constFind(name);
    if (seen != r.speciesIndex.constEnd())
        r.fail(path, "duplicate species name " + quoted(name) + " (also species[" + std::to_string(*seen) + "])");
    r.speciesIndex.insert(name, uint32_t(path.parent->index));   // path: species[i].name
    d.name = name.toStdString();
}

void checkMeshOrGrow(SceneReadContext& r, const QJsonObject& o, const KeyPath& path)
{
    const bool hasMesh = o.contains(QLatin1String("mesh")), hasGrow = o.contains(QLatin1String("grow"));
    if (hasMesh && hasGrow) r.fail(path, "has both \"mesh\" and \"grow\"; give exactly one");
    if (!hasMesh && !hasGrow) r.fail(path, "needs \"mesh\" (a mesh file) or \"grow\" (a procedural tree)");
}

std::string readMeshPath(SceneReadContext& r, const QJsonValue& v, const KeyPath& path) { return readFilePath(r, v, path, "a mesh file"); }

std::string readFilePath(SceneReadContext& r, const QJsonValue& v, const KeyPath& path, const char* what)
{
    const std::string text = r.string(v, path).toStdString();
    if (text.empty()) r.fail(path, "must not be empty");
    fs::path p(text);
    if (p.is_relative()) p = r.base / p;
    const std::string abs = p.lexically_normal().string();
    std::error_code ec;
    const fs::file_status st = fs::status(abs, ec);
    if (st.type() == fs::file_type::not_found) r.fail(path, "no such file: " + abs);
    if (ec) r.fail(path, "cannot access " + abs + " (" + ec.message() + ")");
    if (st.type() == fs::file_type::directory) r.fail(path, std::string("is a folder, not ") + what + ": " + abs);
    if (st.type() != fs::file_type::regular) r.fail(path, "not a regular file: " + abs);
    return abs;
}

void writeMeshPath(SceneWriteContext& w, const SpeciesDesc& d, const KeyPath& path)
{
    if (d.meshPath.empty()) throw Error("scene: " + path.parent->text() + ": has neither a mesh path nor a grow spec");
    w.string(storedMeshPath(d.meshPath, w.base));
}

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

std::string readGrowerSpecies(SceneReadContext& r, const QJsonValue& v, const KeyPath& path)
{
    const QString name = r.string(v, path);
    TreeSpecies s;
    if (!parseSpecies(name.toStdString(), &s))
        r.fail(path, "unknown grower species " + quoted(name) + " (known: " + nameList(speciesNames()) + ")");
    return speciesName(s);
}

void readLeafMaterials(SceneReadContext& r, const QJsonValue& v, const KeyPath& path, SpeciesDesc& d)
{
    if (!v.isArray()) r.wrongType(v, path, "an array of material names");
    const QJsonArray names = v.toArray();
    for (qsizetype k = 0; k < names.size(); ++k) {
        const QString n = r.string(names.at(k), path.at(k));
        if (n.isEmpty()) r.fail(path.at(k), "must not be empty");
        d.leafMaterials.push_back(n.toStdString());
    }
}

void writeLeafMaterials(json::JsonWriter& w, const SpeciesDesc& d)
{
    w.raw("[");
    for (size_t k = 0; k < d.leafMaterials.size(); ++k) {
        if (k) w.raw(", ");
        w.string(d.leafMaterials[k]);
    }
    w.raw("]");
}

// ---- LB lighting ----

void readLightingPreset(SceneReadContext& r, const QJsonValue& v, const KeyPath& path, SpeciesDesc& d)
{
    if (!v.isUndefined()) d.preset = r.string(v, path).toStdString();
    const lb::Preset* preset = lb::findPreset(d.preset);
    if (!preset) {
        std::vector<std::string> names;
        for (const auto& p : lb::presets()) names.push_back(p.name);
        r.fail(path, "unknown preset '" + d.preset + "' (known: " + nameList(names) + ")");
    }
    d.lighting = defaultSpeciesLighting(*preset);
}

void checkLighting(SceneReadContext& r, const KeyPath& path, const SpeciesDesc& d)
{
    if (d.lighting.steps > 0 && d.lighting.tolerance > 0.0)
        r.fail(path, "\"steps\" and \"tolerance\" exclude each other (give a fixed step count or a tolerance)");
    try {
        lb::validate(d.lighting);
    } catch (const Error& e) {
        r.fail(path, e.what());
    }
}

SpeciesDesc defaultSpecies()
{
    SpeciesDesc d;
    d.lighting = defaultSpeciesLighting(*lb::findPreset(d.preset));
    return d;
}

std::string uniqueSpeciesName(const Scene& scene, const std::string& wish)
{
    auto taken = [&](const std::string& n) {
        for (const SpeciesDesc& sp : scene.species)
            if (sp.name == n) return true;
        return false;
    };
    const std::string base = wish.empty() ? std::string("species") : wish;
    if (!taken(base)) return base;
    for (int i = 2;; ++i) {
        const std::string n = base + " (" + std::to_string(i) + ")";
        if (!taken(n)) return n;
    }
}

// ---- instances ----

void readInstanceSpecies(SceneReadContext& r, const QJsonValue& v, const KeyPath& path, InstanceDesc& inst)
{
    const auto it = r.speciesIndex.constFind(r.string(v, path));
    if (it == r.speciesIndex.constEnd()) {
        std::vector<std::string> names;
        for (const auto& s : r.scene->species) names.push_back("'" + s.name + "'");
        r.fail(path, "unknown species " + quoted(v.toString()) +
                         (names.empty() ? " (the scene declares no species)" : " (declared: " + nameList(names) + ")"));
    }
    inst.species = *it;
}

void writeInstanceSpecies(SceneWriteContext& w, const InstanceDesc& inst, const KeyPath& path)
{
    if (inst.species >= w.scene->species.size())
        throw Error("scene: " + path.text() + ": index " + std::to_string(inst.species) + " is out of range (" +
                    std::to_string(w.scene->species.size()) + " species)");
    w.string(w.scene->species[inst.species].name);
}

void readRotation(SceneReadContext& r, const QJsonValue& v, const KeyPath& path, InstanceDesc& inst)
{
    if (v.isDouble()) inst.rotationDeg = glm::vec3(0.0f, r.floatNumber(v, path), 0.0f);
    else if (v.isArray()) inst.rotationDeg = r.vec3(v, path);
    else r.wrongType(v, path, "[rx, ry, rz] or a number (degrees about +Y)");
}

void writeRotation(SceneWriteContext& w, const InstanceDesc& inst, const KeyPath& path)
{
    if (inst.rotationDeg.x == 0.0f && inst.rotationDeg.z == 0.0f) w.number(inst.rotationDeg.y, path);
    else w.vector3(inst.rotationDeg, path);
}

// ---- summaries ----

std::string describeSpecies(const Scene& scene)
{
    std::vector<size_t> counts(scene.species.size(), 0);
    for (const InstanceDesc& inst : scene.instances)
        if (inst.species < counts.size()) ++counts[inst.species];
    std::string s;
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
    return s;
}

std::string describeInstances(const Scene& scene)
{
    if (scene.instances.empty()) return {};
    glm::dvec3 lo(std::numeric_limits<double>::max()), hi(-std::numeric_limits<double>::max());
    float minScale = std::numeric_limits<float>::max(), maxScale = 0.0f;
    for (const InstanceDesc& inst : scene.instances) {
        lo = glm::min(lo, inst.position);
        hi = glm::max(hi, inst.position);
        minScale = std::min(minScale, inst.scale);
        maxScale = std::max(maxScale, inst.scale);
    }
    return "instances: positions from " + human3(lo) + " to " + human3(hi) + " m, scale " + human(minScale) + " to " + human(maxScale) + "\n";
}

} // namespace sylva
