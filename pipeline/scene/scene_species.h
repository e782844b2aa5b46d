// What the scene file's species and instances need beyond the generic field table: unique species
// names and the lookup of instances' species, mesh paths (resolved on read, relative on write), the
// grower species, LB presets with per-channel overrides, rotations, and their summaries.
#pragma once

#include <filesystem>
#include <string>

#include "pipeline/scene/scene_fields.h"

namespace sylva {

// dir as an absolute, lexically normal folder ("" is the current folder; a trailing '/' is dropped).
std::filesystem::path absoluteFolder(const std::string& dir);

// ---- species ----
void readSpeciesName(SceneReadContext& r, const QJsonValue& v, const json::KeyPath& path, SpeciesDesc& d);
// Exactly one of "mesh" and "grow" (checked on the species object at path).
void checkMeshOrGrow(SceneReadContext& r, const QJsonObject& o, const json::KeyPath& path);
// The absolute, lexically normal path of an existing regular file.
std::string readMeshPath(SceneReadContext& r, const QJsonValue& v, const json::KeyPath& path);
// A path to an existing regular file (`what`, e.g. "a DEM image", names it in messages), resolved against
// the scene file's folder; absolute and lexically normal.
std::string readFilePath(SceneReadContext& r, const QJsonValue& v, const json::KeyPath& path, const char* what);
void writeMeshPath(SceneWriteContext& w, const SpeciesDesc& d, const json::KeyPath& path);
// Mesh path relative to base when they share more than the root; absolute otherwise.
std::string storedMeshPath(const std::string& mesh, const std::filesystem::path& base);
std::string readGrowerSpecies(SceneReadContext& r, const QJsonValue& v, const json::KeyPath& path);   // lower-case name
void readLeafMaterials(SceneReadContext& r, const QJsonValue& v, const json::KeyPath& path, SpeciesDesc& d);
void writeLeafMaterials(json::JsonWriter& w, const SpeciesDesc& d);

// ---- LB lighting of a species ----
// The preset (default "leaf") the lighting starts from: sets d.preset and d.lighting to its defaults.
void readLightingPreset(SceneReadContext& r, const QJsonValue& v, const json::KeyPath& path, SpeciesDesc& d);
// After the overrides: steps and tolerance exclude each other, and lb::validate accepts the result.
void checkLighting(SceneReadContext& r, const json::KeyPath& path, const SpeciesDesc& d);
// The species record documented defaults are written from (the default preset's lighting).
SpeciesDesc defaultSpecies();
// A species name not taken in `scene`, from a wish: the wish, else "WISH (2)", "WISH (3)", ... ("species" for an
// empty wish). The studio's import and grow and the Python module's add_species name species with it.
std::string uniqueSpeciesName(const Scene& scene, const std::string& wish);
// A per-channel LB parameter of a record with `lighting` (a species, a volume): one number for all
// channels or [r, g, b], read into and written from lighting.channels[c].*member.
template <class T>
json::Field<T>& channelsField(json::TableBuilder<T>& b, const char* key, float lb::ChannelParams::*member)
{
    return b.custom(
        key,
        [member](json::JsonReader& r, const QJsonValue& v, const json::KeyPath& p, T& d) {
            const glm::vec3 rgb = r.perChannel(v, p);
            for (int c = 0; c < 3; ++c) d.lighting.channels[size_t(c)].*member = rgb[c];
        },
        [member](json::JsonWriter& w, const T& d, const json::KeyPath& p, int) {
            const auto& ch = d.lighting.channels;
            w.vector3(glm::vec3(ch[0].*member, ch[1].*member, ch[2].*member), p);
        });
}

// ---- instances ----
void readInstanceSpecies(SceneReadContext& r, const QJsonValue& v, const json::KeyPath& path, InstanceDesc& inst);
void writeInstanceSpecies(SceneWriteContext& w, const InstanceDesc& inst, const json::KeyPath& path);
// [rx, ry, rz], or a number: degrees about +Y (written so when rx and rz are 0).
void readRotation(SceneReadContext& r, const QJsonValue& v, const json::KeyPath& path, InstanceDesc& inst);
void writeRotation(SceneWriteContext& w, const InstanceDesc& inst, const json::KeyPath& path);

// ---- summaries for people (`sylva info`) ----
std::string describeSpecies(const Scene& scene);     // one line per species
std::string describeInstances(const Scene& scene);   // count-free bounds and scales; empty without instances

} // namespace sylva
