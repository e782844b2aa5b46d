// Tests for the procedural tree grower and the OBJ writer: budgets, determinism, geometry, textures, files, errors.
#include <QObject>
#include <QtTest>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include <tbb/global_control.h>

#include "core/base/error.h"
#include "core/base/progress.h"
#include "pipeline/grow/leaf_texture.h"
#include "pipeline/grow/obj_writer.h"
#include "pipeline/grow/tree_grower.h"
#include "pipeline/io/image_io.h"

using namespace sylva;
namespace fs = std::filesystem;

Q_DECLARE_METATYPE(sylva::TreeSpecies)

namespace {

const TreeSpecies kAllSpecies[] = {TreeSpecies::Broadleaf, TreeSpecies::Birch, TreeSpecies::Conifer, TreeSpecies::Shrub};

GrownTree grow(TreeSpecies species, size_t target, uint64_t seed = 1, float height = 0)
{
    GrowOptions o;
    o.species = species;
    o.targetTriangles = target;
    o.seed = seed;
    o.height = height;
    return growTree(o);
}

template <class T>
bool sameBytes(const std::vector<T>& a, const std::vector<T>& b)
{
    return a.size() == b.size() && (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(T)) == 0);
}

bool identical(const TriangleMesh& a, const TriangleMesh& b)
{
    return sameBytes(a.positions, b.positions) && sameBytes(a.normals, b.normals) && sameBytes(a.uvs, b.uvs) &&
           sameBytes(a.triangles, b.triangles) && sameBytes(a.triangleMaterial, b.triangleMaterial);
}

fs::path outputDir(const std::string& name)
{
    fs::path dir = fs::path(SYLVA_TEST_OUTPUT) / "tree_grower" / name;
    fs::remove_all(dir);
    fs::create_directories(dir);
    return dir;
}

std::string readText(const fs::path& path)
{
    std::string text(size_t(fs::file_size(path)), '\0');
    std::ifstream in(path, std::ios::binary);
    in.read(text.data(), std::streamsize(text.size()));
    return text;
}

// Horizontal distance of a point from the Y axis.
float radial(const glm::vec3& p) { return std::sqrt(p.x * p.x + p.z * p.z); }

// A minimal, independent OBJ reader: counts and the raw face index triples.
struct ParsedObj {
    std::string mtllib;
    std::vector<glm::vec3> v;
    size_t vt = 0, vn = 0;
    std::vector<std::array<long, 9>> faces;  // v/vt/vn per corner, 0 when absent
    std::vector<std::string> usemtl;
    bool ok = true;
    std::string why;
};

ParsedObj parseObj(const fs::path& path)
{
    ParsedObj obj;
    std::ifstream in(path);
    std::string line;
    while (std::getline(in, line)) {
        if (line.empty() || line[0] == '#') continue;
        std::istringstream ls(line);
        std::string tag;
        ls >> tag;
        if (tag == "v") {
            glm::vec3 p;
            ls >> p.x >> p.y >> p.z;
            obj.v.push_back(p);
        } else if (tag == "vt") {
            ++obj.vt;
        } else if (tag == "vn") {
            ++obj.vn;
        } else if (tag == "f") {
            std::array<long, 9> f{};
            int corners = 0;
            std::string corner;
            while (ls >> corner) {
                if (corners == 3) {
                    obj.ok = false;
                    obj.why = "face with more than 3 corners";
                    break;
                }
                long idx[3] = {0, 0, 0};
                int k = 0;
                size_t start = 0;
                for (size_t i = 0; i <= corner.size() && k < 3; ++i)
                    if (i == corner.size() || corner[i] == '/') {
                        if (i > start) idx[k] = std::strtol(corner.c_str() + start, nullptr, 10);
                        ++k;
                        start = i + 1;
                    }
                for (int c = 0; c < 3; ++c) f[size_t(corners * 3 + c)] = idx[c];
                ++corners;
            }
            if (corners != 3) {
                obj.ok = false;
                obj.why = "face with " + std::to_string(corners) + " corners";
            }
            obj.faces.push_back(f);
        } else if (tag == "mtllib") {
            ls >> obj.mtllib;
        } else if (tag == "usemtl") {
            std::string name;
            ls >> name;
            obj.usemtl.push_back(name);
        }
    }
    return obj;
}

struct ParsedMtl {
    std::map<std::string, std::map<std::string, std::string>> materials;  // name -> key -> rest of line
};

ParsedMtl parseMtl(const fs::path& path)
{
    ParsedMtl mtl;
    std::ifstream in(path);
    std::string line, current;
    while (std::getline(in, line)) {
        std::istringstream ls(line);
        std::string key;
        if (!(ls >> key) || key[0] == '#') continue;
        std::string rest;
        std::getline(ls >> std::ws, rest);
        if (key == "newmtl") current = rest;
        else if (!current.empty()) mtl.materials[current][key] = rest;
    }
    return mtl;
}

} // namespace

class TstTreeGrower : public QObject {
    Q_OBJECT

private Q_SLOTS:
    void speciesParsing();
    void determinism_data();
    void determinism();
    void triangleBudget_data();
    void triangleBudget();
    void meshValidity_data();
    void meshValidity();
    void speciesShapes_data();
    void speciesShapes();
    void heightOption();
    void textures_data();
    void textures();
    void writeGrownTree();
    void writeGenericMesh();
    void badInput();
    void progressAndCancel();
};

void TstTreeGrower::speciesParsing()
{
    const std::vector<std::string> names = speciesNames();
    QCOMPARE(names.size(), size_t(4));
    for (size_t i = 0; i < names.size(); ++i) {
        TreeSpecies s = TreeSpecies::Shrub;
        QVERIFY(parseSpecies(names[i], &s));
        QCOMPARE(int(s), int(i));
        QCOMPARE(speciesName(s), names[i]);
        QCOMPARE(int(speciesFromName(names[i])), int(i));
    }
    TreeSpecies s = TreeSpecies::Birch;
    QVERIFY(parseSpecies("Conifer", &s));
    QCOMPARE(s, TreeSpecies::Conifer);
    s = TreeSpecies::Birch;
    QVERIFY(!parseSpecies("oak", &s));
    QVERIFY(!parseSpecies("", &s));
    QCOMPARE(s, TreeSpecies::Birch);  // untouched
}

void TstTreeGrower::determinism_data()
{
    QTest::addColumn<TreeSpecies>("species");
    for (TreeSpecies s : kAllSpecies) QTest::newRow(speciesName(s).c_str()) << s;
}

void TstTreeGrower::determinism()
{
    QFETCH(TreeSpecies, species);
    const GrownTree a = grow(species, 50000, 7);
    const GrownTree b = grow(species, 50000, 7);
    QVERIFY(identical(a.mesh, b.mesh));
    QVERIFY(sameBytes(a.leafTexture.pixels, b.leafTexture.pixels));
    QVERIFY(sameBytes(a.barkTexture.pixels, b.barkTexture.pixels));
    {
        tbb::global_control one(tbb::global_control::max_allowed_parallelism, 1);
        const GrownTree serial = grow(species, 50000, 7);
        QVERIFY2(identical(a.mesh, serial.mesh), "one thread must give the same mesh as many");
    }
    const GrownTree c = grow(species, 50000, 8);
    QVERIFY(!sameBytes(a.mesh.positions, c.mesh.positions));
    // The skeleton does not depend on the budget: the trunk base ring sits at the same place.
    const GrownTree d = grow(species, 20000, 7);
    QCOMPARE(d.mesh.positions[0].y, a.mesh.positions[0].y);
}

void TstTreeGrower::triangleBudget_data()
{
    QTest::addColumn<TreeSpecies>("species");
    QTest::addColumn<int>("target");
    for (TreeSpecies s : kAllSpecies)
        for (int target : {1000, 1001, 10000, 100000, 1000000})
            QTest::newRow((speciesName(s) + "_" + std::to_string(target)).c_str()) << s << target;
}

void TstTreeGrower::triangleBudget()
{
    QFETCH(TreeSpecies, species);
    QFETCH(int, target);
    const GrownTree t = grow(species, size_t(target), 3);
    const double n = double(t.mesh.triangleCount());
    QVERIFY2(std::fabs(n - target) <= 0.05 * target, qPrintable(QString("%1 triangles for %2").arg(n).arg(target)));
    QVERIFY(n <= target);  // the grower promises target or one less
    QVERIFY(n >= target - 1);
    size_t leaf = 0;
    for (size_t i = 0; i < t.mesh.triangleCount(); ++i) leaf += t.mesh.isLeafTriangle(i) ? 1 : 0;
    const double leafShare = double(leaf) / n;
    QVERIFY2(leafShare > 0.65 && leafShare < 0.999, qPrintable(QString("leaf share %1").arg(leafShare)));
    QVERIFY(leaf < size_t(n));  // some wood
}

void TstTreeGrower::meshValidity_data()
{
    QTest::addColumn<TreeSpecies>("species");
    QTest::addColumn<int>("target");
    for (TreeSpecies s : kAllSpecies)
        for (int target : {1000, 100000})
            QTest::newRow((speciesName(s) + "_" + std::to_string(target)).c_str()) << s << target;
}

void TstTreeGrower::meshValidity()
{
    QFETCH(TreeSpecies, species);
    QFETCH(int, target);
    const GrownTree t = grow(species, size_t(target), 11);
    const TriangleMesh& m = t.mesh;
    const size_t nv = m.positions.size();
    QCOMPARE(m.normals.size(), nv);
    QCOMPARE(m.uvs.size(), nv);
    QCOMPARE(m.triangleMaterial.size(), m.triangles.size());

    QCOMPARE(m.materials.size(), size_t(2));
    QCOMPARE(m.materials[0].name, std::string("bark"));
    QVERIFY(!m.materials[0].isLeaf);
    QVERIFY(m.materials[1].name.find("leaf") != std::string::npos);
    QVERIFY(m.materials[1].isLeaf);

    for (size_t v = 0; v < nv; ++v) {
        const glm::vec3& p = m.positions[v];
        const glm::vec3& n = m.normals[v];
        const glm::vec2& uv = m.uvs[v];
        QVERIFY(std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z));
        QVERIFY(std::isfinite(n.x) && std::isfinite(n.y) && std::isfinite(n.z));
        QVERIFY(std::isfinite(uv.x) && std::isfinite(uv.y));
        QVERIFY2(std::fabs(glm::length(n) - 1.0f) < 1e-3f, "normals are unit length");
        QVERIFY2(p.y >= -1e-4f, "nothing below the ground");
    }
    bool sawWood = false, sawLeaf = false;
    std::vector<char> leafVertex(nv, 0);
    for (size_t i = 0; i < m.triangles.size(); ++i) {
        const glm::uvec3& tri = m.triangles[i];
        QVERIFY(tri.x < nv && tri.y < nv && tri.z < nv);
        QVERIFY(tri.x != tri.y && tri.y != tri.z && tri.x != tri.z);
        const glm::vec3 a = m.positions[tri.x], b = m.positions[tri.y], c = m.positions[tri.z];
        const float area = 0.5f * glm::length(glm::cross(b - a, c - a));
        QVERIFY2(area > 1e-10f, qPrintable(QString("degenerate triangle %1, area %2").arg(i).arg(area)));
        QVERIFY(m.triangleMaterial[i] < 2);
        if (m.isLeafTriangle(i)) {
            sawLeaf = true;
            for (int c2 = 0; c2 < 3; ++c2) {
                const glm::vec2 uv = m.uvs[tri[c2]];
                QVERIFY2(uv.x >= 0 && uv.x <= 1 && uv.y >= 0 && uv.y <= 1, "leaf uvs in [0,1]");
                leafVertex[tri[c2]] = 1;
            }
            // The face normal agrees with the vertex normals (cards are flat).
            const glm::vec3 fn = glm::normalize(glm::cross(b - a, c - a));
            QVERIFY(glm::dot(fn, m.normals[tri.x]) > 0.99f);
        } else {
            sawWood = true;
        }
    }
    QVERIFY(sawWood && sawLeaf);
    // Leaves come after the wood and each card uses all four uv corners.
    const size_t firstLeaf = size_t(std::find(m.triangleMaterial.begin(), m.triangleMaterial.end(), 1u) -
                                    m.triangleMaterial.begin());
    QVERIFY(std::all_of(m.triangleMaterial.begin() + std::ptrdiff_t(firstLeaf), m.triangleMaterial.end(),
                        [](uint32_t x) { return x == 1u; }));
    QCOMPARE((m.triangles.size() - firstLeaf) % 2, size_t(0));
}

void TstTreeGrower::speciesShapes_data()
{
    QTest::addColumn<TreeSpecies>("species");
    QTest::addColumn<int>("seed");
    for (TreeSpecies s : kAllSpecies)
        for (int seed : {1, 2, 99})
            QTest::newRow((speciesName(s) + "_seed" + std::to_string(seed)).c_str()) << s << seed;
}

void TstTreeGrower::speciesShapes()
{
    QFETCH(TreeSpecies, species);
    QFETCH(int, seed);
    const GrownTree t = grow(species, 100000, uint64_t(seed));
    const Bounds3 b = meshBounds(t.mesh);
    const glm::vec3 e = b.extent();
    const float height = b.hi.y;
    const float width = std::max(e.x, e.z);
    QVERIFY(std::fabs(b.lo.y) < 0.05f);  // base at the origin
    // The trunk (or the stems) starts near the origin.
    QVERIFY(radial(t.mesh.positions[0]) < 1.0f);

    // Width of the leafy crown at a height band, from leaf vertices.
    auto crownRadius = [&](float y0, float y1) {
        float r = 0;
        for (size_t i = 0; i < t.mesh.triangleCount(); ++i)
            if (t.mesh.isLeafTriangle(i)) {
                const glm::vec3& p = t.mesh.positions[t.mesh.triangles[i].x];
                if (p.y >= y0 && p.y < y1) r = std::max(r, radial(p));
            }
        return r;
    };
    const QString what = QString("height %1 width %2").arg(height).arg(width);
    switch (species) {
    case TreeSpecies::Broadleaf:
        QVERIFY2(height > 10.0f && height < 15.0f, qPrintable(what));
        QVERIFY2(width > 6.0f && width < 14.0f, qPrintable(what));
        QVERIFY2(width / height > 0.5f, qPrintable(what));  // a round crown
        break;
    case TreeSpecies::Birch:
        QVERIFY2(height > 14.0f && height < 19.0f, qPrintable(what));
        QVERIFY2(width / height < 0.6f, qPrintable(what));  // slender
        break;
    case TreeSpecies::Conifer:
        QVERIFY2(height > 17.0f && height < 24.0f, qPrintable(what));
        QVERIFY2(width > 4.0f && width / height < 0.6f, qPrintable(what));
        // a cone: narrow at the top, wide low down
        QVERIFY2(crownRadius(0.8f * height, height) < 0.5f * crownRadius(0.1f * height, 0.4f * height), qPrintable(what));
        break;
    case TreeSpecies::Shrub:
        QVERIFY2(height > 1.2f && height < 3.0f, qPrintable(what));
        QVERIFY2(width > height, qPrintable(what));  // low and wide
        break;
    }
}

void TstTreeGrower::heightOption()
{
    for (TreeSpecies s : kAllSpecies) {
        const GrownTree def = grow(s, 20000, 5);
        QVERIFY(std::fabs(meshBounds(def.mesh).hi.y - defaultTreeHeight(s)) < 0.15f * defaultTreeHeight(s));
        const GrownTree tall = grow(s, 20000, 5, 2.0f * defaultTreeHeight(s));
        const float ratio = meshBounds(tall.mesh).hi.y / meshBounds(def.mesh).hi.y;
        QVERIFY2(ratio > 1.8f && ratio < 2.2f, qPrintable(QString("ratio %1").arg(ratio)));
    }
}

void TstTreeGrower::textures_data()
{
    QTest::addColumn<TreeSpecies>("species");
    for (TreeSpecies s : kAllSpecies) QTest::newRow(speciesName(s).c_str()) << s;
}

void TstTreeGrower::textures()
{
    QFETCH(TreeSpecies, species);
    const GrownTree t = grow(species, 1000);
    const ImageRgba& leaf = t.leafTexture;
    QVERIFY(leaf.width >= 64 && leaf.height >= 64);
    size_t opaque = 0, clear = 0, other = 0;
    for (size_t p = 0; p < size_t(leaf.width) * size_t(leaf.height); ++p) {
        const float a = leaf.pixels[p * 4 + 3];
        if (a == 0.0f) ++clear;
        else if (a == 1.0f) ++opaque;
        else ++other;
    }
    const double coverage = double(opaque) / double(opaque + clear + other);
    QVERIFY(opaque > 0 && clear > 0);
    QCOMPARE(other, size_t(0));  // a clean cut-out
    QVERIFY2(coverage > 0.08 && coverage < 0.8, qPrintable(QString("coverage %1").arg(coverage)));
    // Veins: the opaque texels are not a single flat colour.
    float gMin = 1, gMax = 0;
    for (size_t p = 0; p < size_t(leaf.width) * size_t(leaf.height); ++p)
        if (leaf.pixels[p * 4 + 3] == 1.0f) {
            gMin = std::min(gMin, leaf.pixels[p * 4 + 1]);
            gMax = std::max(gMax, leaf.pixels[p * 4 + 1]);
        }
    QVERIFY(gMax - gMin > 0.1f);
    // Bark: opaque, textured.
    const ImageRgba& bark = t.barkTexture;
    QVERIFY(!bark.empty());
    float rMin = 1, rMax = 0;
    for (size_t p = 0; p < size_t(bark.width) * size_t(bark.height); ++p) {
        QCOMPARE(bark.pixels[p * 4 + 3], 1.0f);
        rMin = std::min(rMin, bark.pixels[p * 4]);
        rMax = std::max(rMax, bark.pixels[p * 4]);
    }
    QVERIFY(rMax - rMin > 0.1f);
    // Each species its own leaf.
    for (TreeSpecies other2 : kAllSpecies)
        if (other2 != species) QVERIFY(!sameBytes(leaf.pixels, makeLeafTexture(other2, leaf.width).pixels));
}

void TstTreeGrower::writeGrownTree()
{
    const fs::path dir = outputDir("grown");
    const GrownTree t = grow(TreeSpecies::Broadleaf, 10000, 4);
    const fs::path objPath = dir / "sub" / "oak.obj";  // a folder that does not exist yet
    writeObj(objPath.string(), t);

    QVERIFY(fs::exists(objPath));
    for (const auto& entry : fs::recursive_directory_iterator(dir))
        QVERIFY2(entry.path().filename().string().rfind(".tmp.", 0) != 0, "no temporary files left behind");
    const ParsedObj obj = parseObj(objPath);
    QVERIFY2(obj.ok, obj.why.c_str());
    QCOMPARE(obj.v.size(), t.mesh.positions.size());
    QCOMPARE(obj.vt, t.mesh.uvs.size());
    QCOMPARE(obj.vn, t.mesh.normals.size());
    QCOMPARE(obj.faces.size(), t.mesh.triangleCount());
    QCOMPARE(obj.usemtl.size(), size_t(2));
    for (const auto& f : obj.faces)
        for (long idx : f) QVERIFY(idx >= 1 && idx <= long(obj.v.size()));
    // Faces reference the same vertices, in order; positions survive the text round trip exactly.
    for (size_t i = 0; i < obj.faces.size(); i += 97) {
        QCOMPARE(obj.faces[i][0], long(t.mesh.triangles[i].x) + 1);
        QCOMPARE(obj.faces[i][3], long(t.mesh.triangles[i].y) + 1);
        QCOMPARE(obj.faces[i][8], long(t.mesh.triangles[i].z) + 1);
    }
    for (size_t i = 0; i < obj.v.size(); i += 31) QCOMPARE(obj.v[i], t.mesh.positions[i]);

    QCOMPARE(obj.mtllib, std::string("oak.mtl"));
    const fs::path mtlPath = objPath.parent_path() / obj.mtllib;
    QVERIFY(fs::exists(mtlPath));
    const ParsedMtl mtl = parseMtl(mtlPath);
    QCOMPARE(mtl.materials.size(), size_t(2));
    QVERIFY(mtl.materials.count("bark"));
    QVERIFY(mtl.materials.count("leaf"));
    for (const std::string& used : obj.usemtl) QVERIFY(mtl.materials.count(used));
    for (const auto& [name, keys] : mtl.materials) {
        QVERIFY(keys.count("Kd"));
        QVERIFY(keys.count("map_Kd"));
        const fs::path tex = objPath.parent_path() / keys.at("map_Kd");
        QVERIFY2(fs::path(keys.at("map_Kd")).is_relative(), "texture paths relative to the OBJ");
        QVERIFY2(fs::exists(tex), tex.string().c_str());
    }
    const auto& leafKeys = mtl.materials.at("leaf");
    QVERIFY(leafKeys.count("map_d"));
    QCOMPARE(leafKeys.at("map_Kd"), std::string("oak_leaf.png"));
    QCOMPARE(mtl.materials.at("bark").at("map_Kd"), std::string("oak_bark.png"));
    const std::string leafPng = (objPath.parent_path() / leafKeys.at("map_d")).string();
    QVERIFY(imageHasAlpha(leafPng));
    const ImageRgba leaf = readImage(leafPng);
    bool zero = false, one = false;
    for (size_t p = 0; p < size_t(leaf.width) * size_t(leaf.height); ++p) {
        zero = zero || leaf.pixels[p * 4 + 3] == 0.0f;
        one = one || leaf.pixels[p * 4 + 3] == 1.0f;
    }
    QVERIFY(zero && one);

    // Writing the same tree twice gives the same bytes.
    const fs::path again = dir / "again" / "oak.obj";
    writeObj(again.string(), t);
    const std::string s1 = readText(objPath), s2 = readText(again);
    QVERIFY(!s1.empty());
    QVERIFY(s1 == s2);
}

void TstTreeGrower::writeGenericMesh()
{
    const fs::path dir = outputDir("generic");
    // A textured leaf material whose texture lives in a sibling folder.
    ImageRgba tex(4, 4, glm::vec4(0.2f, 0.5f, 0.1f, 1.0f));
    const fs::path texPath = dir / "textures" / "green leaf.png";
    writeImage(texPath.string(), tex);

    TriangleMesh m;
    m.positions = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {0, 0, 1}};
    m.normals = {{0, 0, 1}, {0, 0, 1}, {0, 0, 1}, {0, 0, 1}, {0, 1, 0}};
    m.triangles = {{0, 1, 2}, {0, 2, 3}, {0, 4, 1}};
    m.triangleMaterial = {0, 0, 1};
    Material wood;
    wood.name = "old wood";  // whitespace is not allowed in OBJ names
    Material leafMat;
    leafMat.name = "leaf";
    leafMat.isLeaf = true;
    leafMat.diffuseTexture = fs::absolute(texPath).string();
    m.materials = {wood, leafMat};
    const fs::path objPath = dir / "mesh" / "plain.obj";
    writeObj(objPath.string(), m);

    const std::string text = readText(objPath);
    QVERIFY(text.find("mtllib plain.mtl\n") != std::string::npos);
    QVERIFY(text.find("usemtl old_wood\n") != std::string::npos);
    QVERIFY(text.find("usemtl leaf\n") != std::string::npos);
    QVERIFY(text.find("f 1//1 2//2 3//3\n") != std::string::npos);  // normals but no uvs
    QVERIFY(text.find("vt ") == std::string::npos);
    const ParsedObj obj = parseObj(objPath);
    QCOMPARE(obj.v.size(), size_t(5));
    QCOMPARE(obj.faces.size(), size_t(3));
    const ParsedMtl mtl = parseMtl(objPath.parent_path() / "plain.mtl");
    QCOMPARE(mtl.materials.at("leaf").at("map_Kd"), std::string("../textures/green leaf.png"));
    QVERIFY(!mtl.materials.at("old_wood").count("map_Kd"));

    // Bad meshes are refused before anything is written.
    TriangleMesh bad = m;
    bad.triangles.push_back({0, 1, 9});
    bad.triangleMaterial.push_back(0);
    const fs::path badPath = dir / "bad.obj";
    try {
        writeObj(badPath.string(), bad);
        QFAIL("an out-of-range index must throw");
    } catch (const Error& e) {
        QVERIFY(std::string(e.what()).find("bad.obj") != std::string::npos);
    }
    QVERIFY(!fs::exists(badPath));
    bad = m;
    bad.triangleMaterial[0] = 5;
    QVERIFY_THROWS_EXCEPTION(Error, writeObj(badPath.string(), bad));
}

void TstTreeGrower::badInput()
{
    GrowOptions o;
    o.targetTriangles = 999;
    try {
        growTree(o);
        QFAIL("999 triangles must throw");
    } catch (const Error& e) {
        QVERIFY(std::string(e.what()).find("targetTriangles") != std::string::npos);
    }
    o.targetTriangles = 1000001;
    QVERIFY_THROWS_EXCEPTION(Error, growTree(o));
    o.targetTriangles = 0;
    QVERIFY_THROWS_EXCEPTION(Error, growTree(o));
    o.targetTriangles = 10000;
    o.height = -3;
    QVERIFY_THROWS_EXCEPTION(Error, growTree(o));
    o.height = std::nanf("");
    QVERIFY_THROWS_EXCEPTION(Error, growTree(o));
    o.height = 0;
    o.species = static_cast<TreeSpecies>(42);
    QVERIFY_THROWS_EXCEPTION(Error, growTree(o));
    try {
        speciesFromName("oak");
        QFAIL("an unknown species must throw");
    } catch (const Error& e) {
        QVERIFY(std::string(e.what()).find("oak") != std::string::npos);
        QVERIFY(std::string(e.what()).find("conifer") != std::string::npos);
    }

    // Unwritable output: the parent "folder" is a regular file.
    const fs::path dir = outputDir("bad");
    const fs::path blocker = dir / "not_a_folder";
    std::ofstream(blocker) << "x";
    const GrownTree t = grow(TreeSpecies::Shrub, 1000);
    const std::string objPath = (blocker / "tree.obj").string();
    try {
        writeObj(objPath, t);
        QFAIL("writing under a regular file must throw");
    } catch (const Error& e) {
        QVERIFY2(std::string(e.what()).find("tree.obj") != std::string::npos, e.what());
    }
    QVERIFY_THROWS_EXCEPTION(Error, writeObj(objPath, t.mesh));
    QVERIFY_THROWS_EXCEPTION(Error, writeObj("", t));
}

void TstTreeGrower::progressAndCancel()
{
    std::vector<double> fractions;
    Progress progress([&](double f, const std::string&) { fractions.push_back(f); });
    GrowOptions o;
    o.targetTriangles = 5000;
    growTree(o, &progress);
    QVERIFY(fractions.size() >= 3);
    QVERIFY(std::is_sorted(fractions.begin(), fractions.end()));
    QCOMPARE(fractions.back(), 1.0);

    Progress cancelling;
    cancelling.setCallback([&](double, const std::string&) { cancelling.cancel(); });
    QVERIFY_THROWS_EXCEPTION(Cancelled, growTree(o, &cancelling));
}

QTEST_APPLESS_MAIN(TstTreeGrower)
#include "tst_tree_grower.moc"
