// lowerExtension (file_extension.h).
#include "pipeline/io/file_extension.h"

#include <cctype>
#include <filesystem>

namespace sylva {

std::string lowerExtension(const std::string& path)
{
    std::string ext = std::filesystem::path(path).extension().string();
    for (auto& ch : ext) ch = char(std::tolower((unsigned char)ch));
    return ext;
}

} // namespace sylva
