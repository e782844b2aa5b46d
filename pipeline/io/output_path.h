// Checks an output path before a file is written to it by temporary file + rename.
#pragma once

#include <string>

namespace sylva {

// Throws Error naming PATH when it is empty, names a folder, or names something other than a regular
// file (a device such as /dev/null, a FIFO, a socket): renaming a temporary file over those would
// replace them. A missing file is fine (its folder is created by the writers).
void requireReplaceableFile(const std::string& path);

} // namespace sylva

namespace sylva {

// A unique temporary path beside an output file (same folder, same extension so writers that pick
// the format by extension still work), renamed over the target by commit() and removed otherwise.
// The target is checked with requireReplaceableFile and its folder is created.
class ReplacingFile {
public:
    explicit ReplacingFile(std::string target);
    ReplacingFile(const ReplacingFile&) = delete;
    ReplacingFile& operator=(const ReplacingFile&) = delete;
    ~ReplacingFile();

    const std::string& tempPath() const { return m_temp; }
    const std::string& target() const { return m_target; }
    // Renames the temporary file over the target; throws Error naming the target on failure.
    void commit();

private:
    std::string m_target, m_temp;
    bool m_committed = false;
};

} // namespace sylva
