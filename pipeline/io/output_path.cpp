// Output-path checks shared by every atomic writer (npy, images, OBJ, cache).
#include "pipeline/io/output_path.h"

#include <filesystem>

#include "core/base/error.h"

namespace sylva {

void requireReplaceableFile(const std::string& path)
{
    namespace fs = std::filesystem;
    if (path.empty()) throw Error("empty output path");
    std::error_code ec;
    const fs::file_status st = fs::symlink_status(path, ec);
    if (ec || st.type() == fs::file_type::not_found) return;
    if (st.type() == fs::file_type::directory) throw Error(path + ": is a folder, not a file; give a file name");
    if (st.type() == fs::file_type::symlink) {
        const fs::file_status target = fs::status(path, ec);
        if (!ec && target.type() != fs::file_type::regular && target.type() != fs::file_type::not_found)
            throw Error(path + ": links to something that is not a regular file; refusing to replace it");
        return;
    }
    if (st.type() != fs::file_type::regular)
        throw Error(path + ": exists and is not a regular file (a device, pipe or socket); refusing to replace it");
}

} // namespace sylva
