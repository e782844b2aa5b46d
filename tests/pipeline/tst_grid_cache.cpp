// Tests of the grid cache: keys, round trips, detection of damaged or stale entries, concurrent writers.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <cstring>
#include <ctime>
#include <filesystem>
#include <functional>
#include <mutex>
#include <thread>

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <QCoreApplication>
#include <QDir>
#include <QFile>
#include <QFileInfo>
#include <QProcess>
#include <QProcessEnvironment>
#include <QTest>

#include "core/base/error.h"
#include "pipeline/cache/grid_cache.h"
#include "pipeline/io/npy.h"

using namespace sylva;

namespace {

// Set in the environment of the child processes that concurrentWriters starts.
constexpr char kChildDirVariable[] = "SYLVA_TST_CACHE_CHILD_DIR";
constexpr char kChildValueVariable[] = "SYLVA_TST_CACHE_CHILD_VALUE";
constexpr int kChildRounds = 25;
constexpr int kChildGridEdge = 64;   // 64^3 x 3 floats: a 3 MiB entry

QString outDir()
{
    return QStringLiteral(SYLVA_TEST_OUTPUT "/tst_grid_cache");
}

DensityGrid makeDensity(glm::ivec3 dims, float seed)
{
    DensityGrid g;
    g.geometry.dims = dims;
    g.geometry.origin = {0.5, -1.25, 3.0};
    g.geometry.spacing = 0.0625;
    const size_t n = g.geometry.nodeCount();
    g.density.resize(n);
    g.woodFraction.resize(n);
    for (size_t i = 0; i < n; ++i) {
        g.density[i] = float(i % 97) / 97.0f + seed;
        g.woodFraction[i] = float(i % 13) / 13.0f;
    }
    return g;
}

LightingGrid makeLighting(glm::ivec3 dims, float value)
{
    LightingGrid g;
    g.geometry.dims = dims;
    g.geometry.origin = {-2.0, 0.0, 1.0};
    g.geometry.spacing = 0.125;
    g.rgb.assign(g.geometry.nodeCount() * 3, value);
    return g;
}

CacheKey keyFor(const char* mesh, double sigma)
{
    CacheKey key;
    key.add("cache format", int64_t(kCacheFormatVersion)).add("mesh", mesh).add("sigma_s", sigma).add("grid", int64_t(32));
    return key;
}

QByteArray readAll(const std::string& path)
{
    QFile f(QString::fromStdString(path));
    return f.open(QIODevice::ReadOnly) ? f.readAll() : QByteArray();
}

void writeAll(const std::string& path, const QByteArray& bytes)
{
    QFile f(QString::fromStdString(path));
    QVERIFY(f.open(QIODevice::WriteOnly | QIODevice::Truncate));
    QCOMPARE(f.write(bytes), bytes.size());
}

bool exists(const std::string& path)
{
    return QFile::exists(QString::fromStdString(path));
}

} // namespace

class TstGridCache : public QObject {
    Q_OBJECT

private:
    bool isChild() const { return qEnvironmentVariableIsSet(kChildDirVariable); }

    std::string freshDir(const char* name)
    {
        const QString dir = outDir() + QLatin1Char('/') + QLatin1String(name);
        QDir(dir).removeRecursively();
        return dir.toStdString();
    }

    // Stores an entry, lets `damage` edit its bytes, then expects a reported, deleting miss.
    void expectRejected(const char* name, const std::function<void(QByteArray&)>& damage, const QString& expected)
    {
        GridCache cache(freshDir(name));
        const CacheKey key = keyFor("tree.obj", 0.5);
        cache.storeDensity(key, makeDensity({6, 7, 8}, 0.0f));
        const std::string path = cache.entryPath(key, 'd');
        QByteArray bytes = readAll(path);
        damage(bytes);
        writeAll(path, bytes);
        std::string why;
        QVERIFY(!cache.loadDensity(key, &why));
        const QString message = QString::fromStdString(why);
        QVERIFY2(message.contains(expected), qPrintable(message));
        QVERIFY2(message.contains(QString::fromStdString(path)), qPrintable(message));
        QVERIFY2(message.contains(QStringLiteral("recomputing")), qPrintable(message));
        QVERIFY(!exists(path));
        // The next store heals the entry.
        cache.storeDensity(key, makeDensity({6, 7, 8}, 0.0f));
        QVERIFY(cache.loadDensity(key));
    }

private Q_SLOTS:
    void initTestCase()
    {
        // The size limit setting of this test, not the user's (QSettings reads XDG_CONFIG_HOME).
        qputenv("XDG_CONFIG_HOME", QFile::encodeName(outDir() + QStringLiteral("/config")));
        if (isChild()) return;
        QDir(outDir()).removeRecursively();
        QVERIFY(QDir().mkpath(outDir()));
    }

    void keyFields()
    {
        auto hexOf = [](auto build) {
            CacheKey k;
            build(k);
            return k.hex();
        };
        const std::string abc1 = hexOf([](CacheKey& k) { k.add("ab", "c"); });
        const std::string abc2 = hexOf([](CacheKey& k) { k.add("a", "bc"); });
        QVERIFY(abc1 != abc2);
        QVERIFY(hexOf([](CacheKey& k) { k.add("x", "ab").add("y", "c"); }) != hexOf([](CacheKey& k) { k.add("x", "a").add("y", "bc"); }));
        QCOMPARE(abc1, hexOf([](CacheKey& k) { k.add("ab", "c"); }));
        QCOMPARE(abc1.size(), size_t(32));
        QVERIFY(abc1.find_first_not_of("0123456789abcdef") == std::string::npos);
        QVERIFY(hexOf([](CacheKey& k) { k.add("n", 1.0); }) != hexOf([](CacheKey& k) { k.add("n", int64_t(1)); }));
        QCOMPARE(hexOf([](CacheKey& k) { k.add("n", -0.0); }), hexOf([](CacheKey& k) { k.add("n", 0.0); }));
        QVERIFY(hexOf([](CacheKey& k) { k.add("a", int64_t(1)).add("b", int64_t(2)); }) !=
                hexOf([](CacheKey& k) { k.add("b", int64_t(2)).add("a", int64_t(1)); }));
        const std::byte raw[3] = {std::byte{'a'}, std::byte{'b'}, std::byte{'c'}};
        const std::string spanKey = hexOf([&](CacheKey& k) { k.add("mesh", std::span<const std::byte>(raw)); });
        QVERIFY(spanKey != hexOf([](CacheKey& k) { k.add("mesh", "abc"); }));
        QCOMPARE(spanKey, hexOf([&](CacheKey& k) { k.add("mesh", std::span<const std::byte>(raw, 3)); }));
        QVERIFY(spanKey != hexOf([&](CacheKey& k) { k.add("mesh", std::span<const std::byte>(raw, 2)); }));
        // No fields: the XXH3-128 of no bytes, xxHash's published value (`xxhsum -H2 /dev/null`).
        QCOMPARE(CacheKey().hex(), std::string("99aa06d3014798d86001c324468d497f"));
        // Content keys: equal bytes give equal keys, one changed float anywhere gives another key.
        std::vector<float> grid(1 << 16);
        for (size_t i = 0; i < grid.size(); ++i) grid[i] = float(i % 251) * 0.25f;
        auto gridKey = [](const std::vector<float>& g) {
            CacheKey k;
            k.add("density", std::as_bytes(std::span<const float>(g)));
            return k.hex();
        };
        const std::string gridHex = gridKey(grid);
        QCOMPARE(gridKey(std::vector<float>(grid)), gridHex);
        for (size_t at : {size_t(0), grid.size() / 2, grid.size() - 1}) {
            std::vector<float> changed = grid;
            changed[at] = std::nextafter(changed[at], 1e9f);
            QVERIFY(gridKey(changed) != gridHex);
        }
        std::vector<float> shorter(grid.begin(), grid.end() - 1);
        QVERIFY(gridKey(shorter) != gridHex);
    }

    // XXH3-64 against xxHash's published value, and the checksum in an entry against XXH3-64 of the
    // file's header bytes [0, 88) and payload computed here from the bytes on disk.
    void checksumVectors()
    {
        QCOMPARE(xxh3("", 0), 0x2d06800538d394c2ull);
        GridCache cache(freshDir("checksum"), 0);
        const CacheKey key = keyFor("tree.obj", 0.5);
        cache.storeLighting(key, makeLighting({4, 5, 6}, 0.25f));
        const QByteArray bytes = readAll(cache.entryPath(key, 'l'));
        QCOMPARE(bytes.size(), qsizetype(128 + 4 * 5 * 6 * 3 * 4));
        QByteArray covered = bytes.left(88) + bytes.mid(128);
        uint64_t stored = 0;
        for (int b = 7; b >= 0; --b) stored = (stored << 8) | uint8_t(bytes[88 + b]);
        QCOMPARE(stored, xxh3(covered.constData(), size_t(covered.size())));
        // The key digest sits at 64..80, as CacheKey::digest() gives it.
        const auto digest = key.digest();
        QCOMPARE(bytes.mid(64, 16), QByteArray(reinterpret_cast<const char*>(digest.data()), 16));
    }

    void defaultDir()
    {
        const QByteArray saved = qgetenv("XDG_CACHE_HOME");
        qputenv("XDG_CACHE_HOME", "/tmp/sylva-xdg");
        QCOMPARE(GridCache().dir(), std::string("/tmp/sylva-xdg/sylva"));
        qunsetenv("XDG_CACHE_HOME");
        QCOMPARE(QString::fromStdString(GridCache().dir()), QDir::homePath() + QStringLiteral("/.cache/sylva"));
        qputenv("XDG_CACHE_HOME", "relative/path");   // not absolute: ignored, as the XDG spec says
        QCOMPARE(QString::fromStdString(GridCache().dir()), QDir::homePath() + QStringLiteral("/.cache/sylva"));
        if (saved.isNull()) qunsetenv("XDG_CACHE_HOME");
        else qputenv("XDG_CACHE_HOME", saved);
        QCOMPARE(GridCache("/somewhere").dir(), std::string("/somewhere"));
    }

    void roundTrip()
    {
        const std::string dir = freshDir("roundtrip") + "/not/yet/there";
        GridCache cache(dir);
        const CacheKey key = keyFor("tree.obj", 0.5);
        const DensityGrid d = makeDensity({5, 6, 7}, 0.25f);
        cache.storeDensity(key, d);
        QVERIFY(QDir(QString::fromStdString(dir)).exists());   // the entry folder was created
        std::string why;
        const auto loaded = cache.loadDensity(key, &why);
        QVERIFY2(loaded, why.c_str());
        QVERIFY(loaded->geometry == d.geometry);
        QVERIFY(loaded->density == d.density);
        QVERIFY(loaded->woodFraction == d.woodFraction);

        const LightingGrid l = makeLighting({4, 5, 6}, 0.75f);
        cache.storeLighting(key, l);
        const auto light = cache.loadLighting(key, &why);
        QVERIFY2(light, why.c_str());
        QVERIFY(light->geometry == l.geometry);
        QVERIFY(light->rgb == l.rgb);
        // Density and lighting of one key are separate entries.
        QVERIFY(cache.entryPath(key, 'd') != cache.entryPath(key, 'l'));
        QVERIFY(cache.loadDensity(key));

        // A grid without wood fraction comes back with zeros.
        DensityGrid bare = d;
        bare.woodFraction.clear();
        cache.storeDensity(key, bare);
        QVERIFY(cache.loadDensity(key)->woodFraction == std::vector<float>(d.density.size(), 0.0f));

        // Entries are exactly header + payload, and no temporary files remain.
        QCOMPARE(QFileInfo(QString::fromStdString(cache.entryPath(key, 'l'))).size(), qint64(128 + 4 * 5 * 6 * 3 * 4));
        const QStringList files = QFileInfo(QString::fromStdString(cache.entryPath(key, 'd'))).dir().entryList(QDir::Files | QDir::Hidden);
        QCOMPARE(files.size(), 2);

        QVERIFY_THROWS_EXCEPTION(Error, cache.storeLighting(key, LightingGrid{}));
        LightingGrid wrong = l;
        wrong.rgb.pop_back();
        QVERIFY_THROWS_EXCEPTION(Error, cache.storeLighting(key, wrong));
    }

    void missOnOtherKey()
    {
        GridCache cache(freshDir("miss"));
        cache.storeLighting(keyFor("tree.obj", 0.5), makeLighting({3, 3, 3}, 1.0f));
        std::string why;
        QVERIFY(!cache.loadLighting(keyFor("tree.obj", 0.6), &why));
        QVERIFY2(QString::fromStdString(why).contains(QStringLiteral("no cache entry")), why.c_str());
        QVERIFY(!cache.loadLighting(keyFor("bush.obj", 0.5)));
        QVERIFY(!cache.loadDensity(keyFor("tree.obj", 0.5)));
        QVERIFY(cache.loadLighting(keyFor("tree.obj", 0.5)));
    }

    void truncatedEntry()
    {
        expectRejected("truncated", [](QByteArray& b) { b.truncate(b.size() / 2); }, QStringLiteral("is truncated"));
        expectRejected("truncated-header", [](QByteArray& b) { b.truncate(100); }, QStringLiteral("is truncated"));
        expectRejected("empty", [](QByteArray& b) { b.clear(); }, QStringLiteral("is truncated"));
        expectRejected("trailing", [](QByteArray& b) { b.append("junk"); }, QStringLiteral("is corrupt"));
    }

    void flippedPayloadByte()
    {
        expectRejected("flip-payload", [](QByteArray& b) { b[b.size() - 1000] = char(b[b.size() - 1000] ^ 0x10); },
                       QStringLiteral("is corrupt (checksum mismatch)"));
        expectRejected("flip-origin", [](QByteArray& b) { b[40] = char(b[40] ^ 0x01); }, QStringLiteral("is corrupt (checksum mismatch)"));
        expectRejected("flip-checksum", [](QByteArray& b) { b[88] = char(b[88] ^ 0x80); }, QStringLiteral("is corrupt (checksum mismatch)"));
        expectRejected("flip-dims", [](QByteArray& b) { b[16] = char(b[16] + 1); }, QStringLiteral("is corrupt"));
        expectRejected("bad magic", [](QByteArray& b) { b[0] = 'X'; }, QStringLiteral("not a Sylva grid cache file"));
    }

    void wrongVersion()
    {
        expectRejected("version", [](QByteArray& b) { b[8] = char(kCacheFormatVersion + 1); },
                       QStringLiteral("of format version %1").arg(kCacheFormatVersion + 1));
    }

    void keyMismatch()
    {
        GridCache cache(freshDir("stale"));
        const CacheKey a = keyFor("tree.obj", 0.5), b = keyFor("tree.obj", 0.7);
        cache.storeDensity(a, makeDensity({4, 4, 4}, 0.0f));
        QVERIFY(QFile::copy(QString::fromStdString(cache.entryPath(a, 'd')), QString::fromStdString(cache.entryPath(b, 'd'))));
        std::string why;
        QVERIFY(!cache.loadDensity(b, &why));
        QVERIFY2(QString::fromStdString(why).contains(QStringLiteral("stale")), why.c_str());
        QVERIFY(!exists(cache.entryPath(b, 'd')));
        QVERIFY(cache.loadDensity(a));

        // A density entry where a lighting entry belongs is rejected too.
        QVERIFY(QFile::copy(QString::fromStdString(cache.entryPath(a, 'd')), QString::fromStdString(cache.entryPath(a, 'l'))));
        QVERIFY(!cache.loadLighting(a, &why));
        QVERIFY2(QString::fromStdString(why).contains(QStringLiteral("a density entry, not a lighting entry")), why.c_str());
        QVERIFY(!exists(cache.entryPath(a, 'l')));
    }

    void describe()
    {
        GridCache cache(freshDir("describe"));
        const CacheKey key = keyFor("tree.obj", 0.5);
        cache.storeLighting(key, makeLighting({4, 5, 6}, 0.5f));
        const std::string path = cache.entryPath(key, 'l');
        QVERIFY(isCacheFile(path));
        QString text = QString::fromStdString(describeCacheFile(path));
        QVERIFY2(text.contains(QStringLiteral("lighting")), qPrintable(text));
        QVERIFY2(text.contains(QStringLiteral("4 x 5 x 6, 3 channels")), qPrintable(text));
        QVERIFY2(text.contains(QString::fromStdString(key.hex())), qPrintable(text));
        QVERIFY2(text.contains(QStringLiteral("checksum:  ok")), qPrintable(text));

        QByteArray bytes = readAll(path);
        bytes[200] = char(bytes[200] ^ 1);
        writeAll(path, bytes);
        text = QString::fromStdString(describeCacheFile(path));
        QVERIFY2(text.contains(QStringLiteral("MISMATCH")), qPrintable(text));
        writeAll(path, bytes.left(300));
        text = QString::fromStdString(describeCacheFile(path));
        QVERIFY2(text.contains(QStringLiteral("truncated")), qPrintable(text));

        const std::string npy = outDir().toStdString() + "/describe.npy";
        writeNpy(npy, NpyArray{{3}, {1.0f, 2.0f, 3.0f}});
        QVERIFY(!isCacheFile(npy));
        QVERIFY(!isCacheFile(outDir().toStdString() + "/missing"));
        QVERIFY_THROWS_EXCEPTION(Error, describeCacheFile(npy));
        QVERIFY_THROWS_EXCEPTION(Error, describeCacheFile(outDir().toStdString() + "/missing"));
    }

    // A random sequence of stores and loads against a model of least-recently-used eviction kept
    // here: after every operation the entries on disk are exactly the model's and fit the limit.
    void evictionLeastRecentlyUsed()
    {
        const glm::ivec3 dims(6, 7, 8);
        const uint64_t entryBytes = 128 + uint64_t(6 * 7 * 8) * 3 * 4;
        const uint64_t limit = 4 * entryBytes + entryBytes / 2;   // room for four entries
        const std::string dir = freshDir("lru");
        GridCache cache(dir, limit);
        QCOMPARE(cache.maxBytes(), limit);
        std::vector<int> model;   // key numbers, least recently used first
        auto use = [&](int k) {
            model.erase(std::remove(model.begin(), model.end(), k), model.end());
            model.push_back(k);
        };
        uint32_t rng = 12345;
        auto next = [&](uint32_t n) {
            rng = rng * 1664525u + 1013904223u;
            return (rng >> 8) % n;
        };
        for (int op = 0; op < 40; ++op) {
            QTest::qWait(12);   // file times tick in jiffies: keep the uses apart
            const int k = int(next(8));
            const CacheKey key = keyFor("lru.obj", double(k));
            const bool present = std::find(model.begin(), model.end(), k) != model.end();
            if (next(2) == 0) {
                cache.storeLighting(key, makeLighting(dims, float(k)));
                use(k);
                while (model.size() > 4) model.erase(model.begin());
            } else {
                const auto hit = cache.loadLighting(key);
                QCOMPARE(bool(hit), present);
                if (hit) {
                    QCOMPARE(hit->rgb.front(), float(k));
                    use(k);
                }
            }
            const GridCache::Summary sum = cache.summary();
            QVERIFY2(sum.bytes <= limit, qPrintable(QString::number(sum.bytes)));
            std::vector<int> onDisk;
            for (int j = 0; j < 8; ++j)
                if (exists(cache.entryPath(keyFor("lru.obj", double(j)), 'l'))) onDisk.push_back(j);
            std::vector<int> expected = model;
            std::sort(expected.begin(), expected.end());
            QVERIFY2(onDisk == expected, qPrintable(QStringLiteral("op %1").arg(op)));
            // summary() lists them oldest use first, as the model does.
            QCOMPARE(sum.entries.size(), model.size());
            for (size_t i = 0; i < model.size(); ++i)
                QCOMPARE(QString::fromStdString(sum.entries[i].path), QString::fromStdString(cache.entryPath(keyFor("lru.obj", double(model[i])), 'l')));
        }
        // An entry larger than the limit is refused and nothing is written.
        const CacheKey big = keyFor("big.obj", 1.0);
        QVERIFY_THROWS_EXCEPTION(Error, cache.storeLighting(big, makeLighting({20, 20, 20}, 1.0f)));
        QVERIFY(!exists(cache.entryPath(big, 'l')));
    }

    // While one load holds the oldest entry (stopped inside the read), stores past the limit evict
    // the others, never that one; the load then returns the whole grid and marks it used.
    void evictionSparesEntryBeingRead()
    {
        const glm::ivec3 dims(6, 7, 8);
        const uint64_t entryBytes = 128 + uint64_t(6 * 7 * 8) * 3 * 4;
        const std::string dir = freshDir("busy");
        GridCache writer(dir, 2 * entryBytes + entryBytes / 2);
        GridCache reader(dir, 0);
        const CacheKey a = keyFor("a.obj", 1.0), b = keyFor("b.obj", 1.0), c = keyFor("c.obj", 1.0), d = keyFor("d.obj", 1.0),
                       e = keyFor("e.obj", 1.0);
        writer.storeLighting(a, makeLighting(dims, 1.0f));
        QTest::qWait(12);
        writer.storeLighting(b, makeLighting(dims, 2.0f));
        QTest::qWait(12);

        std::mutex m;
        std::condition_variable cv;
        bool locked = false, release = false;
        reader.setReadHookForTests([&](const std::string&) {
            std::unique_lock lock(m);
            locked = true;
            cv.notify_all();
            cv.wait(lock, [&] { return release; });
        });
        std::optional<LightingGrid> got;
        std::thread thread([&] { got = reader.loadLighting(a); });
        {
            std::unique_lock lock(m);
            QVERIFY(cv.wait_for(lock, std::chrono::seconds(10), [&] { return locked; }));
        }
        writer.storeLighting(c, makeLighting(dims, 3.0f));   // a (oldest) is busy: b goes
        QTest::qWait(12);
        writer.storeLighting(d, makeLighting(dims, 4.0f));   // a still busy: c goes
        QVERIFY(exists(writer.entryPath(a, 'l')));
        QVERIFY(!exists(writer.entryPath(b, 'l')));
        QVERIFY(!exists(writer.entryPath(c, 'l')));
        QVERIFY(exists(writer.entryPath(d, 'l')));
        GridCache::CleanOptions all;
        const GridCache::CleanResult r = GridCache(dir, 0).clean(all);   // clean skips it too
        QCOMPARE(r.busy, size_t(1));
        QVERIFY(exists(writer.entryPath(a, 'l')));
        QVERIFY(!exists(writer.entryPath(d, 'l')));
        {
            std::lock_guard lock(m);
            release = true;
        }
        cv.notify_all();
        thread.join();
        QVERIFY(got);
        QCOMPARE(got->rgb, makeLighting(dims, 1.0f).rgb);
        QVERIFY(exists(writer.entryPath(a, 'l')));
    }

    // A load that opened an entry just before a concurrent store renamed a new version over it (the
    // opened file lost its name) reads the new version: the entry was replaced, not evicted. Only a
    // name that is gone is a miss.
    void entryReplacedWhileOpening()
    {
        const glm::ivec3 dims(5, 4, 3);
        const std::string dir = freshDir("replaced");
        GridCache reader(dir, 0);
        GridCache writer(dir, 0);
        const CacheKey key = keyFor("tree.obj", 1.0);
        writer.storeLighting(key, makeLighting(dims, 1.0f));
        int opens = 0;
        reader.setOpenHookForTests([&](const std::string&) {
            if (++opens == 1) writer.storeLighting(key, makeLighting(dims, 2.0f));
        });
        std::string why;
        const auto got = reader.loadLighting(key, &why);
        QVERIFY2(got, why.c_str());
        QCOMPARE(opens, 2);   // the first file opened had been replaced: opened again
        QCOMPARE(got->rgb, makeLighting(dims, 2.0f).rgb);

        // Evicted while opening (the name removed, none put back): a miss that says so.
        opens = 0;
        reader.setOpenHookForTests([&](const std::string& path) {
            ++opens;
            std::error_code ec;
            std::filesystem::remove(path, ec);
        });
        QVERIFY(!reader.loadLighting(key, &why));
        QCOMPARE(opens, 1);
        QVERIFY2(QString::fromStdString(why).startsWith(QStringLiteral("no cache entry")), why.c_str());
    }

    void folderTagAndClean()
    {
        const std::string dir = freshDir("clean");
        GridCache cache(dir, 0);
        const glm::ivec3 dims(4, 4, 4);
        const CacheKey fresh = keyFor("fresh.obj", 1.0), old = keyFor("old.obj", 1.0), older = keyFor("older.obj", 1.0);
        cache.storeLighting(fresh, makeLighting(dims, 1.0f));
        cache.storeLighting(old, makeLighting(dims, 2.0f));
        cache.storeDensity(older, makeDensity(dims, 3.0f));
        // CACHEDIR.TAG: the signature line the specification fixes, first.
        const QByteArray tag = readAll(dir + "/CACHEDIR.TAG");
        QVERIFY(tag.startsWith("Signature: 8a477f597d28d172789f06886806bc55"));
        // Last uses 3 and 10 days ago.
        const auto age = [](const std::string& path, int days) {
            const std::time_t t = std::time(nullptr) - std::time_t(days) * 86400;
            struct timespec times[2] = {{t, 0}, {t, 0}};
            return ::utimensat(AT_FDCWD, path.c_str(), times, 0) == 0;
        };
        QVERIFY(age(cache.entryPath(old, 'l'), 3));
        QVERIFY(age(cache.entryPath(older, 'd'), 10));
        // A version 1 entry (SHA-256 name), a sidecar, a dead writer's temporary file and a live one.
        const std::string grids = dir + "/grids/";
        QByteArray v1 = readAll(cache.entryPath(fresh, 'l'));
        v1[8] = 1;
        writeAll(grids + std::string(64, 'a') + ".l.sgrid", v1);
        writeAll(cache.entryPath(older, 'd') + ".seconds", "12.5\n");
        writeAll(grids + ".tmp.999999999.0.x.l.sgrid", QByteArray(100, 'x'));
        const std::string live = grids + ".tmp." + std::to_string(::getpid()) + ".7.y.l.sgrid";
        writeAll(live, QByteArray(50, 'y'));

        GridCache::Summary sum = cache.summary();
        QCOMPARE(sum.lighting, size_t(2));
        QCOMPARE(sum.density, size_t(1));
        QCOMPARE(sum.otherVersion, size_t(1));
        QCOMPARE(sum.tempFiles, size_t(2));
        uint64_t onDisk = 0;
        for (const QFileInfo& f : QDir(QString::fromStdString(grids)).entryInfoList(QDir::Files | QDir::Hidden)) onDisk += uint64_t(f.size());
        QCOMPARE(sum.bytes, onDisk);
        QCOMPARE(QString::fromStdString(sum.entries.front().path), QString::fromStdString(cache.entryPath(older, 'd')));

        // Older than 5 days: the 10-day entry with its sidecar, the old version, the dead writer's file.
        GridCache::CleanOptions byAge;
        byAge.olderThanSeconds = 5 * 86400;
        GridCache::CleanResult r = cache.clean(byAge);
        QCOMPARE(r.removed, size_t(3));
        QVERIFY(!exists(cache.entryPath(older, 'd')) && !exists(cache.entryPath(older, 'd') + ".seconds"));
        QVERIFY(!exists(grids + ".tmp.999999999.0.x.l.sgrid"));
        QVERIFY(exists(live));
        QVERIFY(exists(cache.entryPath(old, 'l')) && exists(cache.entryPath(fresh, 'l')));
        QCOMPARE(r.kept, size_t(2));
        // Down to one entry's size: the least recently used (3 days) goes.
        GridCache::CleanOptions bySize;
        bySize.maxBytes = uint64_t(QFileInfo(QString::fromStdString(cache.entryPath(fresh, 'l'))).size());
        r = cache.clean(bySize);
        QCOMPARE(r.removed, size_t(1));
        QVERIFY(!exists(cache.entryPath(old, 'l')) && exists(cache.entryPath(fresh, 'l')));
        // No option: every entry.
        r = cache.clean({});
        QCOMPARE(r.removed, size_t(1));
        QCOMPARE(r.kept, size_t(0));
        QVERIFY(!exists(cache.entryPath(fresh, 'l')));
        QVERIFY(exists(live));   // a writer that still runs keeps its file
    }

    void sizesAndDurations()
    {
        QCOMPARE(parseByteSize("4096"), std::optional<uint64_t>(4096));
        QCOMPARE(parseByteSize("20G"), std::optional<uint64_t>(uint64_t(20) << 30));
        QCOMPARE(parseByteSize("512M"), std::optional<uint64_t>(uint64_t(512) << 20));
        QCOMPARE(parseByteSize("1.5GiB"), std::optional<uint64_t>(uint64_t(3) << 29));
        QCOMPARE(parseByteSize("2 kb"), std::optional<uint64_t>(2048));
        QCOMPARE(parseByteSize("1T"), std::optional<uint64_t>(uint64_t(1) << 40));
        for (const char* bad : {"", "G", "-1G", "12X", "1e30T", "nan"}) QVERIFY2(!parseByteSize(bad), bad);
        QCOMPARE(parseDuration("30d"), std::optional<int64_t>(30 * 86400));
        QCOMPARE(parseDuration("7"), std::optional<int64_t>(7 * 86400));
        QCOMPARE(parseDuration("12h"), std::optional<int64_t>(12 * 3600));
        QCOMPARE(parseDuration("90m"), std::optional<int64_t>(90 * 60));
        QCOMPARE(parseDuration("45s"), std::optional<int64_t>(45));
        QCOMPARE(parseDuration("2w"), std::optional<int64_t>(14 * 86400));
        for (const char* bad : {"", "d", "-3d", "3y", "1e20"}) QVERIFY2(!parseDuration(bad), bad);
        QCOMPARE(formatBytes(1000), std::string("1000 bytes"));
        QCOMPARE(formatBytes(1536), std::string("1.50 KiB"));
        QCOMPARE(formatBytes(uint64_t(20) << 30), std::string("20.00 GiB"));
        // The setting: unset gives the default, a size or "none" as written.
        QCOMPARE(cacheSizeLimitSetting(), kDefaultCacheLimit);
        setCacheSizeLimitSetting(uint64_t(3) << 20);
        QCOMPARE(cacheSizeLimitSetting(), uint64_t(3) << 20);
        QCOMPARE(GridCache(freshDir("setting")).maxBytes(), uint64_t(3) << 20);
        setCacheSizeLimitSetting(0);
        QCOMPARE(cacheSizeLimitSetting(), uint64_t(0));
        QVERIFY(QString::fromStdString(cacheSettingsPath()).startsWith(outDir() + QStringLiteral("/config/")));
        QFile::remove(QString::fromStdString(cacheSettingsPath()));
    }

    // Child processes store the same key many times while this process keeps loading it: every
    // load is a clean miss or a whole entry from one writer, and one valid entry remains.
    void concurrentWriters()
    {
        if (isChild()) QSKIP("runs in the parent process only");
        const std::string dir = freshDir("concurrent");
        const CacheKey key = keyFor("forest.obj", 1.5);
        const glm::ivec3 dims(kChildGridEdge);
        QList<QProcess*> children;
        for (int c = 0; c < 3; ++c) {
            auto* child = new QProcess(this);
            QProcessEnvironment env = QProcessEnvironment::systemEnvironment();
            env.insert(QLatin1String(kChildDirVariable), QString::fromStdString(dir));
            env.insert(QLatin1String(kChildValueVariable), QString::number(c + 1));
            child->setProcessEnvironment(env);
            child->setProcessChannelMode(QProcess::MergedChannels);
            child->start(QCoreApplication::applicationFilePath(), {QStringLiteral("concurrentWriterChild")});
            QVERIFY2(child->waitForStarted(), qPrintable(child->errorString()));
            children << child;
        }
        // Whatever happens below, no child outlives this test.
        struct Reaper {
            QList<QProcess*>& children;
            ~Reaper()
            {
                for (QProcess* c : children) {
                    if (c->state() != QProcess::NotRunning) {
                        c->kill();
                        c->waitForFinished(5000);
                    }
                }
            }
        } reaper{children};
        GridCache cache(dir);
        int hits = 0, loads = 0;
        auto running = [&] {
            for (QProcess* c : children)
                if (c->state() != QProcess::NotRunning) return true;
            return false;
        };
        while (running()) {
            std::string why;
            ++loads;
            if (auto g = cache.loadLighting(key, &why)) {
                ++hits;
                QCOMPARE(g->geometry.dims, dims);
                const float first = g->rgb.front();
                QVERIFY(first == 1.0f || first == 2.0f || first == 3.0f);
                QVERIFY(std::all_of(g->rgb.begin(), g->rgb.end(), [&](float v) { return v == first; }));
            } else {
                QVERIFY2(QString::fromStdString(why).startsWith(QStringLiteral("no cache entry")), why.c_str());
            }
            for (QProcess* c : children) c->waitForFinished(1);
        }
        for (QProcess* c : children) {
            QVERIFY2(c->exitStatus() == QProcess::NormalExit && c->exitCode() == 0, c->readAll().constData());
        }
        qInfo("%d of %d loads during the writes were hits", hits, loads);
        std::string why;
        const auto final = cache.loadLighting(key, &why);
        QVERIFY2(final, why.c_str());
        QCOMPARE(final->geometry.dims, dims);
        const QStringList files = QFileInfo(QString::fromStdString(cache.entryPath(key, 'l'))).dir().entryList(QDir::Files | QDir::Hidden);
        QVERIFY2(files.size() == 1, qPrintable(files.join(QLatin1Char(' '))));   // no temporary files left behind
    }

    // The body of a concurrentWriters child (started with this slot's name); skipped otherwise.
    void concurrentWriterChild()
    {
        if (!isChild()) QSKIP("runs only as a child process of concurrentWriters");
        GridCache cache(qEnvironmentVariable(kChildDirVariable).toStdString());
        const float value = qEnvironmentVariable(kChildValueVariable).toFloat();
        const LightingGrid grid = makeLighting(glm::ivec3(kChildGridEdge), value);
        const CacheKey key = keyFor("forest.obj", 1.5);
        for (int round = 0; round < kChildRounds; ++round) {
            cache.storeLighting(key, grid);
            if (round % 5 == 0) {
                std::string why;
                const auto g = cache.loadLighting(key, &why);
                QVERIFY2(g, why.c_str());
            }
        }
    }
};

QTEST_GUILESS_MAIN(TstGridCache)
#include "tst_grid_cache.moc"
