// The grid cache's entry files (cache_entry.cpp; the format is in grid_cache.h): the header's fields, an
// entry's load with its checks and its atomic store, the format version of a file. Internal to pipeline/cache.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "core/grid/grid.h"
#include "pipeline/cache/grid_cache.h"

namespace sylva::cache_format {

inline constexpr char kEntryMagic[8] = {'S', 'Y', 'L', 'V', 'A', 'G', 'R', 'D'};
inline constexpr size_t kHeaderSize = 128;
inline constexpr size_t kKeyOffset = 64;
inline constexpr size_t kPayloadSizeOffset = 80;
inline constexpr size_t kChecksumOffset = 88;   // the checksum covers header bytes [0, 88) and the payload
inline constexpr uint32_t kKindDensity = 1;
inline constexpr uint32_t kKindLighting = 2;

struct EntryHeader {
    uint32_t version = kCacheFormatVersion;
    uint32_t kind = 0;
    int32_t dims[3] = {0, 0, 0};
    uint32_t channels = 0;
    double origin[3] = {0.0, 0.0, 0.0};
    double spacing = 1.0;
    CacheKey::Digest key{};
    uint64_t payloadBytes = 0;
    uint64_t checksum = 0;
};

// Little-endian integers of `bytes` bytes.
void put(unsigned char* out, uint64_t v, int bytes);
uint64_t get(const unsigned char* in, int bytes);

// Bytes as lowercase hex digits.
std::string hexOf(const std::byte* bytes, size_t size);

struct LoadedEntry {
    EntryHeader header;
    std::vector<float> payload;
};

// Loads and verifies one entry. Every defect deletes the file and explains itself through whyMissed.
// The entry is read under a shared flock, which eviction respects; a hit sets its modification time
// (its last use, for the least-recently-used eviction). lockedHook and openedHook: GridCache's test hooks.
std::optional<LoadedEntry> loadEntry(const std::string& path, uint32_t kind, const CacheKey::Digest& key, std::string* whyMissed,
                                     const std::function<void(const std::string&)>& lockedHook,
                                     const std::function<void(const std::string&)>& openedHook);

// Writes `header` (its payload size and checksum filled in here) and the arrays as one entry, atomically.
void storeEntry(const std::string& path, EntryHeader header, const std::vector<const std::vector<float>*>& arrays);

// The header of a grid of `kind` under `key`, and the grid geometry a header describes.
EntryHeader headerFor(const GridGeometry& g, uint32_t kind, const CacheKey& key);
GridGeometry geometryOf(const EntryHeader& h);

// Throws Error naming `path` when the grid cannot be cached (empty dims, a non-positive spacing).
void checkGeometry(const std::string& path, const GridGeometry& g);

// The format version in an entry's header; 0 when it cannot be read or is not a cache file.
uint32_t versionOf(const std::string& path);

} // namespace sylva::cache_format
