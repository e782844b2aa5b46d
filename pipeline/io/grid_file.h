// Grid files by extension, the one dispatch the commands, the services and the studio use: .npy
// (NumPy arrays with JSON sidecars, npy.h) or .vdb (OpenVDB, vdb_io.h).
#pragma once

#include <string>
#include <vector>

#include "core/grid/grid.h"

namespace sylva {

enum class GridFileFormat { Npy, Vdb };

// The extensions of the grid formats, as the commands check and list them: {".npy", ".vdb"}.
const std::vector<std::string>& gridFileExtensions();
// ".npy" or ".vdb".
const char* gridFileExtension(GridFileFormat format);
// The format of PATH by its extension (any case). Throws Error "PATH: not a grid file name (use .npy or
// .vdb)" for another.
GridFileFormat gridFileFormat(const std::string& path);

// A density grid with its wood fraction: .npy writes PATH, the wood fraction file and the sidecar
// (writeDensityGrid); .vdb one file with the grids "density" and "wood_fraction" (writeVdbFile).
void writeDensityFile(const std::string& path, const DensityGrid& grid);
// The files writeDensityFile writes for PATH, the first one PATH.
std::vector<std::string> densityFilesFor(const std::string& path);
// readDensityGrid or readVdbDensity.
DensityGrid readDensityFile(const std::string& path);

// A lighting grid; parametersJson (a JSON object, lightingParamsJson) goes into the .npy sidecar's
// "parameters" or the .vdb's sylva_* metadata. A .vdb also holds `density` when given (the grids
// "density" and "wood_fraction" beside "lighting"), so one file carries what a renderer needs; .npy
// writes the lighting alone. Throws Error naming PATH.
void writeLightingFile(const std::string& path, const LightingGrid& grid, const std::string& parametersJson = {},
                       const DensityGrid* density = nullptr);
// The files writeLightingFile writes for PATH, the first one PATH.
std::vector<std::string> lightingFilesFor(const std::string& path);
// readLightingGrid or readVdbLighting.
LightingGrid readLightingFile(const std::string& path);

} // namespace sylva
