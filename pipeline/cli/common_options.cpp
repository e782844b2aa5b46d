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

sky::SunPlace parseSunAt(const std::string& text)
{
    const std::vector<std::string> parts = splitList(text);
    const std::string expected =
        "expected YYYY-MM-DD,HH:MM[:SS],ZONE,LATITUDE,LONGITUDE (e.g. 2024-06-21,08:30,+2,48.14,11.58), got '" + text + "'";
    sky::SunPlace place;
    if (parts.size() != 5 || !sky::parseSunDate(parts[0], &place.year, &place.month, &place.day) || !sky::parseSunTime(parts[1], &place.hour))
        throw UsageError("option --sun-at: " + expected);
    place.timeZoneHours = parseNumber("--sun-at", parts[2]);
    place.latitudeDeg = parseNumber("--sun-at", parts[3]);
    place.longitudeDeg = parseNumber("--sun-at", parts[4]);
    try {
        sky::noaaSunPosition(place);
    } catch (const Error& e) {
        throw UsageError(std::string("option --sun-at: ") + e.what());
    }
    return place;
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
