// Cryptomatte (Jonah Friedman, Andrew C. Jones, Psyop, "Cryptomatte" specification): MurmurHash3_x86_32 against
// published test vectors, the specification's example IDs and an independent byte-by-byte implementation; the
// float conversion's exponent clamp; and the mattes of `--passes` EXRs, read back with OpenImageIO as a
// compositor reads them, against the share of each pixel's camera samples that hit a card, its triangle or the
// ground by the test's own ray-plane intersections (tests/common/matte_scene.h).
#include <QProcess>
#include <QTemporaryDir>
#include <QTest>

#include <cmath>
#include <cstring>
#include <random>

#include "core/base/error.h"
#include "core/render/cryptomatte.h"
#include "core/render/render_cpu.h"
#include "pipeline/grow/obj_writer.h"
#include "pipeline/render/frame_build.h"
#include "pipeline/render/render_job.h"
#include "pipeline/render/render_passes.h"
#include "pipeline/scene/scene_file.h"
#include "pipeline/services/exports.h"
#include "tests/common/matte_scene.h"
#include "tests/common/run_program.h"

using namespace sylva;

namespace {

// MurmurHash3_x86_32 written from its description a byte at a time: each byte is shifted into a 32-bit
// word, low byte first; four bytes make a block that is mixed into the state; a final 1-3 byte tail is
// mixed without the state's rotation; then the length and the final avalanche.
uint32_t referenceMurmur(const std::string& bytes, uint32_t seed)
{
    auto rotl = [](uint32_t x, unsigned r) { return uint32_t(x << r | x >> (32u - r)); };
    auto scramble = [&](uint32_t k) { return uint32_t(rotl(uint32_t(k * 0xcc9e2d51u), 15) * 0x1b873593u); };
    uint32_t h = seed, word = 0;
    unsigned filled = 0;
    for (char c : bytes) {
        word |= uint32_t(static_cast<unsigned char>(c)) << (8 * filled);
        if (++filled == 4) {
            h = rotl(h ^ scramble(word), 13) * 5u + 0xe6546b64u;
            word = 0;
            filled = 0;
        }
    }
    if (filled) h ^= scramble(word);
    h ^= uint32_t(bytes.size());
    h = (h ^ (h >> 16)) * 0x85ebca6bu;
    h = (h ^ (h >> 13)) * 0xc2b2ae35u;
    return h ^ (h >> 16);
}

uint32_t bitsOf(float f)
{
    uint32_t b;
    std::memcpy(&b, &f, 4);
    return b;
}

// The two-card scene's frame with its mattes, written as `sylva render --passes` writes it.
void writeMatteExr(const Scene& sc, const QString& path)
{
    const RenderScene rs = buildRenderScene(sc, test::matteAssets(), sunRadiance(sc.sun));
    const Film film = renderFilm(rs.view());
    const MatteFilm mattes = renderMatteFilm(rs.view());
    writeRenderFilm(path.toStdString(), film, sc, true, &mattes);
}

// Each matte of the file against the share of each pixel's samples that the test's intersections give
// (pixels where a sample passes within 1e-4 of an edge are left out): the aspen (near card), the spruce (far
// card) and the ground by asset, object and material, the spruce's leaf and bark triangles by material; every
// type's coverage plus the sky's share sums to 1. Returns the pixels compared and those with a partial matte.
void checkMattes(const Scene& sc, const QString& path, int* compared, int* partial)
{
    *compared = *partial = 0;
    const test::ExrCryptomatte object = test::readCryptomatte(path.toStdString(), "CryptoObject");
    const test::ExrCryptomatte material = test::readCryptomatte(path.toStdString(), "CryptoMaterial");
    const test::ExrCryptomatte asset = test::readCryptomatte(path.toStdString(), "CryptoAsset");
    for (const test::ExrCryptomatte* c : {&object, &material, &asset}) {
        QVERIFY2(c->error.empty(), c->error.c_str());
        QCOMPARE(c->hash, std::string("MurmurHash3_32"));
        QCOMPARE(c->conversion, std::string("uint32_to_float32"));
        QCOMPARE(c->ranks, 6);   // 00, 01, 02: no pixel sees more than 6 names here
        QCOMPARE(c->width, sc.render.width);
        QCOMPARE(c->height, sc.render.height);
    }
    QCOMPARE(object.key, cryptomatteKey("CryptoObject"));
    // The manifests: every name the frame shows, with its ID's 8 hex digits.
    const std::map<std::string, std::string> wantObjects = {{"aspen.0", ""}, {"spruce.1", ""}, {"ground", ""}};
    for (const auto& [name, ignored] : wantObjects) QVERIFY2(object.manifest.count(name), name.c_str());
    QCOMPARE(object.manifest.size(), size_t(3));
    QCOMPARE(material.manifest.size(), size_t(4));   // aspen/leaf, spruce/leaf, spruce/bark, ground
    QCOMPARE(asset.manifest.size(), size_t(3));      // aspen, spruce, ground
    for (const auto& [name, hex] : material.manifest) QCOMPARE(hex, cryptomatteHex(cryptomatteId(referenceMurmur(name, 0))));

    const std::vector<float> aspen = asset.matte({"aspen"}), spruce = asset.matte({"spruce"}), ground = asset.matte({"ground"});
    const std::vector<float> aspenObject = object.matte({"aspen.0"}), spruceObject = object.matte({"spruce.1"});
    const std::vector<float> aspenLeaf = material.matte({"aspen/leaf"}), spruceLeaf = material.matte({"spruce/leaf"});
    const std::vector<float> spruceBark = material.matte({"spruce/bark"}), groundMaterial = material.matte({"ground"});
    const std::vector<float> wholeSpruce = material.matte({"spruce/leaf", "spruce/bark"});
    const int w = sc.render.width, h = sc.render.height, spp = sc.render.spp;
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            const size_t p = size_t(y) * size_t(w) + size_t(x);
            int count[5] = {0, 0, 0, 0, 0};   // sky, ground, near card, far leaf, far bark
            bool edge = false;
            for (int s = 0; s < spp; ++s) {
                bool e = false;
                ++count[test::matteTruth(sc, x, y, s, &e) + 1];
                edge |= e;
            }
            // Coverage of every type + the sky's share = 1, whatever the edges.
            for (const test::ExrCryptomatte* c : {&object, &material, &asset}) {
                double sum = 0.0, previous = INFINITY;
                for (int r = 0; r < c->ranks; ++r) {
                    const auto& pr = c->pairs[p * size_t(c->ranks) + size_t(r)];
                    sum += pr[1];
                    QVERIFY2(pr[1] <= previous, "ranks not in descending coverage");
                    previous = pr[1];
                    if (pr[1] == 0.0f) QCOMPARE(pr[0], 0.0f);   // an unused rank is (0, 0)
                }
                const double sky = edge ? -1.0 : double(count[0]) / spp;
                if (sky >= 0.0 && std::abs(sum + sky - 1.0) > 1e-6)
                    QFAIL(qPrintable(QString("pixel %1,%2: coverage %3 + sky %4").arg(x).arg(y).arg(sum).arg(sky)));
            }
            if (edge) continue;
            ++*compared;
            const auto check = [&](const char* what, const std::vector<float>& matte, int samples) {
                const float want = float(samples) / float(spp);
                if (std::abs(matte[p] - want) > 1e-6f)
                    QFAIL(qPrintable(QString("pixel %1,%2: %3 matte %4, %5 of %6 samples hit it").arg(x).arg(y).arg(what).arg(matte[p]).arg(samples).arg(spp)));
            };
            check("aspen (asset)", aspen, count[2]);
            check("aspen.0 (object)", aspenObject, count[2]);
            check("aspen/leaf (material)", aspenLeaf, count[2]);
            check("spruce (asset)", spruce, count[3] + count[4]);
            check("spruce.1 (object)", spruceObject, count[3] + count[4]);
            check("spruce/leaf + spruce/bark (materials)", wholeSpruce, count[3] + count[4]);
            check("spruce/leaf (material)", spruceLeaf, count[3]);
            check("spruce/bark (material)", spruceBark, count[4]);
            check("ground (asset)", ground, count[1]);
            check("ground (material)", groundMaterial, count[1]);
            if (QTest::currentTestFailed()) return;
            for (const std::vector<float>* m : {&aspen, &spruce, &ground})
                if ((*m)[p] > 0.0f && (*m)[p] < 1.0f) ++*partial;
        }
}

} // namespace

class TestCryptomatte : public QObject {
    Q_OBJECT

    QTemporaryDir m_dir;

private Q_SLOTS:
    // Published MurmurHash3_x86_32 vectors (empty input, zero bytes, every tail length, seeds 0, 1, ~0 and
    // 0x9747b28c), then 5000 random byte strings of 0-40 bytes with random seeds against the byte-by-byte
    // implementation above.
    void murmurHash3Vectors()
    {
        const struct {
            std::string bytes;
            uint32_t seed, hash;
        } vectors[] = {
            {"", 0u, 0u},
            {"", 1u, 0x514E28B7u},
            {"", 0xffffffffu, 0x81F16F39u},
            {std::string("\0\0\0\0", 4), 0u, 0x2362F9DEu},
            {std::string("\0\0\0", 3), 0u, 0x85F0B427u},
            {std::string("\0\0", 2), 0u, 0x30F4C306u},
            {std::string("\0", 1), 0u, 0x514E28B7u},
            {"\xff\xff\xff\xff", 0u, 0x76293B50u},
            {"\x21\x43\x65\x87", 0u, 0xF55B516Bu},
            {"\x21\x43\x65\x87", 0x5082EDEEu, 0x2362F9DEu},
            {"\x21\x43\x65", 0u, 0x7E4A8634u},
            {"\x21\x43", 0u, 0xA0F7B07Au},
            {"\x21", 0u, 0x72661CF4u},
            {"aaaa", 0x9747b28cu, 0x5A97808Au},
            {"aaa", 0x9747b28cu, 0x283E0130u},
            {"aa", 0x9747b28cu, 0x5D211726u},
            {"a", 0x9747b28cu, 0x7FA09EA6u},
            {"abcd", 0x9747b28cu, 0xF0478627u},
            {"abc", 0x9747b28cu, 0xC84A62DDu},
            {"ab", 0x9747b28cu, 0x74875592u},
            {"Hello, world!", 0x9747b28cu, 0x24884CBAu},
            {"The quick brown fox jumps over the lazy dog", 0x9747b28cu, 0x2FA826CDu},
        };
        for (const auto& v : vectors) {
            QCOMPARE(murmurHash3(v.bytes, v.seed), v.hash);
            QCOMPARE(referenceMurmur(v.bytes, v.seed), v.hash);
        }
        std::mt19937 rng(7);
        for (int i = 0; i < 5000; ++i) {
            std::string s(size_t(rng() % 41), '\0');
            for (char& c : s) c = char(rng() & 0xffu);
            const uint32_t seed = i % 2 ? uint32_t(rng()) : 0u;
            QCOMPARE(murmurHash3(s, seed), referenceMurmur(s, seed));
        }
    }

    // The specification's manifest examples: "bunny" 13851a76, "default" 42c9679f, "bunny_porcelain_mat"
    // b24b26d4 (name -> MurmurHash3, seed 0 -> float ID -> its bits in hex); the metadata key is the first 7
    // hex digits of the type name's hash.
    void specificationExamples()
    {
        QCOMPARE(cryptomatteHex(cryptomatteId(murmurHash3("bunny"))), std::string("13851a76"));
        QCOMPARE(cryptomatteHex(cryptomatteId(murmurHash3("default"))), std::string("42c9679f"));
        QCOMPARE(cryptomatteHex(cryptomatteId(murmurHash3("bunny_porcelain_mat"))), std::string("b24b26d4"));
        for (const char* type : {"CryptoObject", "CryptoMaterial", "CryptoAsset"}) {
            char hex[9];
            std::snprintf(hex, sizeof hex, "%08x", referenceMurmur(type, 0));
            QCOMPARE(cryptomatteKey(type), std::string(hex, 7));
        }
        QCOMPARE(cryptomatteKey("CryptoObject"), std::string("3ae39a5"));
    }

    // uint32_to_float32: the hash's bits with the exponent clamped to [1, 254]: never zero, denormal, infinite
    // or NaN; sign and mantissa kept; hashes already in range unchanged.
    void floatConversion()
    {
        QCOMPARE(bitsOf(cryptomatteId(0u)), 0x00800000u);
        QCOMPARE(bitsOf(cryptomatteId(0xffffffffu)), 0xff7fffffu);
        QCOMPARE(bitsOf(cryptomatteId(0x7f800000u)), 0x7f000000u);   // would be +inf
        QCOMPARE(bitsOf(cryptomatteId(0x80000001u)), 0x80800001u);   // would be a negative denormal
        QCOMPARE(bitsOf(cryptomatteId(0x3f800000u)), 0x3f800000u);   // 1.0: in range
        std::mt19937 rng(11);
        for (int i = 0; i < 100000; ++i) {
            const uint32_t h = uint32_t(rng());
            const float f = cryptomatteId(h);
            QVERIFY(std::isnormal(f));
            const uint32_t e = (h >> 23) & 0xffu;
            if (e >= 1 && e <= 254) QCOMPARE(bitsOf(f), h);
            else QCOMPARE(bitsOf(f) & 0x807fffffu, h & 0x807fffffu);
        }
    }

    // The mattes of an EXR written by the passes' writer at 16 samples per pixel against the test's own
    // intersections (checkMattes), and anti-aliased: many pixels have a partial matte.
    void mattesMatchSampleShares()
    {
        QVERIFY(m_dir.isValid());
        const Scene sc = test::matteScene(16);
        const QString path = m_dir.filePath("mattes.exr");
        writeMatteExr(sc, path);
        int compared = 0, partial = 0;
        checkMattes(sc, path, &compared, &partial);
        if (QTest::currentTestFailed()) return;
        const int pixels = sc.render.width * sc.render.height;
        qInfo("%d of %d pixels compared, %d with a partial matte", compared, pixels, partial);
        QVERIFY2(compared > pixels * 9 / 10, qPrintable(QString::number(compared)));
        QVERIFY2(partial > 30, qPrintable(QString::number(partial)));
    }

    // One sample per pixel: every matte is 0 or 1, and where the sky is seen all ranks are (0, 0).
    void oneSampleIsBinary()
    {
        const Scene sc = test::matteScene(1);
        const QString path = m_dir.filePath("one.exr");
        writeMatteExr(sc, path);
        int compared = 0, partial = 0;
        checkMattes(sc, path, &compared, &partial);
        if (QTest::currentTestFailed()) return;
        QCOMPARE(partial, 0);
        QVERIFY(compared > sc.render.width * sc.render.height * 9 / 10);
    }

    // More names in a pixel than the default 6 ranks: the writer adds rank layers (up to 16 ranks) so the
    // coverage still sums to the pixel's share of hits; past 16 the smallest are dropped.
    void ranksGrowWithNames()
    {
        MatteFilm film;
        film.width = 1;
        film.height = 1;
        film.start = {0, 9};
        std::vector<float> ids;
        for (uint32_t i = 0; i < 9; ++i) {
            MatteHit h;
            h.object = i;
            film.hits.push_back(h);
            film.entries.push_back({i, 0.1f + 0.001f * float(i)});
            ids.push_back(cryptomatteId(murmurHash3("plant." + std::to_string(i))));
        }
        const CryptomatteRanks r = rankCryptomatte(film, ids);
        QCOMPARE(r.ranks, 10);
        for (int k = 0; k < 9; ++k) {
            QCOMPARE(r.pairs[size_t(2 * k)], ids[size_t(8 - k)]);   // highest coverage first
            QCOMPARE(r.pairs[size_t(2 * k + 1)], 0.1f + 0.001f * float(8 - k));
        }
        QCOMPARE(r.pairs[18], 0.0f);
        QCOMPARE(r.pairs[19], 0.0f);
        QCOMPARE(rankCryptomatte(film, ids, 6, 6).ranks, 6);
        // Two hits with one name (a plant's leaf and bark in CryptoObject) merge into one rank.
        std::vector<float> same(9, ids[0]);
        const CryptomatteRanks merged = rankCryptomatte(film, same);
        QCOMPARE(merged.ranks, 6);
        QCOMPARE(merged.pairs[0], ids[0]);
        float sum = 0.0f;
        for (const MatteFilm::Entry& e : film.entries) sum += e.coverage;
        QCOMPARE(merged.pairs[1], sum);
        QCOMPARE(merged.pairs[3], 0.0f);
    }

    // Mattes of another size than the passes are refused, writing nothing.
    void mismatchedMatteRefused()
    {
        const Scene sc = test::matteScene(1, 8, 6), other = test::matteScene(1, 10, 6);
        const RenderScene rs = buildRenderScene(sc, test::matteAssets(), sunRadiance(sc.sun));
        const RenderScene rsOther = buildRenderScene(other, test::matteAssets(), sunRadiance(other.sun));
        RenderPasses passes = renderPasses(renderFilm(rs.view()), RenderMode::Local, sc.sky);
        passes.cryptomatte = cryptomatteLayers(renderMatteFilm(rsOther.view()), other);
        const QString path = m_dir.filePath("mismatch.exr");
        QVERIFY_THROWS_EXCEPTION(Error, writeRenderPasses(path.toStdString(), passes));
        QVERIFY(!QFile::exists(path));
    }

    // sylva render --passes on a scene file (the cards as OBJ meshes): the same mattes in the EXR.
    void commandLine()
    {
        Scene sc = test::matteScene(4);
        const std::vector<SpeciesAssets> assets = test::matteAssets();
        for (size_t s = 0; s < 2; ++s) {
            const QString obj = m_dir.filePath(QString("card%1.obj").arg(s));
            writeObj(obj.toStdString(), assets[s].mesh);
            sc.species[s].meshPath = obj.toStdString();
            sc.species[s].leafMaterials = {"leaves"};
        }
        const QString scene = m_dir.filePath("cards.sylva.json");
        writeSceneFile(sc, scene.toStdString());
        const QString out = m_dir.filePath("cli.exr");
        const test::Run r = test::runProgram(SYLVA_CLI_PATH, {"render", scene, "--passes", "-o", out, "--quiet", "--no-cache"},
                                             QProcessEnvironment::systemEnvironment(), 300000);
        QVERIFY2(r.code == 0, qPrintable(r.err));
        int compared = 0, partial = 0;
        checkMattes(sc, out, &compared, &partial);
        if (QTest::currentTestFailed()) return;
        QVERIFY2(compared > sc.render.width * sc.render.height * 9 / 10 && partial > 20,
                 qPrintable(QString("%1 compared, %2 partial").arg(compared).arg(partial)));
    }
};

QTEST_GUILESS_MAIN(TestCryptomatte)
#include "tst_cryptomatte.moc"
