// Grid files by extension (grid_file.h).
#include "pipeline/io/grid_file.h"

#include "core/base/error.h"
#include "pipeline/io/file_extension.h"
#include "pipeline/io/npy.h"
#include "pipeline/io/vdb_io.h"

namespace sylva {

const std::vector<std::string>& gridFileExtensions()
{
    static const std::vector<std::string> extensions{".npy", ".vdb"};
    return extensions;
}

const char* gridFileExtension(GridFileFormat format)
{
    return format == GridFileFormat::Vdb ? ".vdb" : ".npy";
}

GridFileFormat gridFileFormat(const std::string& path)
{
    const std::string ext = lowerExtension(path);
    if (ext == ".npy") return GridFileFormat::Npy;
    if (ext == ".vdb") return GridFileFormat::Vdb;
    throw Error(path + ": not a grid file name (use " + extensionList(gridFileExtensions()) + ")");
}

void writeDensityFile(const std::string& path, const DensityGrid& grid)
{
    if (gridFileFormat(path) == GridFileFormat::Vdb) writeVdbFile(path, &grid, nullptr);
    else writeDensityGrid(path, grid);
}

std::vector<std::string> densityFilesFor(const std::string& path)
{
    if (gridFileFormat(path) == GridFileFormat::Vdb) return {path};
    return {path, woodFractionPath(path), gridSidecarPath(path)};
}

DensityGrid readDensityFile(const std::string& path)
{
    return gridFileFormat(path) == GridFileFormat::Vdb ? readVdbDensity(path) : readDensityGrid(path);
}

void writeLightingFile(const std::string& path, const LightingGrid& grid, const std::string& parametersJson, const DensityGrid* density)
{
    if (gridFileFormat(path) == GridFileFormat::Vdb) writeVdbFile(path, density, &grid, parametersJson);
    else writeLightingGrid(path, grid, parametersJson);
}

std::vector<std::string> lightingFilesFor(const std::string& path)
{
    if (gridFileFormat(path) == GridFileFormat::Vdb) return {path};
    return {path, gridSidecarPath(path)};
}

LightingGrid readLightingFile(const std::string& path)
{
    return gridFileFormat(path) == GridFileFormat::Vdb ? readVdbLighting(path) : readLightingGrid(path);
}

} // namespace sylva
