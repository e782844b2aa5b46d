// Tests of grid files: .npy reading/writing, JSON sidecars, and the montage picture of grids.
#include <cmath>
#include <cstring>
#include <filesystem>
#include <limits>

#include <QDir>
#include <QFile>
#include <QJsonArray>
#include <QJsonDocument>
#include <QJsonObject>
#include <QRegularExpression>
#include <QTest>

#include "core/base/error.h"
#include "pipeline/io/atomic_file.h"
#include "pipeline/io/grid_picture.h"
#include "pipeline/io/image_io.h"
#include "pipeline/io/npy.h"

using namespace sylva;

namespace {

QString outDir()
{
    return QStringLiteral(SYLVA_TEST_OUTPUT "/tst_grid_files");
}

std::string outPath(const char* name)
{
    return (outDir() + QLatin1Char('/') + QLatin1String(name)).toStdString();
}

void writeBytes(const std::string& path, const QByteArray& bytes)
{
    QFile f(QString::fromStdString(path));
    QVERIFY(f.open(QIODevice::WriteOnly | QIODevice::Truncate));
    QCOMPARE(f.write(bytes), bytes.size());
}

QByteArray readBytes(const std::string& path)
{
    QFile f(QString::fromStdString(path));
    if (!f.open(QIODevice::ReadOnly)) return {};
    return f.readAll();
}

QByteArray floatBytesLE(const std::vector<float>& values)
{
    QByteArray out;
    for (float v : values) {
        uint32_t bits;
        std::memcpy(&bits, &v, 4);
        for (int b = 0; b < 4; ++b) out += char((bits >> (8 * b)) & 0xff);
    }
    return out;
}

// An .npy file as numpy.lib.format writes it, spelled out by hand: magic, version, little-endian
// header length, the dict, spaces and '\n' so the data starts at a multiple of 64; then the data.
QByteArray npyFile(const QByteArray& dict, const QByteArray& data, int major = 1)
{
    const int lengthBytes = major == 1 ? 2 : 4;
    const int preamble = 8 + lengthBytes;
    int total = preamble + int(dict.size()) + 1;
    total += 64 - total % 64;   // NumPy pads by 1..64 bytes, a whole 64 when already aligned
    const int headerLength = total - preamble;
    QByteArray out("\x93NUMPY", 6);
    out += char(major);
    out += char(0);
    for (int b = 0; b < lengthBytes; ++b) out += char((headerLength >> (8 * b)) & 0xff);
    out += dict;
    out += QByteArray(total - int(out.size()) - 1, ' ');
    out += '\n';
    return out + data;
}

std::vector<float> sequence(size_t n, float scale = 1.0f)
{
    std::vector<float> v(n);
    for (size_t i = 0; i < n; ++i) v[i] = float(i) * scale;
    return v;
}

// Values that stress bit-exactness: signed zeros, denormals, infinities, NaN payloads, extremes.
std::vector<float> awkwardValues(size_t n)
{
    std::vector<float> v(n);
    for (size_t i = 0; i < n; ++i) {
        uint32_t bits = uint32_t(i * 2654435761u) ^ 0x5bd1e995u;
        std::memcpy(&v[i], &bits, 4);
    }
    if (n >= 6) {
        v[0] = -0.0f;
        v[1] = std::numeric_limits<float>::denorm_min();
        v[2] = std::numeric_limits<float>::infinity();
        v[3] = std::numeric_limits<float>::quiet_NaN();
        v[4] = std::numeric_limits<float>::max();
        v[5] = -std::numeric_limits<float>::lowest();
    }
    return v;
}

bool bitEqual(const std::vector<float>& a, const std::vector<float>& b)
{
    return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(float)) == 0;
}

float luminance(const ImageRgba& img, int x, int y)
{
    const float* p = img.at(x, y);
    return p[0] + p[1] + p[2];
}

} // namespace

class TstGridFiles : public QObject {
    Q_OBJECT

private Q_SLOTS:
    void initTestCase()
    {
        QDir(outDir()).removeRecursively();
        QVERIFY(QDir().mkpath(outDir()));
    }

    void npyRoundTrip_data()
    {
        QTest::addColumn<QList<qulonglong>>("shape");
        QTest::newRow("3d") << QList<qulonglong>{5, 4, 3};
        QTest::newRow("4d") << QList<qulonglong>{3, 4, 5, 3};
        QTest::newRow("1d") << QList<qulonglong>{7};
        QTest::newRow("big first axis") << QList<qulonglong>{1234567, 1, 1};
    }

    void npyRoundTrip()
    {
        QFETCH(QList<qulonglong>, shape);
        NpyArray a;
        size_t n = 1;
        for (qulonglong s : shape) {
            a.shape.push_back(size_t(s));
            n *= size_t(s);
        }
        a.data = awkwardValues(n);
        const std::string path = outPath("roundtrip.npy");
        writeNpy(path, a);
        const NpyArray b = readNpy(path);
        QVERIFY(b.shape == a.shape);
        QVERIFY(bitEqual(a.data, b.data));
        const QByteArray bytes = readBytes(path);
        QCOMPARE(size_t(bytes.size()) % 4, size_t(0));
        QCOMPARE(size_t(bytes.size()) - n * 4 > 0, true);
        QCOMPARE((size_t(bytes.size()) - n * 4) % 64, size_t(0));
    }

    // A file spelled out byte for byte as NumPy writes it reads correctly (old and new NumPy, v2.0).
    void npyHandWritten_data()
    {
        QTest::addColumn<QByteArray>("dict");
        QTest::addColumn<int>("major");
        QTest::addColumn<int>("headerTotal");
        const QByteArray dict = "{'descr': '<f4', 'fortran_order': False, 'shape': (2, 3, 4), }";
        QTest::newRow("numpy < 1.23") << dict << 1 << 128;
        QTest::newRow("numpy >= 1.23 (growth room)") << dict + QByteArray(20, ' ') << 1 << 128;
        QTest::newRow("version 2.0") << dict << 2 << 128;
        QTest::newRow("keys reordered, double quotes") << QByteArray("{\"shape\": (2,3,4), \"fortran_order\": False, \"descr\": \"<f4\"}") << 1 << 128;
    }

    void npyHandWritten()
    {
        QFETCH(QByteArray, dict);
        QFETCH(int, major);
        QFETCH(int, headerTotal);
        const std::vector<float> values = sequence(24, 0.5f);
        const QByteArray file = npyFile(dict, floatBytesLE(values), major);
        QCOMPARE(int(file.size()) - 24 * 4, headerTotal);
        const std::string path = outPath("handwritten.npy");
        writeBytes(path, file);
        const NpyArray a = readNpy(path);
        QVERIFY((a.shape == std::vector<size_t>{2, 3, 4}));
        QVERIFY(bitEqual(a.data, values));
    }

    // Our writer produces exactly NumPy's bytes, and its header follows NumPy's layout for any shape.
    void npyWriterMatchesNumpy()
    {
        const std::vector<float> values = sequence(24, 0.25f);
        const std::string path = outPath("writer.npy");
        writeNpy(path, NpyArray{{2, 3, 4}, values});
        const QByteArray expected = npyFile("{'descr': '<f4', 'fortran_order': False, 'shape': (2, 3, 4), }" + QByteArray(20, ' '), floatBytesLE(values));
        QCOMPARE(readBytes(path), expected);

        const QRegularExpression layout(QStringLiteral("^\\{'descr': '<f4', 'fortran_order': False, 'shape': \\(([0-9, ]*)\\), \\} *\\n$"));
        const std::vector<std::vector<size_t>> shapes{{1}, {9, 9, 9}, {64, 64, 64, 3}, {}};
        for (const auto& shape : shapes) {
            size_t n = 1;
            for (size_t s : shape) n *= s;
            writeNpy(path, NpyArray{shape, std::vector<float>(n, 1.0f)});
            const QByteArray bytes = readBytes(path);
            QVERIFY(bytes.startsWith(QByteArray("\x93NUMPY\x01\x00", 8)));
            const int headerLength = uchar(bytes[8]) | (uchar(bytes[9]) << 8);
            QCOMPARE((10 + headerLength) % 64, 0);
            const QString header = QString::fromLatin1(bytes.mid(10, headerLength));
            const auto match = layout.match(header);
            QVERIFY2(match.hasMatch(), qPrintable(header));
            QCOMPARE(size_t(bytes.size()), size_t(10 + headerLength) + n * 4);
            QVERIFY(readNpy(path).shape == shape);
        }
    }

    void npyWriterRejectsMismatch()
    {
        QVERIFY_THROWS_EXCEPTION(Error, writeNpy(outPath("mismatch.npy"), NpyArray{{2, 3}, std::vector<float>(5)}));
        QVERIFY(!QFile::exists(QString::fromStdString(outPath("mismatch.npy"))));
    }

    void npyBadFiles_data()
    {
        QTest::addColumn<QByteArray>("bytes");
        QTest::addColumn<QString>("expected");
        const QByteArray data24 = floatBytesLE(sequence(24));
        auto dict = [](const char* descr, const char* fortran, const char* shape) {
            return QByteArray("{'descr': '") + descr + "', 'fortran_order': " + fortran + ", 'shape': " + shape + ", }";
        };
        QTest::newRow("empty") << QByteArray() << "not an npy file";
        QTest::newRow("garbage") << QByteArray("this is not a numpy file at all, just some text\n") << "not an npy file";
        QTest::newRow("preamble cut") << QByteArray("\x93NUMPY\x01", 7) << "truncated";
        QTest::newRow("header cut") << npyFile(dict("<f4", "False", "(2, 3, 4)"), {}).left(40) << "runs past the end";
        QTest::newRow("header length past end") << QByteArray("\x93NUMPY\x01\x00\xff\x7f{'descr': '<f4'", 25) << "runs past the end";
        QTest::newRow("data cut") << npyFile(dict("<f4", "False", "(2, 3, 4)"), data24.left(50)) << "truncated";
        QTest::newRow("float64") << npyFile(dict("<f8", "False", "(2, 3, 4)"), data24 + data24) << "'<f8' (little-endian float64)";
        QTest::newRow("big-endian") << npyFile(dict(">f4", "False", "(2, 3, 4)"), data24) << "big-endian float32";
        QTest::newRow("uint8") << npyFile(dict("|u1", "False", "(2, 3, 4)"), data24) << "'|u1' (uint8)";
        QTest::newRow("structured") << npyFile("{'descr': [('a', '<f4')], 'fortran_order': False, 'shape': (2,), }", data24) << "structured";
        QTest::newRow("fortran order") << npyFile(dict("<f4", "True", "(2, 3, 4)"), data24) << "Fortran order";
        QTest::newRow("zero shape") << npyFile(dict("<f4", "False", "(0, 3, 4)"), {}) << "zero-sized";
        QTest::newRow("huge shape") << npyFile(dict("<f4", "False", "(1000000, 1000000)"), data24) << "needs 4000000000000 data bytes";
        QTest::newRow("overflowing shape") << npyFile(dict("<f4", "False", "(4611686018427387904, 4611686018427387904)"), data24) << "too large";
        QTest::newRow("shape entry beyond 64 bits") << npyFile(dict("<f4", "False", "(99999999999999999999999, 1)"), data24) << "too large";
        QTest::newRow("negative shape") << npyFile(dict("<f4", "False", "(-2, 3, 4)"), data24) << "malformed npy header";
        QTest::newRow("missing shape") << npyFile("{'descr': '<f4', 'fortran_order': False, }", data24) << "'shape' is missing";
        QTest::newRow("unknown key") << npyFile("{'descr': '<f4', 'fortran_order': False, 'shape': (2, 3, 4), 'x': 1, }", data24) << "unexpected key 'x'";
        QTest::newRow("not a dict") << npyFile("hello", data24) << "malformed npy header";
        QTest::newRow("unterminated") << npyFile("{'descr': '<f4, 'fortran_order': False", data24) << "malformed npy header";
        QTest::newRow("one-entry shape without comma") << npyFile(dict("<f4", "False", "(24)"), data24) << "trailing comma";
        QTest::newRow("fortran not bool") << npyFile(dict("<f4", "0", "(2, 3, 4)"), data24) << "True or False";
        QByteArray badVersion = npyFile(dict("<f4", "False", "(2, 3, 4)"), data24);
        badVersion[6] = char(9);
        QTest::newRow("version 9") << badVersion << "unsupported npy format version 9";
    }

    void npyBadFiles()
    {
        QFETCH(QByteArray, bytes);
        QFETCH(QString, expected);
        const std::string path = outPath("bad.npy");
        writeBytes(path, bytes);
        try {
            readNpy(path);
            QFAIL("readNpy accepted a bad file");
        } catch (const Error& e) {
            const QString message = QString::fromStdString(e.what());
            QVERIFY2(message.contains(QString::fromStdString(path)), qPrintable(message));
            QVERIFY2(message.contains(expected), qPrintable(message));
        }
    }

    void npyMissingFile()
    {
        const std::string path = outPath("does-not-exist.npy");
        try {
            readNpy(path);
            QFAIL("readNpy accepted a missing file");
        } catch (const Error& e) {
            QVERIFY(QString::fromStdString(e.what()).contains(QString::fromStdString(path)));
        }
    }

    void densityRoundTrip()
    {
        DensityGrid g;
        g.geometry.dims = {4, 5, 6};
        g.geometry.origin = {1.25, -3.5, 0.1};
        g.geometry.spacing = 0.03125;
        g.density = sequence(120, 1.0f / 120.0f);
        g.woodFraction = sequence(120, 1.0f / 240.0f);
        const std::string path = outPath("tree.npy");
        writeDensityGrid(path, g);
        QCOMPARE(QString::fromStdString(woodFractionPath(path)), QString::fromStdString(outPath("tree.wood.npy")));
        QVERIFY(QFile::exists(QString::fromStdString(outPath("tree.wood.npy"))));
        QVERIFY(QFile::exists(QString::fromStdString(outPath("tree.npy.json"))));

        const QJsonObject sidecar = QJsonDocument::fromJson(readBytes(outPath("tree.npy.json"))).object();
        QCOMPARE(sidecar.value("version").toInt(), 1);
        QCOMPARE(sidecar.value("kind").toString(), QStringLiteral("density"));
        QCOMPARE(sidecar.value("dims").toArray(), (QJsonArray{4, 5, 6}));
        QCOMPARE(sidecar.value("origin").toArray(), (QJsonArray{1.25, -3.5, 0.1}));
        QCOMPARE(sidecar.value("spacing").toDouble(), 0.03125);

        const DensityGrid r = readDensityGrid(path);
        QVERIFY(r.geometry == g.geometry);   // origin 0.1 survives the JSON round trip exactly
        QVERIFY(bitEqual(r.density, g.density));
        QVERIFY(bitEqual(r.woodFraction, g.woodFraction));
        QVERIFY((readNpy(path).shape == std::vector<size_t>{4, 5, 6}));
    }

    void densityWithoutSidecarOrWood()
    {
        const std::string path = outPath("bare.npy");
        writeNpy(path, NpyArray{{3, 3, 3}, sequence(27)});
        const DensityGrid r = readDensityGrid(path);
        QCOMPARE(r.geometry.dims, glm::ivec3(3, 3, 3));
        QCOMPARE(r.geometry.origin, glm::dvec3(0.0));
        QCOMPARE(r.geometry.spacing, 1.0);
        QVERIFY(r.woodFraction == std::vector<float>(27, 0.0f));
    }

    void sidecarProblems_data()
    {
        QTest::addColumn<QByteArray>("sidecar");
        QTest::addColumn<QString>("expected");
        QTest::newRow("dims disagree") << QByteArray(R"({"version":1,"kind":"density","dims":[3,3,4],"origin":[0,0,0],"spacing":1})") << "disagree";
        QTest::newRow("wrong kind") << QByteArray(R"({"version":1,"kind":"lighting","dims":[3,3,3],"origin":[0,0,0],"spacing":1})") << "not a density grid";
        QTest::newRow("newer version") << QByteArray(R"({"version":2,"kind":"density","dims":[3,3,3],"origin":[0,0,0],"spacing":1})") << "newer";
        QTest::newRow("bad spacing") << QByteArray(R"({"version":1,"kind":"density","dims":[3,3,3],"origin":[0,0,0],"spacing":0})") << "spacing";
        QTest::newRow("missing origin") << QByteArray(R"({"version":1,"kind":"density","dims":[3,3,3],"spacing":1})") << "\"origin\"";
        QTest::newRow("not json") << QByteArray("{version: 1") << "malformed JSON";
    }

    void sidecarProblems()
    {
        QFETCH(QByteArray, sidecar);
        QFETCH(QString, expected);
        const std::string path = outPath("sidecar.npy");
        writeNpy(path, NpyArray{{3, 3, 3}, sequence(27)});
        writeBytes(gridSidecarPath(path), sidecar);
        try {
            readDensityGrid(path);
            QFAIL("a bad sidecar was accepted");
        } catch (const Error& e) {
            const QString message = QString::fromStdString(e.what());
            QVERIFY2(message.contains(QString::fromStdString(gridSidecarPath(path))), qPrintable(message));
            QVERIFY2(message.contains(expected), qPrintable(message));
        }
    }

    void woodShapeMismatch()
    {
        const std::string path = outPath("woody.npy");
        writeNpy(path, NpyArray{{3, 3, 3}, sequence(27)});
        writeNpy(woodFractionPath(path), NpyArray{{3, 3, 2}, sequence(18)});
        QVERIFY_THROWS_EXCEPTION(Error, readDensityGrid(path));
    }

    void lightingRoundTrip()
    {
        LightingGrid g;
        g.geometry.dims = {3, 4, 5};
        g.geometry.origin = {-1.0, 0.0, 2.5};
        g.geometry.spacing = 0.1;
        g.rgb = awkwardValues(3 * 4 * 5 * 3);
        const std::string path = outPath("light.npy");
        writeLightingGrid(path, g, R"({"preset": "leaf", "sun": [0, 1, 0]})");
        QVERIFY((readNpy(path).shape == std::vector<size_t>{3, 4, 5, 3}));
        const QJsonObject sidecar = QJsonDocument::fromJson(readBytes(gridSidecarPath(path))).object();
        QCOMPARE(sidecar.value("kind").toString(), QStringLiteral("lighting"));
        QCOMPARE(sidecar.value("parameters").toObject().value("preset").toString(), QStringLiteral("leaf"));
        const LightingGrid r = readLightingGrid(path);
        QVERIFY(r.geometry == g.geometry);
        QVERIFY(bitEqual(r.rgb, g.rgb));

        // A lighting file is not a density file, and vice versa.
        QVERIFY_THROWS_EXCEPTION(Error, readDensityGrid(path));
        QVERIFY_THROWS_EXCEPTION(Error, readLightingGrid(outPath("tree.npy")));
        QVERIFY_THROWS_EXCEPTION(Error, writeLightingGrid(outPath("light2.npy"), g, "[1, 2]"));
        QVERIFY_THROWS_EXCEPTION(Error, writeLightingGrid(outPath("light2.npy"), g, "{oops"));
    }

    void montageDimensions_data()
    {
        QTest::addColumn<int>("axis");
        QTest::addColumn<int>("slices");
        QTest::addColumn<bool>("withDensity");
        QTest::addColumn<int>("width");
        QTest::addColumn<int>("height");
        // Grid 10x12x14. axis 2: tile x(10) by y(12), scale 64/12 = 5 -> 50x60; 8 slices: 3 cols, 3 rows.
        QTest::newRow("z, both") << 2 << 8 << true << 2 + 3 * 2 * 52 << 2 + 3 * 62;
        QTest::newRow("z, lighting only") << 2 << 8 << false << 2 + 3 * 52 << 2 + 3 * 62;
        // axis 0: tile z(14) by y(12), scale 64/14 = 4 -> 56x48; 4 slices: 2 cols, 2 rows.
        QTest::newRow("x, both") << 0 << 4 << true << 2 + 2 * 2 * 58 << 2 + 2 * 50;
        // axis 1: tile x(10) by z(14), scale 4 -> 40x56; 1 slice.
        QTest::newRow("y, one slice") << 1 << 1 << true << 2 + 2 * 42 << 2 + 58;
        // More slices than nodes along the axis: clamped to 12 (4 cols, 3 rows).
        QTest::newRow("y, clamped") << 1 << 50 << false << 2 + 4 * 42 << 2 + 3 * 58;
    }

    void montageDimensions()
    {
        QFETCH(int, axis);
        QFETCH(int, slices);
        QFETCH(bool, withDensity);
        QFETCH(int, width);
        QFETCH(int, height);
        DensityGrid d;
        d.geometry.dims = {10, 12, 14};
        d.density.assign(d.geometry.nodeCount(), 0.5f);
        LightingGrid l;
        l.geometry = d.geometry;
        l.rgb.assign(d.geometry.nodeCount() * 3, 1.0f);
        const ImageRgba img = gridMontage(withDensity ? &d : nullptr, &l, axis, slices);
        QCOMPARE(img.width, width);
        QCOMPARE(img.height, height);
        QCOMPARE(img.at(0, 0)[0], 0.25f);        // gap
        QVERIFY(std::abs(img.at(2, 2)[0] - (withDensity ? 0.5f : 1.0f)) < 1e-5f);   // first tile
        QCOMPARE(img.at(2, 2)[3], 1.0f);
    }

    // Lit from +x with light decreasing upwards: the picture is brighter on the right (x) and at the bottom (low y).
    void montageOrientation()
    {
        LightingGrid l;
        l.geometry.dims = {16, 16, 8};
        l.rgb.resize(l.geometry.nodeCount() * 3);
        for (int i = 0; i < 16; ++i)
            for (int j = 0; j < 16; ++j)
                for (int k = 0; k < 8; ++k)
                    for (int c = 0; c < 3; ++c) l.rgb[l.geometry.index(i, j, k) * 3 + size_t(c)] = float(i + 1) * (1.0f + 0.01f * float(15 - j));
        DensityGrid d;
        d.geometry = l.geometry;
        d.density.resize(d.geometry.nodeCount());
        for (int i = 0; i < 16; ++i)
            for (int j = 0; j < 16; ++j)
                for (int k = 0; k < 8; ++k) d.density[d.geometry.index(i, j, k)] = j >= 12 ? 1.0f : 0.0f;   // canopy on top

        const ImageRgba img = gridMontage(&d, &l, 2, 1);
        // scale 64/16 = 4 -> tiles 64x64: density at x 2..65, lighting at x 68..131, rows 2..65.
        QCOMPARE(img.width, 2 + 2 * 66);
        QCOMPARE(img.height, 2 + 66);
        QVERIFY(luminance(img, 68 + 60, 30) > luminance(img, 68 + 3, 30));    // lit side (+x) is right
        QVERIFY(luminance(img, 68 + 30, 62) > luminance(img, 68 + 30, 3));    // +y is up: low y at the bottom
        QCOMPARE(img.at(30, 3)[0], 1.0f);                                      // canopy (high y) at the top
        QCOMPARE(img.at(30, 62)[0], 0.0f);
        // The robust max maps the brightest interior values to about white.
        QVERIFY(img.at(68 + 63, 63)[0] > 0.95f);

        // Sliced along x the tile shows z to the right, y up: brightness does not vary with z.
        const ImageRgba side = gridMontage(nullptr, &l, 0, 1);
        QCOMPARE(luminance(side, 2, 30), luminance(side, side.width - 3, 30));
    }

    void montageErrors()
    {
        QVERIFY_THROWS_EXCEPTION(Error, gridMontage(nullptr, nullptr));
        DensityGrid d;
        d.geometry.dims = {3, 3, 3};
        d.density.assign(27, 0.0f);
        LightingGrid l;
        l.geometry.dims = {3, 3, 4};
        l.rgb.assign(36 * 3, 0.0f);
        QVERIFY_THROWS_EXCEPTION(Error, gridMontage(&d, &l));
        QVERIFY_THROWS_EXCEPTION(Error, gridMontage(&d, nullptr, 3));
        // All-zero and non-finite lighting still make a picture.
        l.geometry.dims = {3, 3, 3};
        l.rgb.assign(27 * 3, 0.0f);
        l.rgb[40] = std::numeric_limits<float>::quiet_NaN();
        const ImageRgba img = gridMontage(&d, &l);
        QVERIFY(!img.empty());
    }

    void montageFile()
    {
        DensityGrid d;
        d.geometry.dims = {8, 8, 8};
        d.density = sequence(512, 1.0f / 512.0f);
        LightingGrid l;
        l.geometry = d.geometry;
        l.rgb = sequence(512 * 3, 1.0f / 1536.0f);
        const std::string path = outPath("montage.png");
        writeGridMontage(path, &d, &l, 2, 8);
        const ImageRgba expected = gridMontage(&d, &l, 2, 8);
        const ImageRgba read = readImage(path);
        QCOMPARE(read.width, expected.width);
        QCOMPARE(read.height, expected.height);
        float worst = 0.0f;
        for (size_t i = 0; i < read.pixels.size(); ++i) worst = std::max(worst, std::abs(read.pixels[i] - expected.pixels[i]));
        QVERIFY2(worst <= 0.5f / 255.0f + 1e-6f, qPrintable(QString::number(worst)));
        QVERIFY_THROWS_EXCEPTION(Error, writeGridMontage(outPath("none.png"), nullptr, nullptr));
    }
    // The one atomic writer behind npy, sidecar, cache, scene, OBJ and image files.
    void atomicFileWriter()
    {
        namespace fs = std::filesystem;
        const std::string dir = outPath("atomic");
        const std::string path = dir + "/a.npy";
        auto leftovers = [&] {
            QStringList names = QDir(QString::fromStdString(dir)).entryList({".tmp.*"}, QDir::Files | QDir::Hidden);
            return names.join(QLatin1Char(','));
        };
        {
            AtomicFile file(path);   // creates the folder
            QVERIFY(QFileInfo(QString::fromStdString(file.tempPath())).absolutePath() == QString::fromStdString(dir));
            QVERIFY(QString::fromStdString(file.tempPath()).endsWith(".a.npy"));   // extension kept
            file.write(std::string_view("first"));
            QVERIFY(!QFile::exists(QString::fromStdString(path)));   // nothing in place before commit
            file.commit();
        }
        QCOMPARE(readBytes(path), QByteArray("first"));
        QCOMPARE(leftovers(), QString());
        {
            AtomicFile file(path);   // abandoned: the old file stays, the temporary file goes
            file.write(std::string_view("second"));
        }
        QCOMPARE(readBytes(path), QByteArray("first"));
        QCOMPARE(leftovers(), QString());

        // Permissions of the replaced file are kept; a link stays a link, its target is replaced.
        fs::permissions(path, fs::perms::owner_read | fs::perms::owner_write | fs::perms::group_read);
        const std::string link = dir + "/link.npy";
        fs::create_symlink("a.npy", link);
        writeNpy(link, NpyArray{{2}, {1.0f, 2.0f}});
        QVERIFY(fs::is_symlink(link));
        QCOMPARE(readNpy(path).data, (std::vector<float>{1.0f, 2.0f}));
        QVERIFY(fs::status(path).permissions() == (fs::perms::owner_read | fs::perms::owner_write | fs::perms::group_read));
        QCOMPARE(leftovers(), QString());

        // Errors name the target.
        writeBytes(dir + "/plain", "x");
        try {
            AtomicFile file(dir + "/plain/sub/b.npy");
            QFAIL("a folder below a regular file was accepted");
        } catch (const Error& e) {
            QVERIFY2(std::string(e.what()).rfind(dir + "/plain/sub/b.npy: ", 0) == 0, e.what());
        }
        try {
            AtomicFile file(dir);
            QFAIL("a folder was accepted as a file");
        } catch (const Error& e) {
            QVERIFY2(std::string(e.what()).find("is a folder") != std::string::npos, e.what());
        }
    }
};

QTEST_GUILESS_MAIN(TstGridFiles)
#include "tst_grid_files.moc"
