// The grid cache's folder as a whole (grid_cache.h): its summary, least-recently-used eviction and clean,
// temporary files of writers that are gone.
#include <algorithm>
#include <cerrno>
#include <csignal>
#include <ctime>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include "pipeline/cache/cache_entry.h"
#include "pipeline/cache/grid_cache.h"

namespace sylva {

namespace fs = std::filesystem;
using cache_format::versionOf;

namespace {

constexpr int64_t kStaleTempSeconds = 24 * 3600;

int64_t mtimeNs(const struct stat& st)
{
    return int64_t(st.st_mtim.tv_sec) * 1000000000 + int64_t(st.st_mtim.tv_nsec);
}

bool isTempName(const std::string& name)
{
    return name.rfind(".tmp.", 0) == 0;
}

// A temporary file ".tmp.PID.N.NAME" whose writer is gone (no such process) or that is older than a day.
bool staleTemp(const std::string& name, int64_t ageSeconds)
{
    if (ageSeconds > kStaleTempSeconds) return true;
    const size_t end = name.find('.', 5);
    if (end == std::string::npos) return true;
    long pid = 0;
    try {
        pid = std::stol(name.substr(5, end - 5));
    } catch (...) {
        return true;
    }
    if (pid <= 0) return true;
    if (pid == long(::getpid())) return false;
    return ::kill(pid_t(pid), 0) != 0 && errno == ESRCH;
}

// Removes an entry and its sidecars unless a reader holds it (then false, nothing removed). The
// exclusive lock is held across the unlink, so a reader waiting for its shared lock sees an unlinked
// file and misses.
bool tryRemoveEntry(const GridCache::Entry& e)
{
    const int fd = ::open(e.path.c_str(), O_RDONLY | O_CLOEXEC);
    if (fd < 0) return errno == ENOENT;   // gone already
    if (::flock(fd, LOCK_EX | LOCK_NB) != 0) {
        ::close(fd);
        return false;
    }
    std::error_code ec;
    fs::remove(e.path, ec);
    ::close(fd);
    const fs::path p(e.path);
    const std::string prefix = p.filename().string() + ".";
    for (const auto& side : fs::directory_iterator(p.parent_path(), ec)) {
        const std::string name = side.path().filename().string();
        if (name.rfind(prefix, 0) == 0) fs::remove(side.path(), ec);
    }
    return true;
}

uint64_t entryBytes(const std::vector<GridCache::Entry>& entries)
{
    uint64_t total = 0;
    for (const auto& e : entries) total += e.bytes;
    return total;
}

// Evicts the oldest used of `entries` (sorted oldest first) until they fit `limit`; counts into r.
void evictOldest(std::vector<GridCache::Entry>& entries, uint64_t limit, GridCache::CleanResult& r)
{
    uint64_t total = entryBytes(entries);
    std::vector<GridCache::Entry> kept;
    for (auto& e : entries) {
        if (total > limit) {
            if (tryRemoveEntry(e)) {
                ++r.removed;
                r.removedBytes += e.bytes;
                total -= e.bytes;
                continue;
            }
            ++r.busy;
        }
        kept.push_back(e);
    }
    entries = std::move(kept);
}

} // namespace

GridCache::Summary GridCache::summary(bool readVersions) const
{
    Summary sum;
    const fs::path grids = fs::path(m_dir) / "grids";
    std::error_code ec;
    std::map<std::string, size_t> byName;   // entry file name -> index
    std::vector<std::pair<std::string, uint64_t>> sidecars;
    for (const auto& item : fs::directory_iterator(grids, ec)) {
        struct stat st {};
        const std::string path = item.path().string();
        if (::lstat(path.c_str(), &st) != 0 || !S_ISREG(st.st_mode)) continue;
        const std::string name = item.path().filename().string();
        if (isTempName(name)) {
            ++sum.tempFiles;
            sum.tempBytes += uint64_t(st.st_size);
            sum.bytes += uint64_t(st.st_size);
            continue;
        }
        const size_t dot = name.find(".sgrid");
        if (dot == std::string::npos) continue;
        if (dot + 6 == name.size()) {
            Entry e;
            e.path = path;
            e.bytes = uint64_t(st.st_size);
            e.lastUsedNs = mtimeNs(st);
            e.kind = name.size() > 8 && name[name.size() - 8] == '.' ? name[name.size() - 7] : '?';
            e.version = readVersions ? versionOf(path) : kCacheFormatVersion;
            byName[name] = sum.entries.size();
            sum.entries.push_back(e);
        } else if (name[dot + 6] == '.') {
            sidecars.emplace_back(name.substr(0, dot + 6), uint64_t(st.st_size));
        }
    }
    for (const auto& [owner, bytes] : sidecars) {
        auto it = byName.find(owner);
        if (it != byName.end()) sum.entries[it->second].bytes += bytes;
        else sum.bytes += bytes;   // an orphaned sidecar still takes space
    }
    std::sort(sum.entries.begin(), sum.entries.end(),
              [](const Entry& a, const Entry& b) { return a.lastUsedNs != b.lastUsedNs ? a.lastUsedNs < b.lastUsedNs : a.path < b.path; });
    for (const Entry& e : sum.entries) {
        sum.bytes += e.bytes;
        if (e.version != kCacheFormatVersion) ++sum.otherVersion;
        else if (e.kind == 'd') ++sum.density;
        else if (e.kind == 'l') ++sum.lighting;
    }
    return sum;
}

GridCache::CleanResult GridCache::evictTo(uint64_t limit)
{
    CleanResult r;
    std::vector<Entry> entries = summary(false).entries;
    evictOldest(entries, limit, r);
    r.kept = entries.size();
    r.keptBytes = entryBytes(entries);
    return r;
}

GridCache::CleanResult GridCache::clean(const CleanOptions& options)
{
    CleanResult r;
    const Summary sum = summary(true);
    const fs::path grids = fs::path(m_dir) / "grids";
    std::error_code ec;
    const int64_t now = int64_t(std::time(nullptr));
    for (const auto& item : fs::directory_iterator(grids, ec)) {
        const std::string name = item.path().filename().string();
        struct stat st {};
        if (!isTempName(name) || ::lstat(item.path().c_str(), &st) != 0 || !S_ISREG(st.st_mode)) continue;
        if (staleTemp(name, now - int64_t(st.st_mtim.tv_sec))) {
            std::error_code removeError;
            if (fs::remove(item.path(), removeError)) {
                ++r.removed;
                r.removedBytes += uint64_t(st.st_size);
            }
        }
    }
    const bool all = !options.olderThanSeconds && !options.maxBytes;
    std::vector<Entry> rest;
    for (const Entry& e : sum.entries) {
        const bool old = options.olderThanSeconds && (now - e.lastUsedNs / 1000000000) > *options.olderThanSeconds;
        if (all || old || e.version != kCacheFormatVersion) {
            if (tryRemoveEntry(e)) {
                ++r.removed;
                r.removedBytes += e.bytes;
                continue;
            }
            ++r.busy;
        }
        rest.push_back(e);
    }
    if (options.maxBytes) evictOldest(rest, *options.maxBytes, r);
    r.kept = rest.size();
    r.keptBytes = entryBytes(rest);
    return r;
}

} // namespace sylva
