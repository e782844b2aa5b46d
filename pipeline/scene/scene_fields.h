// The scene file's field table (docs/SCENE.md "Fields"): every key declared once, with its type,
// default, bounds and a one-line doc; reading, writing, the unknown-key check, the summary of
// `sylva info` and the check of docs/SCENE.md all walk it.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include <QHash>
#include <QString>

#include "core/scene/scene.h"
#include "pipeline/scene/field_table.h"

namespace sylva {

// The state of one read: messages name the file; relative mesh paths start at base; species names
// are looked up by hash (one lookup per instance).
struct SceneReadContext : json::JsonReader {
    SceneReadContext(std::string name, std::filesystem::path baseDir, Scene& target)
        : json::JsonReader(std::move(name)), base(std::move(baseDir)), scene(&target)
    {
    }
    std::filesystem::path base;
    Scene* scene;
    QHash<QString, uint32_t> speciesIndex;
};

// The state of one write: mesh paths are written relative to base; instances name their species.
struct SceneWriteContext : json::JsonWriter {
    SceneWriteContext(std::filesystem::path baseDir, const Scene& source) : base(std::move(baseDir)), scene(&source) { name = "scene"; }
    std::filesystem::path base;
    const Scene* scene;
};

// The whole file: a Block-layout table over Scene (version, species, instances, ground, sun, sky,
// camera, render). Read and write it with a SceneReadContext / SceneWriteContext.
const json::Table<Scene>& sceneTable();

// The rows of docs/SCENE.md's field table, in order, as the table declares them.
std::vector<json::FieldDoc> sceneFieldDocs();

// The bounds the scene file checks on the number at KEY, a full key as sceneFieldDocs() names it
// ("sun.temperature", "terrain.rock_slope", "species[i].lighting.steps_per_edge"): the studio's widgets take
// their ranges from it. Throws sylva::Error for an unknown key or a field without bounds.
json::Bounds sceneFieldRange(const std::string& key);

} // namespace sylva
