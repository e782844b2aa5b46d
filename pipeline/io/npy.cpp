// NumPy .npy reader/writer and the JSON sidecars of density and lighting grid files.
#include "pipeline/io/npy.h"

#include <bit>
#include <climits>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <optional>
#include <string_view>

#include <QByteArray>
#include <QDir>
#include <QFile>
#include <QFileInfo>
#include <QJsonArray>
#include <QJsonDocument>
#include <QJsonObject>
#include <QJsonParseError>

#include "core/base/error.h"
#include "pipeline/io/atomic_file.h"
#include "pipeline/io/output_path.h"

namespace sylva {

namespace fs = std::filesystem;

namespace {

constexpr char kMagic[] = "\x93NUMPY";
constexpr size_t kMagicLength = 6;
constexpr size_t kArrayAlign = 64;              // NumPy's ARRAY_ALIGN
constexpr size_t kGrowthAxisMaxDigits = 21;     // NumPy's GROWTH_AXIS_MAX_DIGITS
constexpr size_t kMaxHeaderLength = 1u << 20;   // far beyond any sane header; guards allocation

void swapFloatBytes(float* data, size_t count)
{
    for (size_t i = 0; i < count; ++i) {
        uint32_t bits;
        std::memcpy(&bits, &data[i], 4);
        bits = ((bits & 0xffu) << 24) | ((bits & 0xff00u) << 8) | ((bits >> 8) & 0xff00u) | (bits >> 24);
        std::memcpy(&data[i], &bits, 4);
    }
}

std::string shapeText(const std::vector<size_t>& shape)
{
    std::string s = "(";
    for (size_t i = 0; i < shape.size(); ++i) {
        if (i) s += ", ";
        s += std::to_string(shape[i]);
    }
    if (shape.size() == 1) s += ",";
    return s + ")";
}

// Names a NumPy dtype string such as '<f8' or '|u1' in words for error messages.
std::string describeDtype(const std::string& descr)
{
    if (descr.size() < 3) return "unknown";
    std::string order;
    switch (descr[0]) {
    case '<': order = "little-endian "; break;
    case '>': order = "big-endian "; break;
    case '=': order = "native-endian "; break;
    case '|': break;
    default: return "unknown";
    }
    std::string kind;
    switch (descr[1]) {
    case 'f': kind = "float"; break;
    case 'i': kind = "int"; break;
    case 'u': kind = "uint"; break;
    case 'b': kind = "bool"; break;
    case 'c': kind = "complex"; break;
    case 'U': return order + "unicode string";
    case 'S': return "byte string";
    case 'O': return "Python object";
    default: return "unknown";
    }
    const std::string digits = descr.substr(2);
    if (digits.empty() || digits.find_first_not_of("0123456789") != std::string::npos || digits.size() > 3)
        return "unknown";
    if (kind == "bool") return "bool";
    return order + kind + std::to_string(std::stoi(digits) * 8);
}

// The header dictionary of an .npy file, as written by numpy.lib.format.
struct NpyHeader {
    std::string descr;
    bool fortranOrder = false;
    std::vector<size_t> shape;
};

// Parses the Python literal "{'descr': '<f4', 'fortran_order': False, 'shape': (2, 3), }" (keys in
// any order, either quote style, trailing commas, surrounding whitespace). Throws Error.
class HeaderParser {
public:
    HeaderParser(const std::string& path, std::string_view text) : m_path(path), m_text(text) {}

    NpyHeader parse()
    {
        NpyHeader header;
        bool haveDescr = false, haveFortran = false, haveShape = false;
        skipSpace();
        expect('{');
        skipSpace();
        while (peek() != '}') {
            const std::string key = parseString("a key");
            skipSpace();
            expect(':');
            skipSpace();
            if (key == "descr") {
                if (haveDescr) fail("the key 'descr' appears twice");
                if (peek() == '[')
                    throw Error(m_path + ": the data type is a structured (record) type; float32 ('<f4') is required");
                header.descr = parseString("the 'descr' value");
                haveDescr = true;
            } else if (key == "fortran_order") {
                if (haveFortran) fail("the key 'fortran_order' appears twice");
                header.fortranOrder = parseBool();
                haveFortran = true;
            } else if (key == "shape") {
                if (haveShape) fail("the key 'shape' appears twice");
                header.shape = parseShape();
                haveShape = true;
            } else {
                fail("unexpected key '" + key + "'");
            }
            skipSpace();
            if (peek() == ',') {
                ++m_pos;
                skipSpace();
            } else if (peek() != '}') {
                fail("expected ',' or '}' after the value of '" + key + "'");
            }
        }
        ++m_pos;
        skipSpace();
        if (m_pos != m_text.size()) fail("unexpected text after the closing '}'");
        if (!haveDescr) fail("the key 'descr' is missing");
        if (!haveFortran) fail("the key 'fortran_order' is missing");
        if (!haveShape) fail("the key 'shape' is missing");
        return header;
    }

private:
    [[noreturn]] void fail(const std::string& what) const
    {
        throw Error(m_path + ": malformed npy header (" + what + ") in \"" + printable() + "\"");
    }

    std::string printable() const
    {
        std::string s;
        for (char c : m_text.substr(0, 200)) s += (c >= 32 && c < 127) ? c : '?';
        while (!s.empty() && (s.back() == ' ' || s.back() == '?')) s.pop_back();
        return s;
    }

    char peek() const
    {
        if (m_pos >= m_text.size()) fail("unexpected end of the header");
        return m_text[m_pos];
    }

    void skipSpace()
    {
        while (m_pos < m_text.size() && (m_text[m_pos] == ' ' || m_text[m_pos] == '\t' || m_text[m_pos] == '\n' || m_text[m_pos] == '\r'))
            ++m_pos;
    }

    void expect(char c)
    {
        if (peek() != c) fail(std::string("expected '") + c + "'");
        ++m_pos;
    }

    std::string parseString(const char* what)
    {
        const char quote = peek();
        if (quote != '\'' && quote != '"') fail(std::string("expected a quoted string for ") + what);
        const size_t end = m_text.find(quote, m_pos + 1);
        if (end == std::string_view::npos) fail("unterminated string");
        std::string s(m_text.substr(m_pos + 1, end - m_pos - 1));
        if (s.find('\\') != std::string::npos) fail("escape sequences are not supported");
        m_pos = end + 1;
        return s;
    }

    bool parseBool()
    {
        if (m_text.substr(m_pos, 4) == "True") {
            m_pos += 4;
            return true;
        }
        if (m_text.substr(m_pos, 5) == "False") {
            m_pos += 5;
            return false;
        }
        fail("'fortran_order' must be True or False");
    }

    std::vector<size_t> parseShape()
    {
        std::vector<size_t> shape;
        expect('(');
        skipSpace();
        bool needSeparator = false;
        while (peek() != ')') {
            if (needSeparator) fail("expected ',' between shape entries");
            if (peek() < '0' || peek() > '9') fail("shape entries must be non-negative integers");
            size_t value = 0;
            while (m_pos < m_text.size() && m_text[m_pos] >= '0' && m_text[m_pos] <= '9') {
                const size_t digit = size_t(m_text[m_pos] - '0');
                if (value > (std::numeric_limits<size_t>::max() - digit) / 10)
                    throw Error(m_path + ": npy shape has an entry too large to represent");
                value = value * 10 + digit;
                ++m_pos;
            }
            if (m_pos < m_text.size() && m_text[m_pos] == 'L') ++m_pos;   // Python 2 long suffix
            shape.push_back(value);
            skipSpace();
            needSeparator = true;
            if (peek() == ',') {
                ++m_pos;
                skipSpace();
                needSeparator = false;
            }
        }
        ++m_pos;
        // "(5)" is an int, not a tuple, in Python; NumPy would reject it too.
        if (shape.size() == 1 && needSeparator) fail("a one-entry shape needs a trailing comma, as in (5,)");
        return shape;
    }

    const std::string& m_path;
    std::string_view m_text;
    size_t m_pos = 0;
};

uint64_t readLittleEndian(const unsigned char* p, int bytes)
{
    uint64_t v = 0;
    for (int i = bytes - 1; i >= 0; --i) v = (v << 8) | p[i];
    return v;
}

void writeFloats(AtomicFile& file, const std::vector<float>& data)
{
    if constexpr (std::endian::native == std::endian::little) {
        file.write(data.data(), data.size() * sizeof(float));
    } else {
        std::vector<float> copy = data;
        swapFloatBytes(copy.data(), copy.size());
        file.write(copy.data(), copy.size() * sizeof(float));
    }
}

// ---- sidecars ----

void writeSidecar(const std::string& npyPath, const char* kind, const GridGeometry& g, const QJsonObject* parameters)
{
    QJsonObject o;
    o["version"] = 1;
    o["kind"] = kind;
    o["dims"] = QJsonArray{g.dims.x, g.dims.y, g.dims.z};
    o["origin"] = QJsonArray{g.origin.x, g.origin.y, g.origin.z};
    o["spacing"] = g.spacing;
    if (parameters) o["parameters"] = *parameters;
    const QByteArray bytes = QJsonDocument(o).toJson(QJsonDocument::Indented);
    AtomicFile file(gridSidecarPath(npyPath));
    file.write(bytes.constData(), size_t(bytes.size()));
    file.commit();
}

// Reads PATH.json when present into geometry.origin/spacing, checking kind and dims. Throws Error.
void readSidecar(const std::string& npyPath, const char* kind, GridGeometry& geometry)
{
    const std::string path = gridSidecarPath(npyPath);
    std::error_code ec;
    if (!fs::exists(path, ec)) return;
    QFile file(QString::fromStdString(path));
    if (!file.open(QIODevice::ReadOnly)) throw Error(path + ": cannot read the sidecar (" + file.errorString().toStdString() + ")");
    const QByteArray bytes = file.readAll();
    QJsonParseError parseError;
    const QJsonDocument doc = QJsonDocument::fromJson(bytes, &parseError);
    if (doc.isNull())
        throw Error(path + ": malformed JSON (" + parseError.errorString().toStdString() + " at offset " + std::to_string(parseError.offset) + ")");
    if (!doc.isObject()) throw Error(path + ": the sidecar must hold a JSON object");
    const QJsonObject o = doc.object();
    auto need = [&](const char* field) {
        if (!o.contains(QLatin1String(field))) throw Error(path + ": the sidecar lacks the field \"" + field + "\"");
        return o.value(QLatin1String(field));
    };
    const QJsonValue version = need("version");
    if (!version.isDouble() || version.toDouble() != std::floor(version.toDouble()) || version.toDouble() < 1)
        throw Error(path + ": \"version\" must be a positive integer");
    if (version.toDouble() > 1)
        throw Error(path + ": sidecar version " + std::to_string(version.toInt()) + " is newer than this build reads (1)");
    const QString k = need("kind").toString();
    if (k != QLatin1String(kind))
        throw Error(path + ": the sidecar describes a " + (k.isEmpty() ? std::string("grid of unknown kind") : k.toStdString() + " grid") +
                    ", not a " + kind + " grid");
    const QJsonArray dims = need("dims").toArray();
    if (dims.size() != 3) throw Error(path + ": \"dims\" must hold three integers");
    for (int a = 0; a < 3; ++a)
        if (!dims[a].isDouble() || dims[a].toDouble() != double(geometry.dims[a]))
            throw Error(path + ": \"dims\" [" + std::to_string(dims[0].toInt()) + ", " + std::to_string(dims[1].toInt()) + ", " +
                        std::to_string(dims[2].toInt()) + "] disagree with the array in " + npyPath + " (" +
                        std::to_string(geometry.dims.x) + ", " + std::to_string(geometry.dims.y) + ", " + std::to_string(geometry.dims.z) + ")");
    const QJsonArray origin = need("origin").toArray();
    if (origin.size() != 3) throw Error(path + ": \"origin\" must hold three numbers");
    for (int a = 0; a < 3; ++a) {
        if (!origin[a].isDouble() || !std::isfinite(origin[a].toDouble())) throw Error(path + ": \"origin\" must hold three finite numbers");
        geometry.origin[a] = origin[a].toDouble();
    }
    const QJsonValue spacing = need("spacing");
    if (!spacing.isDouble() || !(spacing.toDouble() > 0.0) || !std::isfinite(spacing.toDouble()))
        throw Error(path + ": \"spacing\" must be a positive number");
    geometry.spacing = spacing.toDouble();
}

glm::ivec3 gridDims(const std::string& path, const std::vector<size_t>& shape, size_t rank, const char* expected)
{
    if (shape.size() != rank || (rank == 4 && shape[3] != 3))
        throw Error(path + ": expected an array of shape " + expected + " but it has shape " + shapeText(shape));
    glm::ivec3 dims;
    for (int a = 0; a < 3; ++a) {
        if (shape[size_t(a)] > size_t(INT_MAX)) throw Error(path + ": grid shape " + shapeText(shape) + " is too large");
        dims[a] = int(shape[size_t(a)]);
    }
    return dims;
}

void checkSize(const std::string& path, const char* what, size_t have, size_t want, const GridGeometry& g)
{
    if (have != want)
        throw Error(path + ": the grid holds " + std::to_string(have) + " " + what + " values but dims " + std::to_string(g.dims.x) + "x" +
                    std::to_string(g.dims.y) + "x" + std::to_string(g.dims.z) + " need " + std::to_string(want));
}

} // namespace

NpyArray readNpy(const std::string& path)
{
    std::error_code ec;
    if (!fs::exists(path, ec)) throw Error(path + ": no such file");
    if (!fs::is_regular_file(path, ec)) throw Error(path + ": not a regular file");
    std::ifstream in(fs::path(path), std::ios::binary);
    if (!in) throw Error(path + ": cannot open the file");
    in.seekg(0, std::ios::end);
    const std::streamoff fileSizeSigned = in.tellg();
    in.seekg(0, std::ios::beg);
    if (fileSizeSigned < 0) throw Error(path + ": cannot determine the file size");
    const size_t fileSize = size_t(fileSizeSigned);

    unsigned char preamble[12] = {};
    const size_t preambleRead = size_t(in.read(reinterpret_cast<char*>(preamble), 8).gcount());
    if (preambleRead < kMagicLength || std::memcmp(preamble, kMagic, kMagicLength) != 0)
        throw Error(path + ": not an npy file (missing the \\x93NUMPY magic)");
    if (preambleRead < 8) throw Error(path + ": truncated npy file (ends inside the preamble)");
    const int major = preamble[6];
    size_t lengthBytes = 0;
    if (major == 1) lengthBytes = 2;
    else if (major == 2 || major == 3) lengthBytes = 4;
    else throw Error(path + ": unsupported npy format version " + std::to_string(major) + "." + std::to_string(int(preamble[7])));
    if (size_t(in.read(reinterpret_cast<char*>(preamble + 8), std::streamsize(lengthBytes)).gcount()) != lengthBytes)
        throw Error(path + ": truncated npy file (ends inside the preamble)");
    const size_t headerLength = size_t(readLittleEndian(preamble + 8, int(lengthBytes)));
    const size_t dataOffset = 8 + lengthBytes + headerLength;
    if (headerLength > fileSize - (8 + lengthBytes))
        throw Error(path + ": truncated npy file (header length " + std::to_string(headerLength) + " runs past the end of the file, which has " +
                    std::to_string(fileSize) + " bytes)");
    if (headerLength > kMaxHeaderLength) throw Error(path + ": npy header length " + std::to_string(headerLength) + " is implausibly large");
    std::string headerText(headerLength, '\0');
    if (size_t(in.read(headerText.data(), std::streamsize(headerLength)).gcount()) != headerLength)
        throw Error(path + ": truncated npy file (cannot read the header)");

    const NpyHeader header = HeaderParser(path, headerText).parse();
    if (header.descr != "<f4")
        throw Error(path + ": data type '" + header.descr + "' (" + describeDtype(header.descr) +
                    ") is not supported; float32 ('<f4', little-endian) is required");
    if (header.fortranOrder) throw Error(path + ": the array is in Fortran order (fortran_order True); C order is required");

    size_t count = 1;
    for (size_t n : header.shape) {
        if (n == 0) throw Error(path + ": npy shape " + shapeText(header.shape) + " has a zero-sized dimension");
        if (count > std::numeric_limits<size_t>::max() / sizeof(float) / n)
            throw Error(path + ": npy shape " + shapeText(header.shape) + " is too large (its element count overflows)");
        count *= n;
    }
    const size_t dataBytes = count * sizeof(float);
    const size_t available = fileSize - dataOffset;
    if (dataBytes > available)
        throw Error(path + ": truncated npy file (shape " + shapeText(header.shape) + " needs " + std::to_string(dataBytes) +
                    " data bytes but the file holds " + std::to_string(available) + ")");

    NpyArray array;
    array.shape = header.shape;
    array.data.resize(count);
    if (size_t(in.read(reinterpret_cast<char*>(array.data.data()), std::streamsize(dataBytes)).gcount()) != dataBytes)
        throw Error(path + ": cannot read the array data");
    if constexpr (std::endian::native != std::endian::little) swapFloatBytes(array.data.data(), array.data.size());
    return array;
}

void writeNpy(const std::string& path, const NpyArray& array)
{
    size_t count = 1;
    for (size_t n : array.shape) {
        if (n != 0 && count > std::numeric_limits<size_t>::max() / n) throw Error(path + ": shape " + shapeText(array.shape) + " is too large");
        count *= n;
    }
    if (count != array.data.size())
        throw Error(path + ": shape " + shapeText(array.shape) + " needs " + std::to_string(count) + " values but " +
                    std::to_string(array.data.size()) + " were given");

    // The same bytes as numpy.save (numpy >= 1.23): keys sorted, spare room to grow the first axis.
    std::string dict = "{'descr': '<f4', 'fortran_order': False, 'shape': " + shapeText(array.shape) + ", }";
    if (!array.shape.empty()) {
        const size_t digits = std::to_string(array.shape[0]).size();
        if (digits < kGrowthAxisMaxDigits) dict.append(kGrowthAxisMaxDigits - digits, ' ');
    }
    int major = 1;
    size_t lengthBytes = 2;
    size_t headerLength = dict.size() + 1;   // + '\n'
    size_t padding = kArrayAlign - (kMagicLength + 2 + lengthBytes + headerLength) % kArrayAlign;
    if (headerLength + padding > 0xffff) {
        major = 2;
        lengthBytes = 4;
        padding = kArrayAlign - (kMagicLength + 2 + lengthBytes + headerLength) % kArrayAlign;
    }
    headerLength += padding;
    std::string bytes(kMagic, kMagicLength);
    bytes += char(major);
    bytes += char(0);
    for (size_t b = 0; b < lengthBytes; ++b) bytes += char((headerLength >> (8 * b)) & 0xff);
    bytes += dict;
    bytes.append(padding, ' ');
    bytes += '\n';

    AtomicFile file(path);
    file.write(bytes.data(), bytes.size());
    writeFloats(file, array.data);
    file.commit();
}

std::string gridSidecarPath(const std::string& npyPath)
{
    return npyPath + ".json";
}

std::string woodFractionPath(const std::string& densityNpyPath)
{
    const std::string suffix = ".npy";
    if (densityNpyPath.size() > suffix.size() && densityNpyPath.compare(densityNpyPath.size() - suffix.size(), suffix.size(), suffix) == 0)
        return densityNpyPath.substr(0, densityNpyPath.size() - suffix.size()) + ".wood.npy";
    return densityNpyPath + ".wood.npy";
}

void writeDensityGrid(const std::string& path, const DensityGrid& grid)
{
    const GridGeometry& g = grid.geometry;
    const size_t n = g.nodeCount();
    if (g.dims.x <= 0 || g.dims.y <= 0 || g.dims.z <= 0) throw Error(path + ": refusing to write a grid with empty dims");
    checkSize(path, "density", grid.density.size(), n, g);
    if (!grid.woodFraction.empty()) checkSize(path, "wood fraction", grid.woodFraction.size(), n, g);
    // All three targets are checked before any is written, so a bad one does not leave a mixed set.
    for (const std::string& target : {path, woodFractionPath(path), gridSidecarPath(path)}) requireReplaceableFile(target);
    const std::vector<size_t> shape{size_t(g.dims.x), size_t(g.dims.y), size_t(g.dims.z)};
    writeNpy(path, NpyArray{shape, grid.density});
    // Always written (zeros when the grid has none) so a stale wood file never outlives its density.
    writeNpy(woodFractionPath(path), NpyArray{shape, grid.woodFraction.empty() ? std::vector<float>(n, 0.0f) : grid.woodFraction});
    writeSidecar(path, "density", g, nullptr);
}

DensityGrid readDensityGrid(const std::string& path)
{
    NpyArray array = readNpy(path);
    DensityGrid grid;
    grid.geometry.dims = gridDims(path, array.shape, 3, "(X, Y, Z)");
    readSidecar(path, "density", grid.geometry);
    grid.density = std::move(array.data);
    const std::string woodPath = woodFractionPath(path);
    std::error_code ec;
    if (fs::exists(woodPath, ec)) {
        NpyArray wood = readNpy(woodPath);
        if (wood.shape != array.shape)
            throw Error(woodPath + ": wood fraction shape " + shapeText(wood.shape) + " differs from the density shape " +
                        shapeText(array.shape) + " in " + path);
        grid.woodFraction = std::move(wood.data);
    } else {
        grid.woodFraction.assign(grid.density.size(), 0.0f);
    }
    return grid;
}

void writeLightingGrid(const std::string& path, const LightingGrid& grid, const std::string& extraJson)
{
    const GridGeometry& g = grid.geometry;
    if (g.dims.x <= 0 || g.dims.y <= 0 || g.dims.z <= 0) throw Error(path + ": refusing to write a grid with empty dims");
    checkSize(path, "RGB", grid.rgb.size(), g.nodeCount() * 3, g);
    for (const std::string& target : {path, gridSidecarPath(path)}) requireReplaceableFile(target);
    std::optional<QJsonObject> parameters;
    if (!extraJson.empty()) {
        QJsonParseError parseError;
        const QJsonDocument doc = QJsonDocument::fromJson(QByteArray::fromStdString(extraJson), &parseError);
        if (!doc.isObject())
            throw Error(path + ": the sidecar parameters must be a JSON object" +
                        (doc.isNull() ? " (" + parseError.errorString().toStdString() + ")" : std::string()));
        parameters = doc.object();
    }
    writeNpy(path, NpyArray{{size_t(g.dims.x), size_t(g.dims.y), size_t(g.dims.z), 3}, grid.rgb});
    writeSidecar(path, "lighting", g, parameters ? &*parameters : nullptr);
}

LightingGrid readLightingGrid(const std::string& path)
{
    NpyArray array = readNpy(path);
    LightingGrid grid;
    grid.geometry.dims = gridDims(path, array.shape, 4, "(X, Y, Z, 3)");
    readSidecar(path, "lighting", grid.geometry);
    grid.rgb = std::move(array.data);
    return grid;
}

} // namespace sylva
