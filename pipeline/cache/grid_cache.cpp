// Grid cache: keyed, checksummed, atomically written binary entries (format in grid_cache.h, docs/FILES.md).
#include "pipeline/cache/grid_cache.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <limits>
#include <sstream>
#include <vector>

#include <QCryptographicHash>
#include <QDir>
#include <QFile>
#include <QFileInfo>

#include "core/base/error.h"
#include "pipeline/io/atomic_file.h"

namespace sylva {

namespace fs = std::filesystem;

// ---- XXH64 (public algorithm by Yann Collet; this implementation is ours) ----

namespace {

constexpr uint64_t kPrime1 = 0x9E3779B185EBCA87ull;
constexpr uint64_t kPrime2 = 0xC2B2AE3D27D4EB4Full;
constexpr uint64_t kPrime3 = 0x165667B19E3779F9ull;
constexpr uint64_t kPrime4 = 0x85EBCA77C2B2AE63ull;
constexpr uint64_t kPrime5 = 0x27D4EB2F165667C5ull;

uint64_t load64(const unsigned char* p)
{
    uint64_t v;
    std::memcpy(&v, p, 8);
    if constexpr (std::endian::native == std::endian::big) v = __builtin_bswap64(v);
    return v;
}

uint32_t load32(const unsigned char* p)
{
    uint32_t v;
    std::memcpy(&v, p, 4);
    if constexpr (std::endian::native == std::endian::big) v = __builtin_bswap32(v);
    return v;
}

uint64_t xxRound(uint64_t acc, uint64_t input)
{
    acc += input * kPrime2;
    acc = std::rotl(acc, 31);
    return acc * kPrime1;
}

uint64_t xxMerge(uint64_t acc, uint64_t value)
{
    acc ^= xxRound(0, value);
    return acc * kPrime1 + kPrime4;
}

// Streaming XXH64: feed bytes in any pieces, the digest equals xxh64() of their concatenation.
class Xxh64 {
public:
    explicit Xxh64(uint64_t seed = 0)
        : m_seed(seed), m_acc{seed + kPrime1 + kPrime2, seed + kPrime2, seed, seed - kPrime1}
    {
    }

    void update(const void* data, size_t size)
    {
        const unsigned char* p = static_cast<const unsigned char*>(data);
        m_total += size;
        if (m_buffered > 0) {
            const size_t take = std::min(size, size_t(32) - m_buffered);
            std::memcpy(m_buffer + m_buffered, p, take);
            m_buffered += take;
            p += take;
            size -= take;
            if (m_buffered < 32) return;
            stripe(m_buffer);
            m_buffered = 0;
        }
        while (size >= 32) {
            stripe(p);
            p += 32;
            size -= 32;
        }
        std::memcpy(m_buffer, p, size);
        m_buffered = size;
    }

    uint64_t digest() const
    {
        uint64_t h;
        if (m_total >= 32) {
            h = std::rotl(m_acc[0], 1) + std::rotl(m_acc[1], 7) + std::rotl(m_acc[2], 12) + std::rotl(m_acc[3], 18);
            for (uint64_t a : m_acc) h = xxMerge(h, a);
        } else {
            h = m_seed + kPrime5;
        }
        h += m_total;
        const unsigned char* p = m_buffer;
        size_t left = m_buffered;
        for (; left >= 8; p += 8, left -= 8) h = std::rotl(h ^ xxRound(0, load64(p)), 27) * kPrime1 + kPrime4;
        if (left >= 4) {
            h = std::rotl(h ^ (uint64_t(load32(p)) * kPrime1), 23) * kPrime2 + kPrime3;
            p += 4;
            left -= 4;
        }
        for (; left > 0; ++p, --left) h = std::rotl(h ^ (uint64_t(*p) * kPrime5), 11) * kPrime1;
        h ^= h >> 33;
        h *= kPrime2;
        h ^= h >> 29;
        h *= kPrime3;
        h ^= h >> 32;
        return h;
    }

private:
    void stripe(const unsigned char* p)
    {
        for (int lane = 0; lane < 4; ++lane) m_acc[lane] = xxRound(m_acc[lane], load64(p + 8 * lane));
    }

    uint64_t m_seed;
    uint64_t m_acc[4];
    unsigned char m_buffer[32] = {};
    size_t m_buffered = 0;
    uint64_t m_total = 0;
};

// ---- entry header ----

constexpr char kEntryMagic[8] = {'S', 'Y', 'L', 'V', 'A', 'G', 'R', 'D'};
constexpr size_t kHeaderSize = 136;
constexpr size_t kChecksumOffset = 104;   // the checksum covers header bytes [0, 104) and the payload
constexpr uint32_t kKindDensity = 1;
constexpr uint32_t kKindLighting = 2;

struct EntryHeader {
    uint32_t version = kCacheFormatVersion;
    uint32_t kind = 0;
    int32_t dims[3] = {0, 0, 0};
    uint32_t channels = 0;
    double origin[3] = {0.0, 0.0, 0.0};
    double spacing = 1.0;
    std::array<std::byte, 32> key{};
    uint64_t payloadBytes = 0;
    uint64_t checksum = 0;
};

void put(unsigned char* out, uint64_t v, int bytes)
{
    for (int b = 0; b < bytes; ++b) out[b] = (unsigned char)((v >> (8 * b)) & 0xff);
}

uint64_t get(const unsigned char* in, int bytes)
{
    uint64_t v = 0;
    for (int b = bytes - 1; b >= 0; --b) v = (v << 8) | in[b];
    return v;
}

void encodeHeader(const EntryHeader& h, unsigned char* out)
{
    std::memset(out, 0, kHeaderSize);
    std::memcpy(out, kEntryMagic, 8);
    put(out + 8, h.version, 4);
    put(out + 12, h.kind, 4);
    for (int a = 0; a < 3; ++a) put(out + 16 + 4 * a, uint32_t(h.dims[a]), 4);
    put(out + 28, h.channels, 4);
    for (int a = 0; a < 3; ++a) put(out + 32 + 8 * a, std::bit_cast<uint64_t>(h.origin[a]), 8);
    put(out + 56, std::bit_cast<uint64_t>(h.spacing), 8);
    std::memcpy(out + 64, h.key.data(), 32);
    put(out + 96, h.payloadBytes, 8);
    put(out + kChecksumOffset, h.checksum, 8);
}

EntryHeader decodeHeader(const unsigned char* in)
{
    EntryHeader h;
    h.version = uint32_t(get(in + 8, 4));
    h.kind = uint32_t(get(in + 12, 4));
    for (int a = 0; a < 3; ++a) h.dims[a] = int32_t(uint32_t(get(in + 16 + 4 * a, 4)));
    h.channels = uint32_t(get(in + 28, 4));
    for (int a = 0; a < 3; ++a) h.origin[a] = std::bit_cast<double>(get(in + 32 + 8 * a, 8));
    h.spacing = std::bit_cast<double>(get(in + 56, 8));
    std::memcpy(h.key.data(), in + 64, 32);
    h.payloadBytes = get(in + 96, 8);
    h.checksum = get(in + kChecksumOffset, 8);
    return h;
}

const char* kindName(uint32_t kind)
{
    return kind == kKindDensity ? "density" : kind == kKindLighting ? "lighting" : "unknown";
}

uint32_t channelsOf(uint32_t kind)
{
    return kind == kKindDensity ? 2u : 3u;
}

// Payload bytes the header's dims and channels imply; 0 when they are invalid or overflow.
uint64_t expectedPayload(const EntryHeader& h)
{
    if (h.kind != kKindDensity && h.kind != kKindLighting) return 0;
    if (h.channels != channelsOf(h.kind)) return 0;
    uint64_t n = 1;
    for (int a = 0; a < 3; ++a) {
        if (h.dims[a] <= 0) return 0;
        if (n > (uint64_t(1) << 40) / uint64_t(h.dims[a])) return 0;
        n *= uint64_t(h.dims[a]);
    }
    return n * h.channels * sizeof(float);
}

std::string hexOf(const std::byte* bytes, size_t size)
{
    static const char digits[] = "0123456789abcdef";
    std::string s;
    s.reserve(size * 2);
    for (size_t i = 0; i < size; ++i) {
        s += digits[(unsigned(bytes[i]) >> 4) & 0xf];
        s += digits[unsigned(bytes[i]) & 0xf];
    }
    return s;
}

std::string hex64(uint64_t v)
{
    static const char digits[] = "0123456789abcdef";
    std::string s(16, '0');
    for (int i = 15; i >= 0; --i, v >>= 4) s[size_t(i)] = digits[v & 0xf];
    return s;
}

// Reads exactly `size` bytes, feeding them to `hash` when given; returns the count actually read.
size_t readFully(QFile& file, void* data, size_t size, Xxh64* hash)
{
    char* p = static_cast<char*>(data);
    size_t done = 0;
    while (done < size) {
        const qint64 chunk = qint64(std::min<size_t>(size - done, size_t(4) << 20));
        const qint64 got = file.read(p + done, chunk);
        if (got <= 0) break;
        if (hash) hash->update(p + done, size_t(got));
        done += size_t(got);
    }
    return done;
}

struct LoadedEntry {
    EntryHeader header;
    std::vector<float> payload;
};

// Loads and verifies one entry. Every defect deletes the file and explains itself through whyMissed.
std::optional<LoadedEntry> loadEntry(const std::string& path, uint32_t kind, const std::array<std::byte, 32>& key, std::string* whyMissed)
{
    auto miss = [&](const std::string& why) -> std::optional<LoadedEntry> {
        if (whyMissed) *whyMissed = why;
        return std::nullopt;
    };
    std::error_code ec;
    if (!fs::exists(path, ec)) return miss("no cache entry " + path);
    QFile file(QString::fromStdString(path));
    if (!file.open(QIODevice::ReadOnly)) return miss("cannot read cache entry " + path + " (" + file.errorString().toStdString() + "); recomputing");

    auto reject = [&](const std::string& problem) -> std::optional<LoadedEntry> {
        file.close();
        std::error_code removeError;
        fs::remove(path, removeError);
        return miss("cache entry " + path + " is " + problem + "; recomputing");
    };

    const uint64_t fileSize = uint64_t(file.size());
    unsigned char raw[kHeaderSize];
    if (readFully(file, raw, kHeaderSize, nullptr) != kHeaderSize)
        return reject("truncated (" + std::to_string(fileSize) + " bytes, the header alone needs " + std::to_string(kHeaderSize) + ")");
    if (std::memcmp(raw, kEntryMagic, 8) != 0) return reject("not a Sylva grid cache file (bad magic)");
    const EntryHeader h = decodeHeader(raw);
    if (h.version != kCacheFormatVersion)
        return reject("of format version " + std::to_string(h.version) + " (this build reads version " + std::to_string(kCacheFormatVersion) + ")");
    if (h.kind != kind) return reject("a " + std::string(kindName(h.kind)) + " entry, not a " + kindName(kind) + " entry");
    if (h.key != key) return reject("stale (written for another key)");
    const uint64_t expected = expectedPayload(h);
    if (expected == 0 || h.payloadBytes != expected || !(h.spacing > 0.0) || !std::isfinite(h.spacing))
        return reject("corrupt (inconsistent header)");
    if (fileSize < kHeaderSize + h.payloadBytes)
        return reject("truncated (" + std::to_string(fileSize - kHeaderSize) + " of " + std::to_string(h.payloadBytes) + " payload bytes)");
    if (fileSize > kHeaderSize + h.payloadBytes)
        return reject("corrupt (" + std::to_string(fileSize - kHeaderSize - h.payloadBytes) + " bytes after the payload)");

    LoadedEntry entry;
    entry.header = h;
    Xxh64 hash;
    hash.update(raw, kChecksumOffset);
    entry.payload.resize(size_t(h.payloadBytes / sizeof(float)));
    if (readFully(file, entry.payload.data(), size_t(h.payloadBytes), &hash) != h.payloadBytes)
        return reject("truncated (the payload could not be read in full)");
    if (hash.digest() != h.checksum) return reject("corrupt (checksum mismatch)");
    if constexpr (std::endian::native == std::endian::big)
        for (float& f : entry.payload) f = std::bit_cast<float>(__builtin_bswap32(std::bit_cast<uint32_t>(f)));
    return entry;
}

void storeEntry(const std::string& path, EntryHeader header, const std::vector<const std::vector<float>*>& arrays)
{
    uint64_t payloadBytes = 0;
    for (const auto* a : arrays) payloadBytes += a->size() * sizeof(float);
    header.payloadBytes = payloadBytes;

    std::vector<std::vector<float>> swapped;   // only on big-endian hosts
    std::vector<const std::vector<float>*> le = arrays;
    if constexpr (std::endian::native == std::endian::big) {
        for (auto*& a : le) {
            swapped.push_back(*a);
            for (float& f : swapped.back()) f = std::bit_cast<float>(__builtin_bswap32(std::bit_cast<uint32_t>(f)));
            a = &swapped.back();
        }
    }

    unsigned char raw[kHeaderSize];
    encodeHeader(header, raw);
    Xxh64 hash;
    hash.update(raw, kChecksumOffset);
    for (const auto* a : le) hash.update(a->data(), a->size() * sizeof(float));
    header.checksum = hash.digest();
    encodeHeader(header, raw);

    // A uniquely named temporary file beside the entry, synced, then renamed into place: readers see
    // the old entry or the new one, and concurrent writers of one key leave one whole entry.
    AtomicFile file(path, AtomicFile::Sync::Yes, "cache entry");
    file.write(raw, kHeaderSize);
    for (const auto* a : le) file.write(a->data(), a->size() * sizeof(float));
    file.commit();
}

EntryHeader headerFor(const GridGeometry& g, uint32_t kind, const CacheKey& key)
{
    EntryHeader h;
    h.kind = kind;
    h.channels = channelsOf(kind);
    for (int a = 0; a < 3; ++a) {
        h.dims[a] = g.dims[a];
        h.origin[a] = g.origin[a];
    }
    h.spacing = g.spacing;
    h.key = key.digest();
    return h;
}

GridGeometry geometryOf(const EntryHeader& h)
{
    GridGeometry g;
    g.dims = glm::ivec3(h.dims[0], h.dims[1], h.dims[2]);
    g.origin = glm::dvec3(h.origin[0], h.origin[1], h.origin[2]);
    g.spacing = h.spacing;
    return g;
}

void checkGeometry(const std::string& path, const GridGeometry& g)
{
    if (g.dims.x <= 0 || g.dims.y <= 0 || g.dims.z <= 0 || !(g.spacing > 0.0) || !std::isfinite(g.spacing))
        throw Error(path + ": refusing to cache a grid with empty dims or a non-positive spacing");
}

} // namespace

uint64_t xxh64(const void* data, size_t size, uint64_t seed)
{
    Xxh64 h(seed);
    h.update(data, size);
    return h.digest();
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
    // 32-byte SHA-256 of the bytes, then their length: the key keeps 40 bytes, not the data.
    unsigned char inner[40];
    const QByteArray digest = QCryptographicHash::hash(
        QByteArrayView(reinterpret_cast<const char*>(bytes.data()), qsizetype(bytes.size())), QCryptographicHash::Sha256);
    std::memcpy(inner, digest.constData(), 32);
    put(inner + 32, bytes.size(), 8);
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

std::array<std::byte, 32> CacheKey::digest() const
{
    const QByteArray d = QCryptographicHash::hash(QByteArrayView(m_fields.data(), qsizetype(m_fields.size())), QCryptographicHash::Sha256);
    std::array<std::byte, 32> out;
    std::memcpy(out.data(), d.constData(), 32);
    return out;
}

std::string CacheKey::hex() const
{
    const auto d = digest();
    return hexOf(d.data(), d.size());
}

// ---- GridCache ----

GridCache::GridCache(std::string dir) : m_dir(std::move(dir))
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
    auto entry = loadEntry(entryPath(key, 'd'), kKindDensity, key.digest(), whyMissed);
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
    storeEntry(path, headerFor(grid.geometry, kKindDensity, key), {&grid.density, grid.woodFraction.empty() ? &zeros : &grid.woodFraction});
}

std::optional<LightingGrid> GridCache::loadLighting(const CacheKey& key, std::string* whyMissed)
{
    auto entry = loadEntry(entryPath(key, 'l'), kKindLighting, key.digest(), whyMissed);
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
    storeEntry(path, headerFor(grid.geometry, kKindLighting, key), {&grid.rgb});
}

// ---- inspection ----

bool isCacheFile(const std::string& path)
{
    QFile file(QString::fromStdString(path));
    if (!file.open(QIODevice::ReadOnly)) return false;
    char magic[8];
    return file.read(magic, 8) == 8 && std::memcmp(magic, kEntryMagic, 8) == 0;
}

std::string describeCacheFile(const std::string& path)
{
    QFile file(QString::fromStdString(path));
    if (!file.open(QIODevice::ReadOnly)) throw Error(path + ": cannot open the file (" + file.errorString().toStdString() + ")");
    const uint64_t fileSize = uint64_t(file.size());
    unsigned char raw[kHeaderSize];
    const size_t got = readFully(file, raw, kHeaderSize, nullptr);
    if (got < 8 || std::memcmp(raw, kEntryMagic, 8) != 0) throw Error(path + ": not a Sylva grid cache file (bad magic)");

    std::ostringstream out;
    out.precision(17);
    out << path << ": Sylva grid cache entry\n";
    if (got < kHeaderSize) {
        out << "  damaged:   truncated (" << fileSize << " bytes, the header alone needs " << kHeaderSize << ")\n";
        return out.str();
    }
    const EntryHeader h = decodeHeader(raw);
    out << "  format:    version " << h.version;
    if (h.version != kCacheFormatVersion) {
        out << " (this build reads version " << kCacheFormatVersion << "; not decoded further)\n";
        return out.str();
    }
    out << "\n  kind:      " << kindName(h.kind) << "\n"
        << "  dims:      " << h.dims[0] << " x " << h.dims[1] << " x " << h.dims[2] << ", " << h.channels << " channels"
        << (h.kind == kKindDensity ? " (density, wood fraction)" : h.kind == kKindLighting ? " (R, G, B)" : "") << "\n"
        << "  origin:    (" << h.origin[0] << ", " << h.origin[1] << ", " << h.origin[2] << ") m\n"
        << "  spacing:   " << h.spacing << " m\n"
        << "  key:       " << hexOf(h.key.data(), h.key.size()) << "\n"
        << "  payload:   " << h.payloadBytes << " bytes\n";
    const uint64_t expected = expectedPayload(h);
    if (expected == 0 || expected != h.payloadBytes) {
        out << "  checksum:  not checked (the header is inconsistent: dims and channels need " << expected << " payload bytes)\n";
        return out.str();
    }
    if (fileSize != kHeaderSize + h.payloadBytes) {
        out << "  checksum:  not checked (" << (fileSize < kHeaderSize + h.payloadBytes ? "truncated: " : "oversized: ") << fileSize - kHeaderSize
            << " payload bytes in the file)\n";
        return out.str();
    }
    Xxh64 hash;
    hash.update(raw, kChecksumOffset);
    std::vector<char> buffer(size_t(4) << 20);
    uint64_t left = h.payloadBytes;
    while (left > 0) {
        const size_t chunk = size_t(std::min<uint64_t>(left, buffer.size()));
        if (readFully(file, buffer.data(), chunk, &hash) != chunk) break;
        left -= chunk;
    }
    const uint64_t computed = hash.digest();
    if (left > 0)
        out << "  checksum:  not checked (read error)\n";
    else if (computed == h.checksum)
        out << "  checksum:  ok (xxh64 " << hex64(h.checksum) << ")\n";
    else
        out << "  checksum:  MISMATCH (stored " << hex64(h.checksum) << ", computed " << hex64(computed) << "): the entry is corrupt\n";
    return out.str();
}

} // namespace sylva
