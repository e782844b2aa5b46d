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

#include <cctype>
#include <cerrno>
#include <csignal>
#include <cstdio>
#include <ctime>
#include <map>

#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>
#include <xxhash.h>

#include <QDir>
#include <QFile>
#include <QSettings>

#include "core/base/error.h"
#include "pipeline/io/atomic_file.h"

namespace sylva {

namespace fs = std::filesystem;

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

CacheKey::Digest canonical(XXH128_hash_t h)
{
    XXH128_canonical_t c;
    XXH128_canonicalFromHash(&c, h);
    CacheKey::Digest out;
    std::memcpy(out.data(), c.digest, out.size());
    return out;
}

// ---- entry header ----

constexpr char kEntryMagic[8] = {'S', 'Y', 'L', 'V', 'A', 'G', 'R', 'D'};
constexpr size_t kHeaderSize = 128;
constexpr size_t kKeyOffset = 64;
constexpr size_t kPayloadSizeOffset = 80;
constexpr size_t kChecksumOffset = 88;   // the checksum covers header bytes [0, 88) and the payload
constexpr uint32_t kKindDensity = 1;
constexpr uint32_t kKindLighting = 2;

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

struct LoadedEntry {
    EntryHeader header;
    std::vector<float> payload;
};

// Loads and verifies one entry. Every defect deletes the file and explains itself through whyMissed.
// The entry is read under a shared flock, which eviction respects; a hit sets its modification time
// (its last use, for the least-recently-used eviction).
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

// ---- GridCache ----

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

// ---- the folder: CACHEDIR.TAG, size limit, eviction, info and clean ----

namespace {

constexpr char kTagSignature[] = "Signature: 8a477f597d28d172789f06886806bc55";
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

} // namespace

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

namespace {

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

// ---- settings and sizes ----

uint64_t cacheSizeLimitSetting()
{
    const QSettings settings(QSettings::NativeFormat, QSettings::UserScope, QStringLiteral("Sylva"), QStringLiteral("sylva"));
    const QVariant value = settings.value(QStringLiteral("cache/maxSize"));
    if (!value.isValid()) return kDefaultCacheLimit;
    const std::string text = value.toString().trimmed().toLower().toStdString();
    if (text == "none" || text == "off" || text == "unlimited") return 0;
    const auto bytes = parseByteSize(text);
    return bytes ? *bytes : kDefaultCacheLimit;
}

void setCacheSizeLimitSetting(uint64_t bytes)
{
    QSettings settings(QSettings::NativeFormat, QSettings::UserScope, QStringLiteral("Sylva"), QStringLiteral("sylva"));
    settings.setValue(QStringLiteral("cache/maxSize"), bytes == 0 ? QStringLiteral("none") : QString::number(qulonglong(bytes)));
    settings.sync();
    if (settings.status() != QSettings::NoError) throw Error(settings.fileName().toStdString() + ": cannot write the settings");
}

std::string cacheSettingsPath()
{
    const QSettings settings(QSettings::NativeFormat, QSettings::UserScope, QStringLiteral("Sylva"), QStringLiteral("sylva"));
    return settings.fileName().toStdString();
}

namespace {

// The non-negative number a size or duration starts with ("1.5G", "30d"): its value and the unit text
// after it; false when the text does not start with one (signs refused).
bool leadingNumber(const std::string& t, double* value, std::string* unit)
{
    size_t used = 0;
    try {
        *value = std::stod(t, &used);
    } catch (...) {
        return false;
    }
    if (used == 0 || !std::isfinite(*value) || *value < 0.0 || t[0] == '-' || t[0] == '+') return false;
    *unit = t.substr(used);
    return true;
}

} // namespace

std::optional<uint64_t> parseByteSize(std::string_view text)
{
    std::string t(text);
    while (!t.empty() && std::isspace((unsigned char)t.back())) t.pop_back();
    double value = 0.0;
    std::string unit;
    if (!leadingNumber(t, &value, &unit)) return std::nullopt;
    while (!unit.empty() && unit.front() == ' ') unit.erase(unit.begin());
    for (char& c : unit) c = char(std::tolower((unsigned char)c));
    if (unit.size() >= 2 && unit.substr(unit.size() - 2) == "ib") unit.resize(unit.size() - 2);
    else if (unit.size() >= 2 && unit.back() == 'b') unit.pop_back();
    else if (unit == "b" || unit == "bytes") unit.clear();
    int shift = 0;
    if (unit.empty()) shift = 0;
    else if (unit == "k") shift = 10;
    else if (unit == "m") shift = 20;
    else if (unit == "g") shift = 30;
    else if (unit == "t") shift = 40;
    else return std::nullopt;
    const double bytes = std::ldexp(value, shift);
    if (bytes >= 18446744073709551616.0) return std::nullopt;
    return uint64_t(std::llround(bytes));
}

std::optional<int64_t> parseDuration(std::string_view text)
{
    const std::string t(text);
    double value = 0.0;
    std::string unit;
    if (!leadingNumber(t, &value, &unit)) return std::nullopt;
    double scale = 0.0;
    if (unit.empty() || unit == "d") scale = 86400.0;
    else if (unit == "s") scale = 1.0;
    else if (unit == "m" || unit == "min") scale = 60.0;
    else if (unit == "h") scale = 3600.0;
    else if (unit == "w") scale = 7 * 86400.0;
    else return std::nullopt;
    if (value * scale > 1e15) return std::nullopt;
    return int64_t(std::llround(value * scale));
}

std::string formatBytes(uint64_t bytes)
{
    if (bytes < 1024) return std::to_string(bytes) + (bytes == 1 ? " byte" : " bytes");
    static const char* units[] = {"KiB", "MiB", "GiB", "TiB", "PiB"};
    double v = double(bytes) / 1024.0;
    int u = 0;
    while (v >= 1024.0 && u < 4) {
        v /= 1024.0;
        ++u;
    }
    char text[32];
    std::snprintf(text, sizeof text, "%.2f %s", v, units[u]);
    return text;
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
