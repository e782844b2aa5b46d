// Options shared by several commands (common_options.h).
#include "pipeline/cli/common_options.h"

#include <cstdio>
#include <filesystem>

#include "core/base/error.h"
#include "pipeline/backend_select.h"
#include "pipeline/cli/cli_util.h"

namespace fs = std::filesystem;

namespace sylva::cli {

std::unique_ptr<tbb::global_control> threadLimit(const Args& args)
{
    if (!args.has("--threads")) return nullptr;
    const long long n = parseInteger("--threads", args.get("--threads"), 1, 1024);
    return std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism, size_t(n));
}

std::unique_ptr<GridCache> openCache(const Args& args)
{
    if (args.has("--no-cache")) return nullptr;
    return std::make_unique<GridCache>(args.get("--cache"));
}

void requireReadable(const std::string& path, const char* what)
{
    std::error_code ec;
    if (!fs::exists(path, ec)) throw Error(path + ": no such " + std::string(what));
    if (fs::is_directory(path, ec)) throw Error(path + ": is a folder, not a " + std::string(what));
}

std::string backendName(const Args& args)
{
    const std::string backend = args.get("--backend", "auto");
    if (backend != "auto" && backend != "cpu" && backend != "cuda")
        throw UsageError("option --backend: expected auto, cpu or cuda, got '" + backend + "'");
    return backend;
}

std::unique_ptr<Backend> openBackend(const std::string& name)
{
    return selectBackend(name, [](const std::string& note) { std::fprintf(stderr, "note: %s\n", note.c_str()); });
}

std::string outputFile(const Args& args, const std::vector<std::string>& extensions, const std::string& fallback)
{
    const std::string path = fallback.empty() ? args.require("--output") : args.get("--output", fallback);
    const std::string problem = unwritableExtension(path, extensions);
    if (!problem.empty()) throw UsageError("output " + path + ": " + problem);
    return path;
}

} // namespace sylva::cli
