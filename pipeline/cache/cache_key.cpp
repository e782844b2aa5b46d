// Cache keys (grid_cache.h's CacheKey): XXH3-128 over labelled, typed fields.
#include <bit>
#include <cstring>
#include <string>

#include <xxhash.h>

#include "pipeline/cache/cache_entry.h"
#include "pipeline/cache/grid_cache.h"

namespace sylva {

using cache_format::hexOf;
using cache_format::put;

namespace {

CacheKey::Digest canonical(XXH128_hash_t h)
{
    XXH128_canonical_t c;
    XXH128_canonicalFromHash(&c, h);
    CacheKey::Digest out;
    std::memcpy(out.data(), c.digest, out.size());
    return out;
}

} // namespace

uint64_t xxh3(const void* data, size_t size)
{
    return XXH3_64bits(data, size);
}

// ---- CacheKey ----

void CacheKey::field(char type, std::string_view label, const void* value, size_t size)
{
    unsigned char length[8];
    m_fields += type;
    put(length, label.size(), 8);
    m_fields.append(reinterpret_cast<const char*>(length), 8);
    m_fields.append(label);
    put(length, size, 8);
    m_fields.append(reinterpret_cast<const char*>(length), 8);
    m_fields.append(static_cast<const char*>(value), size);
}

CacheKey& CacheKey::add(std::string_view label, std::span<const std::byte> bytes)
{
    // 16-byte XXH3-128 of the bytes, then their length: the key keeps 24 bytes, not the data.
    unsigned char inner[kDigestBytes + 8];
    const Digest digest = canonical(XXH3_128bits(bytes.data(), bytes.size()));
    std::memcpy(inner, digest.data(), kDigestBytes);
    put(inner + kDigestBytes, bytes.size(), 8);
    field('B', label, inner, sizeof(inner));
    return *this;
}

CacheKey& CacheKey::add(std::string_view label, std::string_view text)
{
    field('S', label, text.data(), text.size());
    return *this;
}

CacheKey& CacheKey::add(std::string_view label, double value)
{
    unsigned char bytes[8];
    put(bytes, std::bit_cast<uint64_t>(value == 0.0 ? 0.0 : value), 8);
    field('D', label, bytes, 8);
    return *this;
}

CacheKey& CacheKey::add(std::string_view label, int64_t value)
{
    unsigned char bytes[8];
    put(bytes, uint64_t(value), 8);
    field('I', label, bytes, 8);
    return *this;
}

CacheKey::Digest CacheKey::digest() const
{
    return canonical(XXH3_128bits(m_fields.data(), m_fields.size()));
}

std::string CacheKey::hex() const
{
    const auto d = digest();
    return hexOf(d.data(), d.size());
}

} // namespace sylva
