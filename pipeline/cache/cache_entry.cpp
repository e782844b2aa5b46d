// The grid cache's entry files (cache_entry.h): header encoding, load and store, inspection for `sylva info`.
#include "pipeline/cache/cache_entry.h"

#include <algorithm>
#include <bit>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <sstream>

#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>
#include <xxhash.h>

#include <QFile>

#include "core/base/error.h"
#include "pipeline/io/atomic_file.h"

namespace sylva {

namespace fs = std::filesystem;

namespace cache_format {
namespace {

// Streaming XXH3-64 (libxxhash): the digest equals xxh3() of the concatenated pieces.
class Xxh3Stream {
public:
    Xxh3Stream() : m_state(XXH3_createState())
    {
        if (!m_state || XXH3_64bits_reset(m_state) == XXH_ERROR) throw std::bad_alloc();
    }
    ~Xxh3Stream() { XXH3_freeState(m_state); }
    Xxh3Stream(const Xxh3Stream&) = delete;
    Xxh3Stream& operator=(const Xxh3Stream&) = delete;
    void update(const void* data, size_t size) { XXH3_64bits_update(m_state, data, size); }
    uint64_t digest() const { return XXH3_64bits_digest(m_state); }

private:
    XXH3_state_t* m_state;
};

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
    std::memcpy(out + kKeyOffset, h.key.data(), h.key.size());
    put(out + kPayloadSizeOffset, h.payloadBytes, 8);
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
    std::memcpy(h.key.data(), in + kKeyOffset, h.key.size());
    h.payloadBytes = get(in + kPayloadSizeOffset, 8);
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

std::string hex64(uint64_t v)
{
    static const char digits[] = "0123456789abcdef";
    std::string s(16, '0');
    for (int i = 15; i >= 0; --i, v >>= 4) s[size_t(i)] = digits[v & 0xf];
    return s;
}

// Reads exactly `size` bytes, feeding them to `hash` when given; returns the count actually read.
size_t readFully(QFile& file, void* data, size_t size, Xxh3Stream* hash)
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

} // namespace

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

std::optional<LoadedEntry> loadEntry(const std::string& path, uint32_t kind, const CacheKey::Digest& key, std::string* whyMissed,
                                     const std::function<void(const std::string&)>& lockedHook,
                                     const std::function<void(const std::string&)>& openedHook)
{
    auto miss = [&](const std::string& why) -> std::optional<LoadedEntry> {
        if (whyMissed) *whyMissed = why;
        return std::nullopt;
    };
    // Shared lock for the read; eviction takes the exclusive one, unlinks, then lets go. The file
    // opened may have lost its name before the lock was held: evicted, or replaced by a concurrent
    // store's rename. Open the name again then, so a replaced entry is read in its new version and
    // only a name that is gone is a miss (a bounded number of times: writers that keep replacing it
    // make this a miss, never a wait without end).
    QFile file(QString::fromStdString(path));
    struct stat st {};
    for (int attempt = 0;; ++attempt) {
        std::error_code ec;
        if (!fs::exists(path, ec)) return miss("no cache entry " + path);
        if (!file.open(QIODevice::ReadOnly)) {
            if (!fs::exists(path, ec)) return miss("no cache entry " + path);
            return miss("cannot read cache entry " + path + " (" + file.errorString().toStdString() + "); recomputing");
        }
        if (openedHook) openedHook(path);
        while (::flock(file.handle(), LOCK_SH) != 0 && errno == EINTR) {}
        if (::fstat(file.handle(), &st) != 0) return miss("cannot read cache entry " + path + " (fstat failed); recomputing");
        if (st.st_nlink > 0) break;
        file.close();
        if (attempt == 15) return miss("no cache entry " + path + " (replaced or evicted while opening it)");
    }
    if (lockedHook) lockedHook(path);

    auto reject = [&](const std::string& problem) -> std::optional<LoadedEntry> {
        file.close();
        std::error_code removeError;
        fs::remove(path, removeError);
        return miss("cache entry " + path + " is " + problem + "; recomputing");
    };

    const uint64_t fileSize = uint64_t(st.st_size);
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
    Xxh3Stream hash;
    hash.update(raw, kChecksumOffset);
    entry.payload.resize(size_t(h.payloadBytes / sizeof(float)));
    if (readFully(file, entry.payload.data(), size_t(h.payloadBytes), &hash) != h.payloadBytes)
        return reject("truncated (the payload could not be read in full)");
    if (hash.digest() != h.checksum) return reject("corrupt (checksum mismatch)");
    if constexpr (std::endian::native == std::endian::big)
        for (float& f : entry.payload) f = std::bit_cast<float>(__builtin_bswap32(std::bit_cast<uint32_t>(f)));
    (void)::futimens(file.handle(), nullptr);   // used now (best effort: a read-only cache still reads)
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
    Xxh3Stream hash;
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

uint32_t versionOf(const std::string& path)
{
    unsigned char raw[12];
    const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
    if (fd < 0) return 0;
    const ssize_t got = ::read(fd, raw, sizeof raw);
    ::close(fd);
    if (got != ssize_t(sizeof raw) || std::memcmp(raw, kEntryMagic, 8) != 0) return 0;
    return uint32_t(get(raw + 8, 4));
}

} // namespace cache_format

using namespace cache_format;

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
    Xxh3Stream hash;
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
        out << "  checksum:  ok (xxh3 " << hex64(h.checksum) << ")\n";
    else
        out << "  checksum:  MISMATCH (stored " << hex64(h.checksum) << ", computed " << hex64(computed) << "): the entry is corrupt\n";
    return out.str();
}

} // namespace sylva
