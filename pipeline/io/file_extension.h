// The extension of a file name, lower-cased, as the writers and readers pick a format by it.
#pragma once

#include <string>

namespace sylva {

// ".PNG" for "out/A.PNG" -> ".png"; "" when the name has none. Only the last one counts
// ("grid.density.NPY" -> ".npy").
std::string lowerExtension(const std::string& path);

} // namespace sylva
