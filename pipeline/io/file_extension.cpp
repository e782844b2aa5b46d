// lowerExtension and the output extension check (file_extension.h).
#include "pipeline/io/file_extension.h"

#include <algorithm>
#include <cctype>
#include <filesystem>

namespace sylva {

std::string lowerExtension(const std::string& path)
{
    std::string ext = std::filesystem::path(path).extension().string();
    for (auto& ch : ext) ch = char(std::tolower((unsigned char)ch));
    return ext;
}

std::string extensionList(const std::vector<std::string>& extensions)
{
    std::string out;
    for (size_t i = 0; i < extensions.size(); ++i) {
        if (i > 0) out += i + 1 == extensions.size() ? " or " : ", ";
        out += extensions[i];
    }
    return out;
}

std::string unwritableExtension(const std::string& path, const std::vector<std::string>& extensions)
{
    const std::string ext = lowerExtension(path);
    if (std::find(extensions.begin(), extensions.end(), ext) != extensions.end()) return {};
    const std::string use = " (use " + extensionList(extensions) + ")";
    if (ext.empty()) return "has no extension" + use;
    return "cannot write " + ext + " files" + use;
}

} // namespace sylva
