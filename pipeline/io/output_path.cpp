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

#include <atomic>
#include <unistd.h>

namespace sylva {

ReplacingFile::ReplacingFile(std::string target) : m_target(std::move(target))
{
    namespace fs = std::filesystem;
    requireReplaceableFile(m_target);
    static std::atomic<unsigned> counter{0};
    const fs::path path(m_target);
    const fs::path dir = path.parent_path().empty() ? fs::path(".") : path.parent_path();
    std::error_code ec;
    fs::create_directories(dir, ec);
    if (!fs::is_directory(dir))
        throw Error(m_target + ": cannot create the folder " + dir.string() + (ec ? " (" + ec.message() + ")" : ""));
    m_temp = (dir / (".tmp." + std::to_string(::getpid()) + "." + std::to_string(counter.fetch_add(1)) + "." +
                     path.filename().string()))
                 .string();
}

ReplacingFile::~ReplacingFile()
{
    if (!m_committed) {
        std::error_code ec;
        std::filesystem::remove(m_temp, ec);
    }
}

void ReplacingFile::commit()
{
    std::error_code ec;
    std::filesystem::rename(m_temp, m_target, ec);
    if (ec) throw Error(m_target + ": cannot move the written file into place (" + ec.message() + ")");
    m_committed = true;
}

} // namespace sylva
