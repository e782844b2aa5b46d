// Grid cache: keyed, checksummed, atomically written binary entries (format in grid_cache.h, docs/FILES.md).
// The entries' files are cache_entry.cpp, the keys cache_key.cpp, the folder's upkeep (summary, eviction,
// clean) cache_folder.cpp, the size limit's setting and the sizes' text cache_settings.cpp.
#include "pipeline/cache/grid_cache.h"

#include <filesystem>
#include <utility>

#include <QDir>

#include "core/base/error.h"
#include "pipeline/cache/cache_entry.h"
#include "pipeline/io/atomic_file.h"

namespace sylva {

namespace fs = std::filesystem;
using namespace cache_format;

namespace {

constexpr char kTagSignature[] = "Signature: 8a477f597d28d172789f06886806bc55";

} // namespace

GridCache::GridCache(std::string dir, std::optional<uint64_t> maxBytes)
    : m_dir(std::move(dir)), m_maxBytes(maxBytes ? *maxBytes : cacheSizeLimitSetting())
{
    if (m_dir.empty()) {
        const QString xdg = qEnvironmentVariable("XDG_CACHE_HOME");
        if (!xdg.isEmpty() && QDir::isAbsolutePath(xdg))
            m_dir = QDir(xdg).filePath(QStringLiteral("sylva")).toStdString();
        else
            m_dir = QDir(QDir::homePath()).filePath(QStringLiteral(".cache/sylva")).toStdString();
    }
}

std::string GridCache::entryPath(const CacheKey& key, char kind) const
{
    return (fs::path(m_dir) / "grids" / (key.hex() + "." + kind + ".sgrid")).string();
}

std::optional<DensityGrid> GridCache::loadDensity(const CacheKey& key, std::string* whyMissed)
{
    auto entry = loadEntry(entryPath(key, 'd'), kKindDensity, key.digest(), whyMissed, m_readHook, m_openHook);
    if (!entry) return std::nullopt;
    DensityGrid grid;
    grid.geometry = geometryOf(entry->header);
    const size_t n = grid.geometry.nodeCount();
    grid.woodFraction.assign(entry->payload.begin() + std::ptrdiff_t(n), entry->payload.end());
    entry->payload.resize(n);
    grid.density = std::move(entry->payload);
    return grid;
}

void GridCache::storeDensity(const CacheKey& key, const DensityGrid& grid)
{
    const std::string path = entryPath(key, 'd');
    checkGeometry(path, grid.geometry);
    const size_t n = grid.geometry.nodeCount();
    if (grid.density.size() != n || (!grid.woodFraction.empty() && grid.woodFraction.size() != n))
        throw Error(path + ": the density grid's arrays do not match its dims");
    const std::vector<float> zeros = grid.woodFraction.empty() ? std::vector<float>(n, 0.0f) : std::vector<float>();
    beforeStore(path, uint64_t(n) * 2 * sizeof(float));
    storeEntry(path, headerFor(grid.geometry, kKindDensity, key), {&grid.density, grid.woodFraction.empty() ? &zeros : &grid.woodFraction});
    afterStore(path);
}

std::optional<LightingGrid> GridCache::loadLighting(const CacheKey& key, std::string* whyMissed)
{
    auto entry = loadEntry(entryPath(key, 'l'), kKindLighting, key.digest(), whyMissed, m_readHook, m_openHook);
    if (!entry) return std::nullopt;
    LightingGrid grid;
    grid.geometry = geometryOf(entry->header);
    grid.rgb = std::move(entry->payload);
    return grid;
}

void GridCache::storeLighting(const CacheKey& key, const LightingGrid& grid)
{
    const std::string path = entryPath(key, 'l');
    checkGeometry(path, grid.geometry);
    if (grid.rgb.size() != grid.geometry.nodeCount() * 3) throw Error(path + ": the lighting grid's array does not match its dims");
    beforeStore(path, uint64_t(grid.rgb.size()) * sizeof(float));
    storeEntry(path, headerFor(grid.geometry, kKindLighting, key), {&grid.rgb});
    afterStore(path);
}

bool GridCache::beforeCompute()
{
    if (!m_beforeCompute) return false;
    const std::function<void()> hook = std::move(m_beforeCompute);
    m_beforeCompute = nullptr;
    hook();
    return true;
}

void GridCache::beforeStore(const std::string& path, uint64_t payloadBytes) const
{
    const uint64_t bytes = kHeaderSize + payloadBytes;
    if (m_maxBytes > 0 && bytes > m_maxBytes)
        throw Error(path + ": not cached: the entry (" + formatBytes(bytes) + ") is larger than the cache size limit (" +
                    formatBytes(m_maxBytes) + "; `sylva cache limit` or cache/maxSize in " + cacheSettingsPath() + ")");
    // CACHEDIR.TAG, so backup and sync tools skip the folder (https://bford.info/cachedir/).
    const std::string tag = (fs::path(m_dir) / "CACHEDIR.TAG").string();
    std::error_code ec;
    if (!fs::exists(tag, ec)) {
        AtomicFile file(tag, AtomicFile::Sync::No, "cache folder tag");
        file.write(std::string(kTagSignature) + "\n# This file is a cache directory tag created by Sylva (sylva, sylva-studio).\n"
                   "# For information about cache directory tags, see https://bford.info/cachedir/\n");
        file.commit();
    }
}

void GridCache::afterStore(const std::string&)
{
    if (m_maxBytes > 0) evictTo(m_maxBytes);
}

} // namespace sylva
