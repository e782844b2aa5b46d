// The description of a file that `sylva info` prints: a scene (.json), a mesh, a grid (.npy, with its
// sidecar, or .vdb: describeVdbFile) or a grid cache entry.
#pragma once

#include <string>

#include "core/base/progress.h"

namespace sylva {

// The whole text, lines ending in '\n'. Throws Error naming the file when it is missing, a folder, of a
// kind info does not read (an image, a .npy.json sidecar, ...) or unreadable; Cancelled when progress is
// cancelled (checked before and after reading the file; the reading itself is not divided).
std::string describeFile(const std::string& path, Progress* progress = nullptr);

} // namespace sylva
