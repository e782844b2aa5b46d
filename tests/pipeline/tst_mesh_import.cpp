// Mesh import: real trees (OBJ, textured OBJ, FBX), written glTF/PLY/DAE/OBJ files, clean-up and errors.
#include <QDir>
#include <QFile>
#include <QFileInfo>
#include <QTest>

#include <cmath>
#include <functional>
#include <map>
#include <random>
#include <set>
#include <string>
#include <vector>

#include "core/base/error.h"
#include "pipeline/import/mesh_cleanup.h"
#include "pipeline/import/mesh_import.h"

using namespace sylva;

namespace {

QString treesDir() { return QStringLiteral(SYLVA_RESOURCES "/trees/quaternius"); }

QString outputDir()
{
    const QString dir = QStringLiteral(SYLVA_TEST_OUTPUT "/mesh_import");
    QDir().mkpath(dir);
    return dir;
}

std::string writeFile(const QString& name, const QByteArray& content)
{
    const QString path = outputDir() + "/" + name;
    QDir().mkpath(QFileInfo(path).absolutePath());
    QFile f(path);
    if (!f.open(QIODevice::WriteOnly | QIODevice::Truncate)) qFatal("cannot write %s", qPrintable(path));
    f.write(content);
    return path.toStdString();
}

QByteArray readFile(const QString& path)
{
    QFile f(path);
    if (!f.open(QIODevice::ReadOnly)) qFatal("cannot read %s", qPrintable(path));
    return f.readAll();
}

// What an OBJ file holds, counted from its 'v', 'f' and 'usemtl' lines: an n-gon makes n-2
// triangles; a face whose corners sit on fewer than three distinct positions makes only degenerate
// ones (Birch_1 has three such quads).
struct ObjCounts {
    size_t triangles = 0, quads = 0, otherPolygons = 0, faces = 0;
    size_t collapsedTriangles = 0;                        // triangles of faces with < 3 distinct positions
    std::map<std::string, size_t> trianglesPerMaterial;  // kept (not collapsed) triangles
};

ObjCounts countObj(const QString& path)
{
    ObjCounts counts;
    std::string material;
    std::vector<QByteArray> positions;  // the 'v' lines' coordinate text
    for (const QByteArray& raw : readFile(path).split('\n')) {
        const QList<QByteArray> words = raw.simplified().split(' ');
        if (words.first() == "v" && words.size() >= 4) positions.push_back(words[1] + ' ' + words[2] + ' ' + words[3]);
        if (words.first() == "usemtl" && words.size() > 1) material = words[1].toStdString();
        if (words.first() != "f") continue;
        const size_t corners = size_t(words.size() - 1);
        std::set<QByteArray> distinct;
        for (qsizetype c = 1; c < words.size(); ++c) distinct.insert(positions.at(size_t(words[c].split('/')[0].toInt() - 1)));
        ++counts.faces;
        if (corners == 4) ++counts.quads;
        else if (corners != 3) ++counts.otherPolygons;
        counts.triangles += corners - 2;
        if (distinct.size() < 3) counts.collapsedTriangles += corners - 2;
        else counts.trianglesPerMaterial[material] += corners - 2;
    }
    return counts;
}

bool finite3(const glm::vec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

// The invariants every imported mesh keeps; returns an empty string or what is wrong.
QString meshProblem(const TriangleMesh& mesh)
{
    if (mesh.triangles.empty()) return "no triangles";
    if (mesh.normals.size() != mesh.positions.size()) return "normals not per vertex";
    if (!mesh.uvs.empty() && mesh.uvs.size() != mesh.positions.size()) return "uvs not per vertex";
    if (mesh.triangleMaterial.size() != mesh.triangles.size()) return "triangleMaterial not per triangle";
    for (size_t t = 0; t < mesh.triangles.size(); ++t) {
        for (int c = 0; c < 3; ++c)
            if (mesh.triangles[t][c] >= mesh.positions.size()) return QString("triangle %1 index out of range").arg(t);
        if (mesh.triangleMaterial[t] >= mesh.materials.size()) return QString("triangle %1 material out of range").arg(t);
    }
    for (size_t v = 0; v < mesh.positions.size(); ++v) {
        if (!finite3(mesh.positions[v])) return QString("vertex %1 not finite").arg(v);
        if (std::fabs(glm::length(mesh.normals[v]) - 1.0f) > 1e-4f) return QString("normal %1 not unit").arg(v);
    }
    return {};
}

double totalArea(const TriangleMesh& mesh)
{
    double area = 0;
    for (const auto& t : mesh.triangles) {
        const glm::dvec3 a(mesh.positions[t[0]]), b(mesh.positions[t[1]]), c(mesh.positions[t[2]]);
        area += 0.5 * glm::length(glm::cross(b - a, c - a));
    }
    return area;
}

const Material* findMaterial(const TriangleMesh& mesh, const std::string& name)
{
    for (const Material& m : mesh.materials)
        if (m.name == name) return &m;
    return nullptr;
}

// Runs f, expects a sylva::Error whose message names the path; returns the message.
QString expectError(const std::string& path, const std::function<void()>& f)
{
    try {
        f();
    } catch (const Error& e) {
        const QString message = QString::fromStdString(e.what());
        if (!message.contains(QString::fromStdString(path))) return "MESSAGE LACKS PATH: " + message;
        return message;
    } catch (const std::exception& e) {
        return QString("WRONG EXCEPTION TYPE: ") + e.what();
    }
    return "NO ERROR";
}

bool hasWarningContaining(const ImportReport& report, const QString& text)
{
    for (const std::string& w : report.warnings)
        if (QString::fromStdString(w).contains(text)) return true;
    return false;
}

// A copy of Tree_1 (OBJ_textured) whose leaf material is renamed "Crown" (no leaf word in it), with
// the given MTL body for Crown; Bark keeps its bark texture. Textures are named by absolute path.
std::string crownVariant(const QString& name, const QByteArray& crownLines)
{
    const QString src = treesDir() + "/OBJ_textured/Tree_1.obj";
    QByteArray obj = readFile(src);
    obj.replace("mtllib Tree_1.mtl", "mtllib " + name.toUtf8() + ".mtl");
    obj.replace("usemtl Tree_Leaves", "usemtl Crown");
    const QByteArray textures = (treesDir() + "/Textures/").toUtf8();
    QByteArray mtl = "newmtl Bark\nKd 1 1 1\nmap_Kd " + textures + "Tree_Bark.jpg\n\nnewmtl Crown\nKd 1 1 1\n";
    mtl += QByteArray(crownLines).replace("$T/", textures);
    writeFile("crown/" + name + ".mtl", mtl);
    return writeFile("crown/" + name + ".obj", obj);
}

} // namespace

class TestMeshImport : public QObject {
    Q_OBJECT
private Q_SLOTS:
    // Every real tree: n-gons become n-2 triangles each (quads 2), counted independently from the
    // file; only the triangles of collapsed faces are dropped; leaf triangles are those of the
    // *Leaves materials.
    void realObjTrees_data()
    {
        QTest::addColumn<QString>("file");
        QVERIFY2(QDir(treesDir() + "/OBJ").exists(), qPrintable(treesDir()));
        const QStringList objs = QDir(treesDir() + "/OBJ").entryList({"*.obj"}, QDir::Files, QDir::Name);
        QVERIFY(objs.size() >= 4);
        for (const QString& obj : objs) QTest::newRow(qPrintable(obj)) << treesDir() + "/OBJ/" + obj;
    }
    void realObjTrees()
    {
        QFETCH(QString, file);
        const ObjCounts counts = countObj(file);
        QVERIFY(counts.quads > 0);
        ImportReport report;
        const TriangleMesh mesh = importMesh(file.toStdString(), {}, &report);
        QCOMPARE(meshProblem(mesh), QString());
        QCOMPARE(report.inputTriangles, counts.triangles);
        QCOMPARE(report.droppedDegenerate, counts.collapsedTriangles);
        QCOMPARE(report.droppedNonFinite, size_t(0));
        QCOMPARE(mesh.triangleCount(), counts.triangles - counts.collapsedTriangles);
        QVERIFY(report.weldedVertices > 0);  // Assimp's OBJ reader gives every face corner its own vertex
        QVERIFY(!mesh.uvs.empty());

        size_t leaf = 0;
        for (const auto& [name, n] : counts.trianglesPerMaterial)
            if (QString::fromStdString(name).contains("Leaves")) leaf += n;
        QCOMPARE(report.leafTriangles, leaf);
        QCOMPARE(report.woodTriangles, mesh.triangleCount() - leaf);
        QCOMPARE(mesh.materials.size(), counts.trianglesPerMaterial.size());
        for (const Material& m : mesh.materials) {
            QCOMPARE(m.isLeaf, QString::fromStdString(m.name).contains("Leaves"));
            QVERIFY(m.diffuseTexture.empty() && m.alphaTexture.empty());
            QCOMPARE(m.diffuse, glm::vec3(0.64f));
        }
        const Bounds3 b = meshBounds(mesh);
        QVERIFY(b.valid() && b.extent().y > 1.0f && b.extent().y < 100.0f);
    }

    // Bark and leaves have identical properties in the MTL; they must stay two materials.
    void objLeafWoodSplitKeepsIdenticalMaterials()
    {
        const QString file = treesDir() + "/OBJ/Tree_1.obj";
        QVERIFY2(QFile::exists(file), qPrintable(file));
        ImportReport report;
        const TriangleMesh mesh = importMesh(file.toStdString(), {}, &report);
        QCOMPARE(mesh.materials.size(), size_t(2));
        const Material* bark = findMaterial(mesh, "Bark");
        const Material* leaves = findMaterial(mesh, "Tree_Leaves");
        QVERIFY(bark && leaves);
        QCOMPARE(bark->diffuse, leaves->diffuse);
        QVERIFY(!bark->isLeaf);
        QVERIFY(leaves->isLeaf);
        QVERIFY(report.leafTriangles > 0 && report.woodTriangles > 0);
        const QString text = QString::fromStdString(describeMesh(mesh));
        QVERIFY2(text.contains("Tree_Leaves: leaf") && text.contains("Bark: wood"), qPrintable(text));
        QVERIFY2(text.contains(QString("triangles: %1").arg(mesh.triangleCount())), qPrintable(text));
    }

    // Textures named relative to the MTL resolve to existing absolute files; leaves by their map_d.
    void objTexturedResolvesTextures_data()
    {
        QTest::addColumn<QString>("file");
        QVERIFY2(QDir(treesDir() + "/OBJ_textured").exists(), qPrintable(treesDir()));
        for (const char* tree : {"Tree_1", "Birch_1", "Pine_1", "DeadTree_1"})
            QTest::newRow(tree) << treesDir() + "/OBJ_textured/" + tree + ".obj";
    }
    void objTexturedResolvesTextures()
    {
        QFETCH(QString, file);
        ImportReport report;
        const TriangleMesh mesh = importMesh(file.toStdString(), {}, &report);
        QCOMPARE(meshProblem(mesh), QString());
        QVERIFY2(report.warnings.empty(), report.warnings.empty() ? "" : report.warnings.front().c_str());
        const ObjCounts counts = countObj(file);
        QCOMPARE(mesh.triangleCount(), counts.triangles - counts.collapsedTriangles);
        const QString textures = QFileInfo(treesDir() + "/Textures").canonicalFilePath();
        for (const Material& m : mesh.materials) {
            const QFileInfo diffuse(QString::fromStdString(m.diffuseTexture));
            QVERIFY2(diffuse.isAbsolute() && diffuse.isFile(), m.diffuseTexture.c_str());
            QCOMPARE(diffuse.canonicalPath(), textures);
            QCOMPARE(m.diffuse, glm::vec3(1.0f));
            if (m.isLeaf) {
                const QFileInfo alpha(QString::fromStdString(m.alphaTexture));
                QVERIFY2(alpha.isAbsolute() && alpha.isFile(), m.alphaTexture.c_str());
                QVERIFY(alpha.fileName().contains("Leaves"));
            } else {
                QVERIFY(m.alphaTexture.empty());
                QVERIFY(!QString::fromStdString(m.name).contains("Leaves"));
            }
        }
        if (!file.contains("DeadTree")) QVERIFY(report.leafTriangles > 0);
        QVERIFY(report.woodTriangles > 0);
    }

    // Leaf detection from textures alone (material named "Crown"): by map_d, by an RGBA map_Kd;
    // without textures it is wood; a missing texture is a warning and an empty path.
    void leafDetectionFromTextures()
    {
        QVERIFY2(QDir(treesDir() + "/OBJ_textured").exists(), qPrintable(treesDir()));
        const size_t leafTriangles = countObj(treesDir() + "/OBJ/Tree_1.obj").trianglesPerMaterial["Tree_Leaves"];
        QVERIFY(leafTriangles > 0);

        ImportReport report;
        TriangleMesh mesh = importMesh(crownVariant("opacity_map", "map_d $T/Tree_Leaves.png\n"), {}, &report);
        QVERIFY(findMaterial(mesh, "Crown")->isLeaf);
        QVERIFY(!findMaterial(mesh, "Crown")->alphaTexture.empty());
        QVERIFY(findMaterial(mesh, "Crown")->diffuseTexture.empty());
        QCOMPARE(report.leafTriangles, leafTriangles);

        mesh = importMesh(crownVariant("rgba_diffuse", "map_Kd $T/Tree_Leaves.png\n"), {}, &report);
        QVERIFY(findMaterial(mesh, "Crown")->isLeaf);
        QVERIFY(findMaterial(mesh, "Crown")->alphaTexture.empty());
        QVERIFY(!findMaterial(mesh, "Bark")->isLeaf);  // Tree_Bark.jpg has no alpha
        QCOMPARE(report.leafTriangles, leafTriangles);

        mesh = importMesh(crownVariant("untextured", ""), {}, &report);
        QVERIFY(!findMaterial(mesh, "Crown")->isLeaf);
        QCOMPARE(report.leafTriangles, size_t(0));

        mesh = importMesh(crownVariant("missing_texture", "map_Kd no_such_texture.png\n"), {}, &report);
        QVERIFY(!findMaterial(mesh, "Crown")->isLeaf);
        QVERIFY(findMaterial(mesh, "Crown")->diffuseTexture.empty());
        QVERIFY(hasWarningContaining(report, "no_such_texture.png"));
    }

    void fbxTrees_data()
    {
        QTest::addColumn<QString>("file");
        QVERIFY2(QDir(treesDir() + "/FBX").exists(), qPrintable(treesDir()));
        const QStringList files = QDir(treesDir() + "/FBX").entryList({"*.fbx"}, QDir::Files, QDir::Name);
        QVERIFY(!files.isEmpty());
        for (const QString& f : files) QTest::newRow(qPrintable(f)) << treesDir() + "/FBX/" + f;
    }
    void fbxTrees()
    {
        QFETCH(QString, file);
        ImportReport report;
        const TriangleMesh mesh = importMesh(file.toStdString(), {}, &report);
        QCOMPARE(meshProblem(mesh), QString());
        QCOMPARE(mesh.triangleCount(), report.inputTriangles - report.droppedDegenerate - report.droppedNonFinite);
        QCOMPARE(report.leafTriangles + report.woodTriangles, mesh.triangleCount());
        QVERIFY(report.leafTriangles > 0);
        QVERIFY(report.woodTriangles > 0);
        QVERIFY(mesh.materials.size() >= 2);
        const Bounds3 b = meshBounds(mesh);  // Blender's FBX is in centimetres; we want metres, y up
        QVERIFY2(b.valid() && b.extent().y > 3.0f && b.extent().y < 15.0f, describeMesh(mesh).c_str());
        QVERIFY(b.lo.y > -0.01f);
        qInfo().noquote() << QFileInfo(file).fileName() << "\n" << QString::fromStdString(describeMesh(mesh));
    }

    // glTF with an embedded buffer: one quad mesh instanced by a parent(translate)/child(scale) pair
    // and by a mirrored node. Transforms compose, the mirror keeps the front face, MASK is leaf.
    void gltfEmbeddedWithNodeTransforms()
    {
        QByteArray buffer;
        const float positions[] = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0};
        const uint16_t indices[] = {0, 1, 2, 0, 2, 3};
        buffer.append(reinterpret_cast<const char*>(positions), sizeof positions);
        buffer.append(reinterpret_cast<const char*>(indices), sizeof indices);
        const QByteArray json = "{\n"
            "  \"asset\": {\"version\": \"2.0\"},\n"
            "  \"scene\": 0,\n"
            "  \"scenes\": [{\"nodes\": [0, 2]}],\n"
            "  \"nodes\": [\n"
            "    {\"name\": \"parent\", \"translation\": [10, 0, 0], \"children\": [1]},\n"
            "    {\"name\": \"child\", \"scale\": [2, 2, 2], \"mesh\": 0},\n"
            "    {\"name\": \"mirror\", \"scale\": [-1, 1, 1], \"mesh\": 0}\n"
            "  ],\n"
            "  \"meshes\": [{\"primitives\": [{\"attributes\": {\"POSITION\": 0}, \"indices\": 1, \"material\": 0}]}],\n"
            "  \"materials\": [{\"name\": \"Crown\", \"alphaMode\": \"MASK\",\n"
            "                 \"pbrMetallicRoughness\": {\"baseColorFactor\": [0.25, 0.5, 0.125, 1.0]}}],\n"
            "  \"accessors\": [\n"
            "    {\"bufferView\": 0, \"componentType\": 5126, \"count\": 4, \"type\": \"VEC3\", \"min\": [0, 0, 0], \"max\": [1, 1, 0]},\n"
            "    {\"bufferView\": 1, \"componentType\": 5123, \"count\": 6, \"type\": \"SCALAR\"}\n"
            "  ],\n"
            "  \"bufferViews\": [\n"
            "    {\"buffer\": 0, \"byteOffset\": 0, \"byteLength\": 48, \"target\": 34962},\n"
            "    {\"buffer\": 0, \"byteOffset\": 48, \"byteLength\": 12, \"target\": 34963}\n"
            "  ],\n"
            "  \"buffers\": [{\"byteLength\": 60, \"uri\": \"data:application/octet-stream;base64," + buffer.toBase64() + "\"}]\n"
            "}";
        const std::string path = writeFile("quad.gltf", json);
        ImportReport report;
        const TriangleMesh mesh = importMesh(path, {}, &report);
        QCOMPARE(meshProblem(mesh), QString());
        QCOMPARE(mesh.triangleCount(), size_t(4));
        QCOMPARE(mesh.positions.size(), size_t(8));
        const Bounds3 b = meshBounds(mesh);
        QCOMPARE(b.lo, glm::vec3(-1, 0, 0));
        QCOMPARE(b.hi, glm::vec3(12, 2, 0));
        QCOMPARE(std::fabs(totalArea(mesh) - 5.0) < 1e-6, true);  // 2x2 quad + 1x1 quad
        for (const glm::vec3& n : mesh.normals) QCOMPARE(n, glm::vec3(0, 0, 1));
        for (const auto& t : mesh.triangles) {  // counter-clockwise seen from +z, mirrored or not
            const glm::vec3 a = mesh.positions[t[0]], bb = mesh.positions[t[1]], c = mesh.positions[t[2]];
            QVERIFY(glm::cross(bb - a, c - a).z > 0.0f);
        }
        QCOMPARE(mesh.materials.size(), size_t(1));
        QVERIFY(mesh.materials[0].isLeaf);
        QCOMPARE(mesh.materials[0].diffuse, glm::vec3(0.25f, 0.5f, 0.125f));
        QCOMPARE(report.leafTriangles, size_t(4));
    }

    // ASCII PLY with a quad and a triangle; no materials in the file: one default (wood) material.
    void plyAscii()
    {
        const std::string path = writeFile("quad_and_triangle.ply", "ply\nformat ascii 1.0\n"
                                                                    "element vertex 5\n"
                                                                    "property float x\nproperty float y\nproperty float z\n"
                                                                    "element face 2\n"
                                                                    "property list uchar int vertex_indices\n"
                                                                    "end_header\n"
                                                                    "0 0 0\n1 0 0\n1 1 0\n0 1 0\n2 0 0\n"
                                                                    "4 0 1 2 3\n3 1 4 2\n");
        ImportReport report;
        const TriangleMesh mesh = importMesh(path, {}, &report);
        QCOMPARE(meshProblem(mesh), QString());
        QCOMPARE(report.inputTriangles, size_t(3));
        QCOMPARE(mesh.triangleCount(), size_t(3));
        QCOMPARE(mesh.positions.size(), size_t(5));
        QVERIFY(std::fabs(totalArea(mesh) - 1.5) < 1e-6);
        for (const glm::vec3& n : mesh.normals) QCOMPARE(n, glm::vec3(0, 0, 1));
        QCOMPARE(report.woodTriangles, size_t(3));
    }

    // COLLADA: a quad (polylist) of "Bark" and a triangle of "PineNeedles" under a translating node.
    void daeWithMaterialsAndTransform()
    {
        const std::string path = writeFile("two_materials.dae", "<?xml version=\"1.0\" encoding=\"utf-8\"?>\n"
            "<COLLADA xmlns=\"http://www.collada.org/2005/11/COLLADASchema\" version=\"1.4.1\">\n"
            "  <asset><unit name=\"meter\" meter=\"1\"/><up_axis>Y_UP</up_axis></asset>\n"
            "  <library_effects>\n"
            "    <effect id=\"bark-fx\"><profile_COMMON><technique sid=\"common\"><lambert>\n"
            "      <diffuse><color>0.4 0.3 0.2 1</color></diffuse></lambert></technique></profile_COMMON></effect>\n"
            "    <effect id=\"needle-fx\"><profile_COMMON><technique sid=\"common\"><lambert>\n"
            "      <diffuse><color>0.1 0.4 0.1 1</color></diffuse></lambert></technique></profile_COMMON></effect>\n"
            "  </library_effects>\n"
            "  <library_materials>\n"
            "    <material id=\"bark-mat\" name=\"Bark\"><instance_effect url=\"#bark-fx\"/></material>\n"
            "    <material id=\"needle-mat\" name=\"PineNeedles\"><instance_effect url=\"#needle-fx\"/></material>\n"
            "  </library_materials>\n"
            "  <library_geometries>\n"
            "    <geometry id=\"shape\" name=\"shape\"><mesh>\n"
            "      <source id=\"shape-pos\">\n"
            "        <float_array id=\"shape-pos-array\" count=\"18\">0 0 0 1 0 0 1 1 0 0 1 0 0 0 1 1 0 1</float_array>\n"
            "        <technique_common><accessor source=\"#shape-pos-array\" count=\"6\" stride=\"3\">\n"
            "          <param name=\"X\" type=\"float\"/><param name=\"Y\" type=\"float\"/><param name=\"Z\" type=\"float\"/>\n"
            "        </accessor></technique_common>\n"
            "      </source>\n"
            "      <vertices id=\"shape-vtx\"><input semantic=\"POSITION\" source=\"#shape-pos\"/></vertices>\n"
            "      <polylist material=\"barkSym\" count=\"1\"><input semantic=\"VERTEX\" source=\"#shape-vtx\" offset=\"0\"/>\n"
            "        <vcount>4</vcount><p>0 1 2 3</p></polylist>\n"
            "      <triangles material=\"needleSym\" count=\"1\"><input semantic=\"VERTEX\" source=\"#shape-vtx\" offset=\"0\"/>\n"
            "        <p>0 4 5</p></triangles>\n"
            "    </mesh></geometry>\n"
            "  </library_geometries>\n"
            "  <library_visual_scenes>\n"
            "    <visual_scene id=\"scene\"><node id=\"tree\" name=\"tree\">\n"
            "      <matrix>1 0 0 5 0 1 0 0 0 0 1 0 0 0 0 1</matrix>\n"
            "      <instance_geometry url=\"#shape\"><bind_material><technique_common>\n"
            "        <instance_material symbol=\"barkSym\" target=\"#bark-mat\"/>\n"
            "        <instance_material symbol=\"needleSym\" target=\"#needle-mat\"/>\n"
            "      </technique_common></bind_material></instance_geometry>\n"
            "    </node></visual_scene>\n"
            "  </library_visual_scenes>\n"
            "  <scene><instance_visual_scene url=\"#scene\"/></scene>\n"
            "</COLLADA>\n");
        ImportReport report;
        const TriangleMesh mesh = importMesh(path, {}, &report);
        QCOMPARE(meshProblem(mesh), QString());
        QCOMPARE(mesh.triangleCount(), size_t(3));
        const Bounds3 b = meshBounds(mesh);
        QCOMPARE(b.lo, glm::vec3(5, 0, 0));
        QCOMPARE(b.hi, glm::vec3(6, 1, 1));
        QCOMPARE(report.leafTriangles, size_t(1));
        QCOMPARE(report.woodTriangles, size_t(2));
        const Material* bark = findMaterial(mesh, "Bark");
        QVERIFY2(bark, describeMesh(mesh).c_str());
        QVERIFY(!bark->isLeaf);
        QCOMPARE(bark->diffuse, glm::vec3(0.4f, 0.3f, 0.2f));
        const Material* needles = findMaterial(mesh, "PineNeedles");
        QVERIFY(needles && needles->isLeaf);
    }

    // --leaf-materials: exactly the named materials (any case) are leaf; unknown names warn.
    void leafMaterialsOverride()
    {
        writeFile("override/two.mtl", "newmtl Bark\nKd 0.5 0.4 0.3\n\nnewmtl Leaves\nKd 0.2 0.6 0.2\n");
        const std::string path = writeFile("override/two.obj", "mtllib two.mtl\n"
                                                               "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n"
                                                               "usemtl Bark\nf 1 2 3\n"
                                                               "usemtl Leaves\nf 1 3 4\n");
        ImportReport report;
        TriangleMesh mesh = importMesh(path, {}, &report);
        QVERIFY(!findMaterial(mesh, "Bark")->isLeaf);
        QVERIFY(findMaterial(mesh, "Leaves")->isLeaf);
        QCOMPARE(findMaterial(mesh, "Bark")->diffuse, glm::vec3(0.5f, 0.4f, 0.3f));

        ImportOptions options;
        options.leafMaterials = {"bARK", "NoSuchMaterial"};
        mesh = importMesh(path, options, &report);
        QVERIFY(findMaterial(mesh, "Bark")->isLeaf);
        QVERIFY(!findMaterial(mesh, "Leaves")->isLeaf);
        QCOMPARE(report.leafTriangles, size_t(1));
        QCOMPARE(report.woodTriangles, size_t(1));
        QVERIFY(hasWarningContaining(report, "NoSuchMaterial"));

        const QString tree = treesDir() + "/OBJ/Tree_1.obj";
        if (!QFile::exists(tree)) return;
        options.leafMaterials = {"bark"};
        mesh = importMesh(tree.toStdString(), options, &report);
        QVERIFY(findMaterial(mesh, "Bark")->isLeaf);
        QVERIFY(!findMaterial(mesh, "Tree_Leaves")->isLeaf);
        QCOMPARE(report.leafTriangles, countObj(tree).trianglesPerMaterial["Bark"]);
    }

    // Two triangles of a square written with separate (duplicate) vertices weld into four vertices;
    // not with weld off; not across a uv seam.
    void duplicateVerticesWelded()
    {
        const std::string path = writeFile("duplicates.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\n"
                                                             "v 0 0 0\nv 1 1 0\nv 0 1 0\n"
                                                             "f 1 2 3\nf 4 5 6\n");
        ImportReport report;
        TriangleMesh mesh = importMesh(path, {}, &report);
        QCOMPARE(mesh.positions.size(), size_t(4));
        QCOMPARE(report.weldedVertices, size_t(2));
        QCOMPARE(mesh.triangleCount(), size_t(2));

        ImportOptions noWeld;
        noWeld.weld = false;
        mesh = importMesh(path, noWeld, &report);
        QCOMPARE(mesh.positions.size(), size_t(6));
        QCOMPARE(report.weldedVertices, size_t(0));

        // Same positions, but the second triangle's corners on the shared edge have other uvs.
        const std::string seam = writeFile("uv_seam.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n"
                                                          "vt 0 0\nvt 1 0\nvt 1 1\nvt 0.5 0.5\nvt 0.7 0.7\nvt 0 1\n"
                                                          "f 1/1 2/2 3/3\nf 1/4 3/5 4/6\n");
        mesh = importMesh(seam, {}, &report);
        QCOMPARE(mesh.positions.size(), size_t(6));
        QCOMPARE(report.weldedVertices, size_t(0));
        QCOMPARE(mesh.uvs.size(), size_t(6));
        std::set<std::pair<float, float>> uvs;
        for (const glm::vec2& uv : mesh.uvs) uvs.insert({uv.x, uv.y});
        QCOMPARE(uvs.size(), size_t(6));
        QVERIFY(uvs.count({0.5f, 0.5f}) && uvs.count({0.7f, 0.7f}));
    }

    // A repeated-vertex triangle, a collinear triangle and a triangle with a NaN corner are dropped.
    void degenerateAndNonFiniteDropped()
    {
        const std::string path = writeFile("bad_faces.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\n"
                                                            "v 2 0 0\n"
                                                            "v nan 0 0\n"
                                                            "f 1 2 3\n"   // good
                                                            "f 1 2 2\n"   // repeated vertex
                                                            "f 1 2 4\n"   // collinear: zero area
                                                            "f 1 5 3\n"); // NaN corner
        ImportReport report;
        const TriangleMesh mesh = importMesh(path, {}, &report);
        QCOMPARE(meshProblem(mesh), QString());
        QCOMPARE(report.inputTriangles, size_t(4));
        QCOMPARE(report.droppedDegenerate, size_t(2));
        QCOMPARE(report.droppedNonFinite, size_t(1));
        QCOMPARE(mesh.triangleCount(), size_t(1));
        QCOMPARE(mesh.positions.size(), size_t(3));
    }

    // A quad and a pentagon become 2 + 3 triangles covering the same area.
    void polygonsTriangulated()
    {
        const std::string path = writeFile("polygons.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n"
                                                           "v 3 0 0\nv 4 0 0\nv 4.5 1 0\nv 3.5 2 0\nv 2.5 1 0\n"
                                                           "f 1 2 3 4\nf 5 6 7 8 9\n");
        ImportReport report;
        const TriangleMesh mesh = importMesh(path, {}, &report);
        QCOMPARE(meshProblem(mesh), QString());
        QCOMPARE(report.inputTriangles, size_t(5));
        QCOMPARE(mesh.triangleCount(), size_t(5));
        QVERIFY(std::fabs(totalArea(mesh) - (1.0 + 2.5)) < 1e-6);  // unit square + pentagon of area 2.5
    }

    // The clean-up itself triangulates polygons (here without Assimp) and keeps each face's material.
    void cleanupTriangulatesPolygonsKeepingMaterials()
    {
        PolygonSoup soup;
        soup.positions = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {3, 0, 0}, {4, 0, 0}, {4.5f, 1, 0}, {3.5f, 2, 0},
                          {2.5f, 1, 0}};
        const uint32_t quad[] = {0, 1, 2, 3}, pentagon[] = {4, 5, 6, 7, 8};
        soup.addFace(quad, 4, 7);
        soup.addFace(pentagon, 5, 3);
        CleanupStats stats;
        const TriangleMesh mesh = cleanupMesh(soup, {}, &stats);
        QCOMPARE(stats.inputTriangles, size_t(5));
        QCOMPARE(mesh.triangleCount(), size_t(5));
        std::map<uint32_t, int> perMaterial;
        for (uint32_t m : mesh.triangleMaterial) ++perMaterial[m];
        QCOMPARE(perMaterial[7], 2);
        QCOMPARE(perMaterial[3], 3);
        QVERIFY(std::fabs(totalArea(mesh) - 3.5) < 1e-6);
        for (const glm::vec3& n : mesh.normals) QCOMPARE(n, glm::vec3(0, 0, 1));
    }

    // Non-manifold input (three triangles on one edge, two fans touching at a vertex) is kept whole.
    void cleanupKeepsNonManifoldFaces()
    {
        PolygonSoup soup;
        soup.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}};
        const uint32_t faces[][3] = {{0, 1, 2}, {1, 0, 3}, {0, 1, 4}};
        for (const auto& f : faces) soup.addFace(f, 3, 0);
        CleanupStats stats;
        const TriangleMesh mesh = cleanupMesh(soup, {}, &stats);
        QCOMPARE(mesh.triangleCount(), size_t(3));
        QCOMPARE(mesh.positions.size(), size_t(5));  // the copies OpenMesh needed are shared again
        QVERIFY(stats.nonManifoldFaces >= 1);
    }

    // Without normals in the file: unit normals facing the counter-clockwise side; planar -> exact.
    void normalsComputed()
    {
        const std::string path = writeFile("plane_no_normals.obj", "v 0 0 0\nv 2 0 0\nv 2 0 -2\nv 0 0 -2\nv 1 0 -1\n"
                                                                   "f 1 2 5\nf 2 3 5\nf 3 4 5\nf 4 1 5\n");
        const TriangleMesh mesh = importMesh(path);
        QCOMPARE(meshProblem(mesh), QString());
        QCOMPARE(mesh.normals.size(), size_t(5));
        for (const glm::vec3& n : mesh.normals) {
            QVERIFY(std::fabs(glm::length(n) - 1.0f) < 1e-6f);
            QVERIFY2(glm::length(n - glm::vec3(0, 1, 0)) < 1e-6f, qPrintable(QString("%1 %2 %3").arg(n.x).arg(n.y).arg(n.z)));
        }
        // A tent: the ridge vertices average the two slopes, each slope's corner keeps its own.
        const std::string tent = writeFile("tent.obj", "v 0 0 0\nv 1 1 0\nv 2 0 0\nv 0 0 -1\nv 1 1 -1\nv 2 0 -1\n"
                                                       "f 1 2 5 4\nf 2 3 6 5\n");
        const TriangleMesh t = importMesh(tent);
        QCOMPARE(meshProblem(t), QString());
        for (size_t v = 0; v < t.positions.size(); ++v) {
            const glm::vec3 p = t.positions[v], n = t.normals[v];
            const glm::vec3 expected = p.x == 1.0f ? glm::vec3(0, 1, 0)
                                                   : glm::normalize(glm::vec3(p.x < 1.0f ? -1.0f : 1.0f, 1, 0));
            QVERIFY2(glm::length(n - expected) < 1e-5f, qPrintable(QString("%1 %2 %3").arg(n.x).arg(n.y).arg(n.z)));
        }
    }

    void errorsNameTheFile()
    {
        const std::string missing = (outputDir() + "/no_such_mesh.obj").toStdString();
        QFile::remove(QString::fromStdString(missing));
        QString message = expectError(missing, [&] { importMesh(missing); });
        QVERIFY2(message.contains("no such file"), qPrintable(message));

        std::mt19937 rng(42);
        QByteArray noise;
        for (int i = 0; i < 4096; ++i) noise.append(char(rng() & 0xff));
        for (const char* name : {"garbage.obj", "garbage.fbx", "garbage.glb", "garbage.ply", "garbage.dae", "garbage.xyz"}) {
            const std::string garbage = writeFile(name, noise);
            message = expectError(garbage, [&] { importMesh(garbage); });
            QVERIFY2(!message.startsWith("NO ERROR") && !message.startsWith("MESSAGE LACKS") &&
                         !message.startsWith("WRONG"),
                     qPrintable(QString(name) + ": " + message));
        }
        const std::string text = writeFile("not_a_mesh.obj", "this is a shopping list\nmilk\nbread\n");
        message = expectError(text, [&] { importMesh(text); });
        QVERIFY2(!message.startsWith("NO ERROR") && !message.startsWith("MESSAGE LACKS"), qPrintable(message));

        const std::string empty = writeFile("empty.obj", "");
        message = expectError(empty, [&] { importMesh(empty); });
        QVERIFY2(message.contains("empty"), qPrintable(message));

        const std::string onlyDegenerate =
            writeFile("only_degenerate.obj", "v 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\nf 1 1 2\n");
        message = expectError(onlyDegenerate, [&] { importMesh(onlyDegenerate); });
        QVERIFY2(message.contains("no triangles"), qPrintable(message));

        const std::string points = writeFile("only_points.obj", "v 0 0 0\nv 1 0 0\np 1 2\n");
        message = expectError(points, [&] { importMesh(points); });
        QVERIFY2(!message.startsWith("NO ERROR") && !message.startsWith("MESSAGE LACKS"), qPrintable(message));

        const std::string folder = outputDir().toStdString();
        message = expectError(folder, [&] { importMesh(folder); });
        QVERIFY2(message.contains("folder"), qPrintable(message));
    }
};

QTEST_GUILESS_MAIN(TestMeshImport)
#include "tst_mesh_import.moc"
