// Checks an output path before a file is written to it by temporary file + rename (AtomicFile).
#pragma once

#include <string>

namespace sylva {

// Throws Error naming PATH when it is empty, names a folder, or names something other than a regular
// file (a device such as /dev/null, a FIFO, a socket): renaming a temporary file over those would
// replace them. A missing file is fine (its folder is created by the writers).
void requireReplaceableFile(const std::string& path);

} // namespace sylva
