// Scene files (*.sylva.json, docs/SCENE.md): strict reading with key-path messages, exact writing, a summary.
#pragma once

#include <string>

#include "core/scene/scene.h"

namespace sylva {

// The scene file format version this build reads and writes ("version" in the file).
inline constexpr int kSceneFileVersion = 1;

// Reads and checks a scene file. Mesh paths are resolved against the scene file's folder and must
// name existing files; SpeciesDesc::meshPath holds the absolute, lexically normal path. Throws Error
// "PATH: KEY.PATH: problem" (e.g. "forest.sylva.json: instances[3].scale: must be > 0, got -1") on
// unreadable files, malformed JSON (with line and column), unknown or duplicate keys, wrong types,
// out-of-range values and LB parameters that lb::validate refuses. A terrain's DEM is read too
// (loadSceneTerrain), and its problems reported the same way.
Scene readSceneFile(const std::string& path);

// As readSceneFile, from text. baseDir: folder relative mesh paths start from (empty: the current
// folder). nameForMessages: what messages call the text (usually the file's path).
Scene parseScene(const std::string& jsonText, const std::string& baseDir, const std::string& nameForMessages);

// The scene as scene-file JSON text: every field the format holds, explicitly (no reliance on
// defaults); mesh paths relative to baseDir when they share more than the root with it, absolute
// otherwise. Numbers are written in the shortest form that reads back to the same float/double, so
// parseScene(sceneToJson(s, dir), dir, name) equals s field by field. Not stored (run-time solve
// settings, LbParams defaults after reading): LbParams::sun and ::intensity (taken from the scene's
// sun when solving), checkEvery, maxSteps, warmStart, solvesPerPass, blockSteps, brownThreshold.
// Throws Error naming the key path for a non-finite number, an instance whose species index is out
// of range, or a species with neither a mesh path nor a grow spec.
std::string sceneToJson(const Scene& scene, const std::string& baseDir);

// Writes sceneToJson(scene, folder of path) atomically (temporary file in the same folder, then
// rename); creates the folder. Throws Error naming the path.
void writeSceneFile(const Scene& scene, const std::string& path);

// A few lines for `sylva info`: species (mesh file or grow spec, LB preset and grid, instance count),
// instances (count and bounds), ground, sun, sky, camera, render settings. Ends with a newline.
std::string describeScene(const Scene& scene);

} // namespace sylva
