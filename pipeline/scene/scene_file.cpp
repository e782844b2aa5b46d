// Scene files: the entry points. The fields are declared once in scene_fields.cpp; json_codec reads
// and writes them; AtomicFile puts the file in place.
#include "pipeline/scene/scene_file.h"

#include <cstdio>
#include <filesystem>

#include <QByteArray>
#include <QFile>

#include "core/base/error.h"
#include "pipeline/io/atomic_file.h"
#include "pipeline/io/dem_io.h"
#include "pipeline/io/env_map_io.h"
#include "pipeline/io/output_path.h"
#include "pipeline/scene/scene_fields.h"
#include "pipeline/scene/scene_species.h"
#include "pipeline/scene/scene_volumes.h"

namespace sylva {

namespace fs = std::filesystem;

Scene parseScene(const std::string& jsonText, const std::string& baseDir, const std::string& nameForMessages)
{
    const QJsonObject root =
        json::parseObject(jsonText, nameForMessages, "the scene must be a JSON object ({ \"version\": 1, ... })");
    Scene scene;
    SceneReadContext context(nameForMessages, absoluteFolder(baseDir), scene);
    json::readObject(context, root, json::KeyPath{}, scene, sceneTable());
    return scene;
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
    Scene scene = parseScene(text, fs::absolute(path).parent_path().string(), path);
    try {
        loadSceneTerrain(scene);   // the terrain's heights, read and checked with the file
    } catch (const Error& e) {
        throw Error(path + ": terrain.dem: " + e.what());
    }
    loadSceneVolumes(scene);   // the volumes' density and temperature grids, read and checked with the file
    try {
        const std::string cleaned = loadSceneSky(scene);   // the sky's map read and cleaned, or its Preetham model built
        if (cleaned.find("cleaned:") != std::string::npos) std::fprintf(stderr, "sylva: sky.path: %s\n", cleaned.c_str());
    } catch (const Error& e) {
        throw Error(path + ": sky: " + e.what());
    }
    return scene;
}

std::string sceneToJson(const Scene& scene, const std::string& baseDir)
{
    SceneWriteContext context(absoluteFolder(baseDir), scene);
    context.text.reserve(1024 + scene.instances.size() * 96);
    json::writeObject(context, scene, json::KeyPath{}, sceneTable(), 0);
    context.raw("\n");
    return std::move(context.text);
}

void writeSceneFile(const Scene& scene, const std::string& path)
{
    requireReplaceableFile(path);
    const std::string text = sceneToJson(scene, fs::absolute(path).parent_path().string());
    AtomicFile file(path, AtomicFile::Sync::Yes, "scene file");
    file.write(text);
    file.commit();
}

std::string describeScene(const Scene& scene)
{
    std::string s;
    for (const auto& field : sceneTable().fields)
        if (field.summary) s += field.summary(scene);
    return s;
}

} // namespace sylva
