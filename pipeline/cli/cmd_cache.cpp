// sylva cache: what the grid cache holds (info), emptying it (clean) and its size limit (limit).
#include <cstdio>
#include <ctime>
#include <string>

#include "core/base/error.h"
#include "pipeline/cache/grid_cache.h"
#include "pipeline/cli/cli_util.h"
#include "pipeline/cli/commands.h"
#include "pipeline/cli/common_options.h"

namespace sylva::cli {
namespace {

const OptionSpec kOlderThan{"--older-than", "D", "clean: entries not used for D (30d, 12h, 90m, 45s, 2w; a bare number is days)"};
const OptionSpec kMaxSize{"--max-size", "S", "clean: then least recently used first down to S (500M, 2G; powers of 1024)"};

std::string whenText(int64_t ns, int64_t now)
{
    const std::time_t t = std::time_t(ns / 1000000000);
    std::tm local{};
    localtime_r(&t, &local);
    char stamp[64];
    std::strftime(stamp, sizeof stamp, "%Y-%m-%d %H:%M %Z", &local);
    const int64_t age = now - int64_t(t);
    std::string ago;
    if (age < 120) ago = "just now";
    else if (age < 7200) ago = std::to_string(age / 60) + " minutes ago";
    else if (age < 2 * 86400) ago = std::to_string(age / 3600) + " hours ago";
    else ago = std::to_string(age / 86400) + " days ago";
    return std::string(stamp) + " (" + ago + ")";
}

std::string sizeText(uint64_t bytes)
{
    return bytes < 1024 ? formatBytes(bytes) : formatBytes(bytes) + " (" + std::to_string(bytes) + " bytes)";
}

std::string limitText(uint64_t limit)
{
    return limit == 0 ? std::string("none") : sizeText(limit);
}

int runInfo(GridCache& cache)
{
    const GridCache::Summary s = cache.summary();
    const int64_t now = int64_t(std::time(nullptr));
    const size_t current = s.density + s.lighting;
    std::printf("cache:     %s\n", cache.dir().c_str());
    std::printf("entries:   %zu (%zu density, %zu lighting)", current, s.density, s.lighting);
    if (s.otherVersion > 0) std::printf(", and %zu of another format version (sylva cache clean removes them)", s.otherVersion);
    std::printf("\nsize:      %s\n", sizeText(s.bytes).c_str());
    std::printf("limit:     %s, set in %s\n", limitText(cache.maxBytes()).c_str(), cacheSettingsPath().c_str());
    if (!s.entries.empty()) {
        std::printf("oldest:    %s, last used\n", whenText(s.entries.front().lastUsedNs, now).c_str());
        std::printf("newest:    %s, last used\n", whenText(s.entries.back().lastUsedNs, now).c_str());
    }
    if (s.tempFiles > 0)
        std::printf("temporary: %zu file(s), %s (writes in progress, or left by a crash: sylva cache clean removes those)\n",
                    s.tempFiles, formatBytes(s.tempBytes).c_str());
    return kOk;
}

int runClean(const Args& args, GridCache& cache)
{
    GridCache::CleanOptions options;
    if (args.has("--older-than")) {
        options.olderThanSeconds = parseDuration(args.get("--older-than"));
        if (!options.olderThanSeconds)
            throw UsageError("option --older-than: '" + args.get("--older-than") + "' is not a duration (30d, 12h, 90m, 45s, 2w)");
    }
    if (args.has("--max-size")) {
        options.maxBytes = parseByteSize(args.get("--max-size"));
        if (!options.maxBytes) throw UsageError("option --max-size: '" + args.get("--max-size") + "' is not a size (500M, 2G, 1048576)");
    }
    const GridCache::CleanResult r = cache.clean(options);
    std::printf("removed %zu file(s), %s; %zu entries, %s remain in %s\n", r.removed, formatBytes(r.removedBytes).c_str(), r.kept,
                formatBytes(r.keptBytes).c_str(), cache.dir().c_str());
    if (r.busy > 0) std::printf("%zu entries were being read and stay (run it again later)\n", r.busy);
    return kOk;
}

int runLimit(const Args& args)
{
    if (args.positional().size() < 2) {
        std::printf("%s\n", limitText(cacheSizeLimitSetting()).c_str());
        return kOk;
    }
    const std::string text = args.positional()[1];
    uint64_t bytes = 0;
    if (text != "none" && text != "off") {
        const auto parsed = parseByteSize(text);
        if (!parsed || *parsed == 0) throw UsageError("'" + text + "' is not a size limit (500M, 20G, or none)");
        bytes = *parsed;
    }
    setCacheSizeLimitSetting(bytes);
    std::printf("cache size limit: %s (in %s)\n", limitText(bytes).c_str(), cacheSettingsPath().c_str());
    if (bytes > 0) {
        GridCache cache({}, bytes);
        const GridCache::CleanResult r = cache.evictTo(bytes);
        if (r.removed > 0) std::printf("evicted %zu entries, %s, from %s\n", r.removed, formatBytes(r.removedBytes).c_str(), cache.dir().c_str());
    }
    return kOk;
}

int runCache(const Args& args)
{
    const std::string action = args.positional()[0];
    if (action != "clean" && (args.has("--older-than") || args.has("--max-size")))
        throw UsageError("--older-than and --max-size belong to 'sylva cache clean'");
    if (action == "limit") {
        if (args.has("--cache")) throw UsageError("the size limit is a setting of every cache folder; 'sylva cache limit' takes no --cache");
        return runLimit(args);
    }
    if (args.positional().size() > 1) throw UsageError("unexpected argument '" + args.positional()[1] + "' for 'sylva cache " + action + "'");
    GridCache cache(args.get("--cache"));
    if (action == "info") return runInfo(cache);
    if (action == "clean") return runClean(args, cache);
    throw UsageError("unknown action '" + action + "' for 'sylva cache' (info, clean or limit)");
}

} // namespace

Command cacheCommand()
{
    return {"cache",
            "info|clean|limit [SIZE|none] [--older-than D] [--max-size S] [--cache DIR]",
            "the grid cache: info (size, entries, oldest use), clean (all, or by age and size), limit (the size limit)",
            {kOlderThan, kMaxSize, kCache},
            1,
            2,
            &runCache};
}

} // namespace sylva::cli
