// What a scene, mesh, grid or cache file holds, as text (file_info.h).
#include "pipeline/services/file_info.h"

#include <cstdio>
#include <filesystem>

#include "core/base/error.h"
#include "pipeline/cache/grid_cache.h"
#include "pipeline/import/mesh_import.h"
#include "pipeline/io/file_extension.h"
#include "pipeline/io/npy.h"
#include "pipeline/io/vdb_io.h"
#include "pipeline/scene/scene_file.h"
#include "pipeline/services/grid_stats.h"

namespace fs = std::filesystem;

namespace sylva {
namespace {

// The array's shape and value range, then its sidecar as stored (the first 4095 bytes).
std::string describeNpy(const std::string& path)
{
    const NpyArray a = readNpy(path);
    std::string shape;
    for (size_t s : a.shape) shape += (shape.empty() ? "" : ", ") + std::to_string(s);
    const ValueStats v = valueStats(a.data);
    std::string text = path + ": NumPy float32 array, shape (" + shape + "), " + std::to_string(v.count) + " values";
    char numbers[128];
    std::snprintf(numbers, sizeof numbers, ", min %.6g, max %.6g, mean %.6g\n", v.min, v.max, v.mean);
    text += numbers;
    const std::string sidecar = gridSidecarPath(path);
    if (fs::exists(sidecar)) {
        if (std::FILE* f = std::fopen(sidecar.c_str(), "rb")) {
            char buf[4096];
            const size_t n = std::fread(buf, 1, sizeof buf - 1, f);
            std::fclose(f);
            buf[n] = 0;
            text += "placement (" + sidecar + "): " + std::string(buf) + "\n";
        }
    }
    return text;
}

std::string describeMeshFile(const std::string& path)
{
    ImportReport report;
    TriangleMesh mesh;
    try {
        mesh = importMesh(path, {}, &report);
    } catch (const Error& e) {
        throw Error(std::string(e.what()) + " (sylva info reads meshes, .npy and .vdb grids and cache entries)");
    }
    std::string text = path + ": mesh\n" + describeMesh(mesh);
    for (const auto& w : report.warnings) text += "warning: " + w + "\n";
    return text;
}

std::string describeKnownFile(const std::string& path)
{
    if (isCacheFile(path)) return describeCacheFile(path);
    const std::string ext = lowerExtension(path);
    if (ext == ".npy") return describeNpy(path);
    if (ext == ".vdb") return describeVdbFile(path);
    if (ext == ".json" && path.size() > 11 && path.substr(path.size() - 11) != ".npy.json")
        return path + ": scene\n" + describeScene(readSceneFile(path));
    for (const char* notMesh : {".json", ".png", ".jpg", ".jpeg", ".tif", ".tiff", ".exr", ".txt", ".mtl"})
        if (ext == notMesh)
            throw Error(path + ": not a scene, mesh, .npy or .vdb grid or cache entry (sylva info reads those; a .npy.json "
                               "sidecar is shown with its .npy)");
    return describeMeshFile(path);
}

} // namespace

std::string describeFile(const std::string& path, Progress* progress)
{
    std::error_code ec;
    if (!fs::exists(path, ec)) throw Error(path + ": no such file");
    if (fs::is_directory(path, ec)) throw Error(path + ": is a folder, not a file");
    if (progress) progress->report(0.0, "reading " + fs::path(path).filename().string());
    std::string text = describeKnownFile(path);
    if (progress) progress->report(1.0);
    return text;
}

} // namespace sylva
