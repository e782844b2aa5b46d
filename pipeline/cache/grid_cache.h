// On-disk cache of density and lighting grids keyed by a hash of everything that produced them.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>

#include "core/grid/grid.h"

namespace sylva {

// Version of the binary entry format below. Fold it into keys (key.add("cache format",
// int64_t(kCacheFormatVersion))) so a format change moves to fresh entries instead of rejecting old ones.
inline constexpr uint32_t kCacheFormatVersion = 1;

// SHA-256 over labelled, length-prefixed, typed fields, so ("ab","c") != ("a","bc") and
// add("n", 1.0) != add("n", int64_t(1)). Byte spans are hashed first (their SHA-256 and length go
// into the key), so keys over large meshes stay cheap to copy. The order of add() calls matters.
class CacheKey {
public:
    CacheKey& add(std::string_view label, std::span<const std::byte> bytes);
    CacheKey& add(std::string_view label, std::string_view text);
    CacheKey& add(std::string_view label, const char* text) { return add(label, std::string_view(text)); }
    CacheKey& add(std::string_view label, double value);   // -0.0 is folded into 0.0
    CacheKey& add(std::string_view label, int64_t value);
    CacheKey& add(std::string_view label, int value) { return add(label, int64_t(value)); }

    std::array<std::byte, 32> digest() const;   // SHA-256 of the fields so far
    std::string hex() const;                      // digest() as 64 lowercase hex digits

private:
    void field(char type, std::string_view label, const void* value, size_t size);
    std::string m_fields;
};

// Cache entries live in DIR/grids/<hex>.<d|l>.sgrid, one file per key and kind.
//
// Binary entry format, version 1 (all integers and floats little-endian), 136-byte header:
//   offset size
//     0      8  magic "SYLVAGRD"
//     8      4  uint32 format version (kCacheFormatVersion)
//    12      4  uint32 kind: 1 = density, 2 = lighting
//    16     12  int32[3] dims X, Y, Z (nodes)
//    28      4  uint32 channels: 2 for density (density, wood fraction), 3 for lighting (R, G, B)
//    32     24  float64[3] origin (metres)
//    56      8  float64 spacing (metres)
//    64     32  SHA-256 of the key (CacheKey::digest())
//    96      8  uint64 payload byte count = X*Y*Z*channels*4
//   104      8  uint64 XXH64 (seed 0) of header bytes [0, 104) followed by the payload
//   112     24  reserved, zero
//   136      -  payload, float32: density: density[N] then wood fraction[N] (z fastest);
//                lighting: rgb[N*3] (node * 3 + channel)
// The checksum is XXH64, written here, not SHA-256: it guards against torn or damaged files, not
// against an adversary, and at ~4 GB/s it costs little next to the disk, where QCryptographicHash's
// SHA-256 (Qt 6.4) runs at ~130 MB/s: 1.5 s per 200 MB lighting grid on every load. It also covers the
// header fields, so a damaged origin or dims is caught too. Keys stay SHA-256 (small inputs).
class GridCache {
public:
    // Empty dir: $XDG_CACHE_HOME/sylva when that variable is set and absolute, else ~/.cache/sylva.
    explicit GridCache(std::string dir = {});
    const std::string& dir() const { return m_dir; }

    // A missing entry is a miss (whyMissed: "no cache entry PATH"). A truncated, corrupt, wrong-version,
    // wrong-kind or stale (other key) entry is never used: it is deleted and whyMissed says why, e.g.
    // "cache entry PATH is corrupt (checksum mismatch); recomputing".
    std::optional<DensityGrid> loadDensity(const CacheKey& key, std::string* whyMissed = nullptr);
    std::optional<LightingGrid> loadLighting(const CacheKey& key, std::string* whyMissed = nullptr);

    // Atomic: written to a uniquely named temporary file in the entry's folder, then renamed over the
    // entry, so concurrent writers of one key leave one whole entry. Creates the folders. Throws Error
    // naming the file when it cannot be written (callers may treat that as a warning).
    void storeDensity(const CacheKey& key, const DensityGrid& grid);
    void storeLighting(const CacheKey& key, const LightingGrid& grid);

    // kind: 'd' (density) or 'l' (lighting).
    std::string entryPath(const CacheKey& key, char kind) const;

private:
    std::string m_dir;
};

// Describes a cache entry for `sylva info`: kind, dims, channels, placement, key, payload size, and
// whether the checksum holds (or how the file is damaged). Throws Error when it is not a cache file.
std::string describeCacheFile(const std::string& path);

// True when PATH starts with the cache magic "SYLVAGRD".
bool isCacheFile(const std::string& path);

// XXH64 of bytes with seed 0 (the cache's checksum), exposed for tests and tools.
uint64_t xxh64(const void* data, size_t size, uint64_t seed = 0);

} // namespace sylva
