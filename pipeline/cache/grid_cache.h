// On-disk cache of density and lighting grids keyed by a hash of everything that produced them.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "core/grid/grid.h"

namespace sylva {

// Version of the binary entry format below. Fold it into keys (key.add("cache format",
// int64_t(kCacheFormatVersion))) so a format change moves to fresh entries instead of rejecting old ones.
// Version 2: XXH3 keys (128-bit) and checksums (64-bit), 128-byte header; version 1 had SHA-256 keys.
inline constexpr uint32_t kCacheFormatVersion = 2;

// XXH3-128 over labelled, length-prefixed, typed fields, so ("ab","c") != ("a","bc") and
// add("n", 1.0) != add("n", int64_t(1)). Byte spans are hashed first (their XXH3-128 and length go
// into the key), so keys over large meshes stay cheap to copy. The order of add() calls matters.
// XXH3 is not cryptographic: the key tells apart inputs, it does not resist an adversary (the cache
// is the user's own folder); at ~10 GB/s a 256^3 density keys in milliseconds (SHA-256: ~1 s).
class CacheKey {
public:
    static constexpr size_t kDigestBytes = 16;
    using Digest = std::array<std::byte, kDigestBytes>;

    CacheKey& add(std::string_view label, std::span<const std::byte> bytes);
    CacheKey& add(std::string_view label, std::string_view text);
    CacheKey& add(std::string_view label, const char* text) { return add(label, std::string_view(text)); }
    CacheKey& add(std::string_view label, double value);   // -0.0 is folded into 0.0
    CacheKey& add(std::string_view label, int64_t value);
    CacheKey& add(std::string_view label, int value) { return add(label, int64_t(value)); }

    Digest digest() const;    // XXH3-128 of the fields so far, canonical (big-endian) bytes
    std::string hex() const;  // digest() as 32 lowercase hex digits (what `xxhsum -H2` prints)

private:
    void field(char type, std::string_view label, const void* value, size_t size);
    std::string m_fields;
};

// Cache entries live in DIR/grids/<hex>.<d|l>.sgrid, one file per key and kind; DIR holds a
// CACHEDIR.TAG (https://bford.info/cachedir/) so backup tools skip it.
//
// Binary entry format, version 2 (all integers and floats little-endian), 128-byte header:
//   offset size
//     0      8  magic "SYLVAGRD"
//     8      4  uint32 format version (kCacheFormatVersion)
//    12      4  uint32 kind: 1 = density, 2 = lighting
//    16     12  int32[3] dims X, Y, Z (nodes)
//    28      4  uint32 channels: 2 for density (density, wood fraction), 3 for lighting (R, G, B)
//    32     24  float64[3] origin (metres)
//    56      8  float64 spacing (metres)
//    64     16  XXH3-128 of the key (CacheKey::digest())
//    80      8  uint64 payload byte count = X*Y*Z*channels*4
//    88      8  uint64 XXH3-64 (seed 0) of header bytes [0, 88) followed by the payload
//    96     32  reserved, zero
//   128      -  payload, float32: density: density[N] then wood fraction[N] (z fastest);
//                lighting: rgb[N*3] (node * 3 + channel)
// The checksum guards against torn or damaged files, not against an adversary, and covers the
// header fields too, so a damaged origin or dims is caught.
//
// Size limit and eviction: after each store, entries are evicted least recently used first (a load
// sets an entry's modification time: its last use) until the folder's entries fit the limit. An
// entry being read holds a shared lock (flock) and is never evicted; eviction takes the exclusive
// lock without waiting and skips an entry it cannot lock.
class GridCache {
public:
    // Empty dir: $XDG_CACHE_HOME/sylva when that variable is set and absolute, else ~/.cache/sylva.
    // maxBytes: the size limit (0: none); without it, cacheSizeLimitSetting().
    explicit GridCache(std::string dir = {}, std::optional<uint64_t> maxBytes = std::nullopt);
    const std::string& dir() const { return m_dir; }
    uint64_t maxBytes() const { return m_maxBytes; }

    // A missing entry is a miss (whyMissed: "no cache entry PATH"). A truncated, corrupt, wrong-version,
    // wrong-kind or stale (other key) entry is never used: it is deleted and whyMissed says why, e.g.
    // "cache entry PATH is corrupt (checksum mismatch); recomputing". A hit marks the entry used now.
    std::optional<DensityGrid> loadDensity(const CacheKey& key, std::string* whyMissed = nullptr);
    std::optional<LightingGrid> loadLighting(const CacheKey& key, std::string* whyMissed = nullptr);

    // Atomic: written to a uniquely named temporary file in the entry's folder, then renamed over the
    // entry, so concurrent writers of one key leave one whole entry (an interrupted write leaves none).
    // Creates the folders and CACHEDIR.TAG, then evicts down to the size limit. Throws Error naming the
    // file when it cannot be written or is larger than the limit (callers may treat that as a warning).
    void storeDensity(const CacheKey& key, const DensityGrid& grid);
    void storeLighting(const CacheKey& key, const LightingGrid& grid);

    // kind: 'd' (density) or 'l' (lighting).
    std::string entryPath(const CacheKey& key, char kind) const;

    // ---- the folder as a whole (sylva cache info / clean) ----
    struct Entry {
        std::string path;
        uint64_t bytes = 0;      // the entry and its sidecars (NAME.sgrid.*)
        int64_t lastUsedNs = 0;  // nanoseconds since the epoch (the entry's modification time)
        char kind = '?';         // 'd', 'l'
        uint32_t version = 0;    // format version in its header (0: unreadable)
    };
    struct Summary {
        std::vector<Entry> entries;   // every *.sgrid, oldest use first
        uint64_t bytes = 0;           // entries, sidecars and temporary files
        size_t density = 0, lighting = 0, otherVersion = 0;
        size_t tempFiles = 0;         // temporary files of writers (".tmp.*"), running or crashed
        uint64_t tempBytes = 0;
    };
    Summary summary(bool readVersions = true) const;

    struct CleanOptions {
        std::optional<int64_t> olderThanSeconds;   // remove entries not used for this long
        std::optional<uint64_t> maxBytes;           // then evict least recently used down to this
        // Neither: remove every entry. Always: entries of other format versions, and temporary files of
        // writers that are gone (their process id no longer runs, or older than a day).
    };
    struct CleanResult {
        size_t removed = 0, busy = 0, kept = 0;   // busy: being read, left in place
        uint64_t removedBytes = 0, keptBytes = 0;
    };
    CleanResult clean(const CleanOptions& options);

    // Evicts least recently used entries until the entries fit `limit` bytes; returns what it did.
    CleanResult evictTo(uint64_t limit);

    // Called once, before the first voxelization or LB solve that a miss in this cache would start
    // (densityForTriangles, lightingFor), which then looks in the cache again: `sylva render --mpi`'s rank 0
    // shares the species' solves out to the ranks there, so a warm cache is read once and waits for no one.
    void setBeforeCompute(std::function<void()> hook) { m_beforeCompute = std::move(hook); }
    // Runs that hook and clears it first (a solve inside it computes as usual); true when it ran, and the
    // caller should look in the cache again. For callers that miss one at a time (a render's preparation).
    bool beforeCompute();

    // For tests: called while a load holds an entry's shared lock, before it reads the payload.
    void setReadHookForTests(std::function<void(const std::string& path)> hook) { m_readHook = std::move(hook); }
    // For tests: called when a load has opened an entry, before it takes the shared lock.
    void setOpenHookForTests(std::function<void(const std::string& path)> hook) { m_openHook = std::move(hook); }

private:
    void beforeStore(const std::string& path, uint64_t payloadBytes) const;
    void afterStore(const std::string& path);
    std::string m_dir;
    uint64_t m_maxBytes = 0;
    std::function<void(const std::string&)> m_readHook;
    std::function<void(const std::string&)> m_openHook;
    std::function<void()> m_beforeCompute;
};

// The cache size limit from the user's settings (QSettings "Sylva"/"sylva": $XDG_CONFIG_HOME/Sylva/
// sylva.conf, key cache/maxSize, bytes or a size like "20G"); kDefaultCacheLimit when unset, 0 = none.
inline constexpr uint64_t kDefaultCacheLimit = uint64_t(20) << 30;
uint64_t cacheSizeLimitSetting();
void setCacheSizeLimitSetting(uint64_t bytes);   // 0: no limit
std::string cacheSettingsPath();                 // the settings file (for messages)

// "20G", "512M", "1.5GiB", "4096" (bytes; K, M, G, T are powers of 1024, "iB"/"B" optional) -> bytes;
// std::nullopt when it is not such a size.
std::optional<uint64_t> parseByteSize(std::string_view text);
// "30d", "12h", "90m", "45s", "2w" (a bare number is days) -> seconds; std::nullopt otherwise.
std::optional<int64_t> parseDuration(std::string_view text);
// 1536 -> "1.50 KiB"
std::string formatBytes(uint64_t bytes);

// Describes a cache entry for `sylva info`: kind, dims, channels, placement, key, payload size, and
// whether the checksum holds (or how the file is damaged). Throws Error when it is not a cache file.
std::string describeCacheFile(const std::string& path);

// True when PATH starts with the cache magic "SYLVAGRD".
bool isCacheFile(const std::string& path);

// XXH3-64 of bytes with seed 0 (the cache's checksum), exposed for tests and tools.
uint64_t xxh3(const void* data, size_t size);

} // namespace sylva
