// The extension of a file name, lower-cased, as the writers and readers pick a format by it, and the
// check of an output name against the formats a writer has.
#pragma once

#include <string>
#include <vector>

namespace sylva {

// ".PNG" for "out/A.PNG" -> ".png"; "" when the name has none. Only the last one counts
// ("grid.density.NPY" -> ".npy").
std::string lowerExtension(const std::string& path);

// {".npy", ".vdb"} -> ".npy or .vdb"; {".png", ".exr", ".tif"} -> ".png, .exr or .tif".
std::string extensionList(const std::vector<std::string>& extensions);

// Empty when lowerExtension(path) is one of `extensions` (lower case, with the dot); else why not, for
// a message about PATH: "cannot write .x files (use .npy or .vdb)" or "has no extension (use ...)".
std::string unwritableExtension(const std::string& path, const std::vector<std::string>& extensions);

} // namespace sylva
