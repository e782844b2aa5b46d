// The glTF export (pipeline/services/gltf_export.h, sylva export -o FILE.glb) read back by a reader of its own,
// written here from the glTF 2.0 specification (GLB header and chunks, the JSON through QJsonDocument, accessors
// through their bufferViews): each instance's world matrix from TRANSLATION / ROTATION / SCALE against the map the
// renderer builds for it (makeInstance, composeInstances for group members, landPlantInstance for landscape
// plants), counts per species, the container's alignment rules, accessor bounds, materials' alpha modes and
// embedded images; the limit; the command line; and, where node has them, the Khronos glTF validator and glTF
// Transform's inspect.
#include <QDir>
#include <QFile>
#include <QImage>
#include <QJsonArray>
#include <QJsonDocument>
#include <QJsonObject>
#include <QProcess>
#include <QStandardPaths>
#include <QTemporaryDir>
#include <QTest>

#include <cmath>
#include <cstring>
#include <map>
#include <vector>

#include <glm/glm.hpp>
#include <glm/gtc/quaternion.hpp>

#include "core/base/error.h"
#include "core/render/render_scene.h"
#include "core/render/surfaces/landscape_trace.h"
#include "core/render/surfaces/mesh_trace.h"
#include "core/terrain/height_field.h"
#include "pipeline/io/image_io.h"
#include "pipeline/render/render_job.h"
#include "pipeline/scene/scene_file.h"
#include "pipeline/services/gltf_export.h"
#include "tests/common/glb_reader.h"
#include "tests/common/run_program.h"
#include "tests/common/scenes.h"

using namespace sylva;
using namespace sylva::test;

namespace {

// The largest distance between the file's placement of the mesh box corners and the point the renderer's map
// `rec` (parent -> geometry, parent = world - origin) sends back to the corner.
double worstCorner(const FileInstance& fi, const InstanceRecord& rec, const Bounds3& box, const glm::dvec3& origin)
{
    double worst = 0.0;
    for (int k = 0; k < 8; ++k) {
        const glm::dvec3 x((k & 1) ? box.hi.x : box.lo.x, (k & 2) ? box.hi.y : box.lo.y, (k & 4) ? box.hi.z : box.lo.z);
        const glm::dvec3 w = fi.apply(x) - origin;
        glm::dvec3 back;
        for (int i = 0; i < 3; ++i) back[i] = double(rec.row[i].x) * w.x + double(rec.row[i].y) * w.y + double(rec.row[i].z) * w.z + double(rec.row[i].w);
        worst = std::max(worst, glm::length(back - x) * double(rec.scale));   // in world metres
    }
    return worst;
}

// A scene of the two grown species of smallForest: instances with turns about all three axes and scales, and a
// group (placed twice) holding an instance and a nested group.
Scene groupedForest()
{
    Scene s = smallForest();
    s.instances[0].rotationDeg = {20.0f, 35.0f, -50.0f};
    s.instances[1].rotationDeg = {-70.0f, 140.0f, 15.0f};
    s.instances[1].scale = 0.7f;
    GroupDesc inner{"pair", {}};
    InstanceDesc a;
    a.species = 0;
    a.position = {1.0, 0.5, -2.0};
    a.rotationDeg = {10.0f, 0.0f, 30.0f};
    a.scale = 0.5f;
    inner.instances.push_back(a);
    GroupDesc outer{"stand", {}};
    InstanceDesc b;
    b.species = 1;
    b.position = {-2.0, 0.0, 1.0};
    b.rotationDeg = {0.0f, 75.0f, 5.0f};
    outer.instances.push_back(b);
    InstanceDesc g;
    g.group = 0;
    g.position = {4.0, 1.0, 0.0};
    g.rotationDeg = {0.0f, -30.0f, 12.0f};
    g.scale = 1.5f;
    outer.instances.push_back(g);
    s.groups = {inner, outer};
    for (int k = 0; k < 2; ++k) {
        InstanceDesc p;
        p.group = 1;
        p.position = {20.0 + 15.0 * k, 0.0, 5.0 - 8.0 * k};
        p.rotationDeg = {5.0f * float(k), 60.0f + 90.0f * float(k), -8.0f};
        p.scale = 1.0f + 0.25f * float(k);
        s.instances.push_back(p);
    }
    return s;
}

// The renderer's parent -> geometry maps of every species instance of `scene` in the export's order (the scene's
// instances, group members depth first), per species.
void rendererMaps(const Scene& scene, const InstanceDesc& d, const InstanceRecord* outer, std::map<uint32_t, std::vector<InstanceRecord>>& out)
{
    const InstanceRecord own = makeInstance(d, glm::dvec3(0.0));
    const InstanceRecord rec = outer ? composeInstances(own, *outer) : own;
    if (d.group == kNoGroup) {
        out[d.species].push_back(rec);
        return;
    }
    for (const InstanceDesc& c : scene.groups[d.group].instances) rendererMaps(scene, c, &rec, out);
}

std::vector<SpeciesAssets> geometryOf(const Scene& scene) { return loadSpeciesAssets(scene, nullptr, false); }

// A hilly landscape of one grown shrub species (tile plants every 6 m) and two instances standing on the terrain.
Scene hillyLandscape()
{
    Scene s;
    s.species = {shrubSpecies(16, 5, 1500, 2.0f)};
    const uint32_t n = 97;
    std::vector<float> h(size_t(n) * n);
    for (uint32_t j = 0; j < n; ++j)
        for (uint32_t i = 0; i < n; ++i) h[size_t(j) * n + i] = 8.0f * std::sin(0.07f * float(i)) * std::cos(0.05f * float(j)) + 0.1f * float(i);
    s.terrain.dem = "(in memory)";
    s.terrain.origin = {1000.0, 40.0, -500.0};
    s.terrain.spacing = 2.0;
    s.terrain.field = std::make_shared<const HeightField>(buildHeightField(std::move(h), n, n, 2.0f, 2.0f));
    s.terrain.cells = 3;
    s.terrain.tiles.size = 50.0;
    s.terrain.tiles.seed = 3;
    TilePlantDesc p;
    p.species = 0;
    p.speciesName = "shrub";
    p.spacing = 6.0;
    s.terrain.tiles.plants = {p};
    for (int k = 0; k < 2; ++k) {
        InstanceDesc d;
        d.position = {1040.0 + 50.0 * k, 0.5 * k, -450.0 + 30.0 * k};
        d.rotationDeg = {0.0f, 30.0f + 100.0f * float(k), 0.0f};
        d.onTerrain = true;
        s.instances.push_back(d);
    }
    s.camera.position = {1100.0, 120.0, -560.0};
    s.camera.target = {1090.0, 40.0, -400.0};
    return s;
}

} // namespace

class TstGltfExport : public QObject {
    Q_OBJECT

    QTemporaryDir m_dir;

private Q_SLOTS:
    // Instances of two species, turned about all three axes, scaled, and in nested groups placed twice: every
    // instance's matrix against the renderer's map (the mesh box's corners within 0.1 mm), counts per species,
    // the structure, the materials and the embedded images.
    void instancesMatchTheRenderer()
    {
        const Scene scene = groupedForest();
        const std::vector<SpeciesAssets> assets = geometryOf(scene);
        const QString path = m_dir.filePath("forest.glb");
        const GltfPlan plan = exportGltf(scene, assets, path.toStdString());
        // 3 own instances + 2 placements x (1 member + 1 nested member).
        QCOMPARE(plan.instances, size_t(7));
        const Glb g = readGlb(path);
        QVERIFY2(structureProblems(g).isEmpty(), qPrintable(structureProblems(g)));
        QCOMPARE(qint64(plan.estimatedBytes), QFileInfo(path).size());
        QVERIFY(g.json["extensionsUsed"].toArray().contains("EXT_mesh_gpu_instancing"));
        QVERIFY(g.json["extensionsRequired"].toArray().contains("EXT_mesh_gpu_instancing"));
        QCOMPARE(g.json["asset"].toObject()["version"].toString(), QStringLiteral("2.0"));

        std::map<uint32_t, std::vector<InstanceRecord>> maps;
        for (const InstanceDesc& d : scene.instances) rendererMaps(scene, d, nullptr, maps);
        QString problem;
        const std::vector<SpeciesNode> nodes = instancedNodes(g, &problem);
        QVERIFY2(problem.isEmpty(), qPrintable(problem));
        QCOMPARE(nodes.size(), size_t(2));
        double worst = 0.0;
        for (uint32_t s = 0; s < 2; ++s) {
            QCOMPARE(nodes[s].name, QString::fromStdString(scene.species[s].name));
            QCOMPARE(nodes[s].instances.size(), maps[s].size());
            QCOMPARE(nodes[s].instances.size(), plan.perSpecies[s]);
            const Bounds3 box = meshBounds(assets[s].mesh);
            for (size_t i = 0; i < maps[s].size(); ++i) worst = std::max(worst, worstCorner(nodes[s].instances[i], maps[s][i], box, glm::dvec3(0.0)));
        }
        qInfo("7 instances (3 in groups two deep), worst corner %.2e m", worst);
        QVERIFY2(worst < 1e-4, qPrintable(QString::number(worst)));
        QCOMPARE(plan.perSpecies[0], size_t(4));   // 2 own (a, c) + 2 nested pair members
        QCOMPARE(plan.perSpecies[1], size_t(3));   // 1 own + 2 stand members

        // Each species' mesh once: its vertices and triangles, uv flipped to glTF's top-left origin.
        for (uint32_t s = 0; s < 2; ++s) {
            const QJsonObject mesh = g.json["meshes"].toArray()[nodes[s].mesh].toObject();
            size_t indices = 0;
            for (const QJsonValue& pv : mesh["primitives"].toArray()) {
                const QJsonObject prim = pv.toObject();
                const QJsonObject at = prim["attributes"].toObject();
                QCOMPARE(g.json["accessors"].toArray()[at["POSITION"].toInt()].toObject()["count"].toInt(), int(assets[s].mesh.positions.size()));
                QVERIFY(at.contains("NORMAL") && at.contains("TEXCOORD_0"));
                indices += size_t(g.json["accessors"].toArray()[prim["indices"].toInt()].toObject()["count"].toInt());
                int n = 0;
                const std::vector<double> uv = readAccessor(g, at["TEXCOORD_0"].toInt(), &n, &problem);
                QVERIFY(problem.isEmpty());
                QCOMPARE(uv[1], 1.0 - double(assets[s].mesh.uvs[0].y));
                // Materials: leaves with cut-outs MASK at the renderer's 0.5, double-sided; wood opaque.
                const QJsonObject mat = g.json["materials"].toArray()[prim["material"].toInt()].toObject();
                const QString name = mat["name"].toString();
                const auto& mats = assets[s].mesh.materials;
                const auto it = std::find_if(mats.begin(), mats.end(), [&](const Material& m) { return name.endsWith("/" + QString::fromStdString(m.name)); });
                QVERIFY2(it != mats.end(), qPrintable(name));
                QCOMPARE(mat["doubleSided"].toBool(), it->isLeaf);
                QCOMPARE(mat["alphaMode"].toString(QStringLiteral("OPAQUE")), it->isLeaf ? QStringLiteral("MASK") : QStringLiteral("OPAQUE"));
                if (it->isLeaf) QCOMPARE(mat["alphaCutoff"].toDouble(), 0.5);
                const QJsonArray base = mat["pbrMetallicRoughness"].toObject()["baseColorFactor"].toArray();
                QCOMPARE(float(base[0].toDouble()), it->diffuse.x);
                // Its texture: an embedded PNG that decodes to the species' image (alpha kept for the cut-out).
                const int tex = mat["pbrMetallicRoughness"].toObject()["baseColorTexture"].toObject()["index"].toInt(-1);
                QVERIFY2(tex >= 0, qPrintable(name));
                const QJsonObject image = g.json["images"].toArray()[g.json["textures"].toArray()[tex].toObject()["source"].toInt()].toObject();
                QCOMPARE(image["mimeType"].toString(), QStringLiteral("image/png"));
                const QJsonObject view = g.json["bufferViews"].toArray()[image["bufferView"].toInt()].toObject();
                QImage decoded;
                QVERIFY(decoded.loadFromData(g.bin.mid(qsizetype(view["byteOffset"].toDouble()), qsizetype(view["byteLength"].toDouble())), "PNG"));
                const size_t m = size_t(it - mats.begin());
                QCOMPARE(decoded.width(), assets[s].diffuse[m].width);
                QCOMPARE(decoded.hasAlphaChannel(), it->isLeaf);
                const float* px = assets[s].diffuse[m].at(3, 5);
                QCOMPARE(qGreen(decoded.pixel(3, 5)), int(std::lround(std::clamp(px[1], 0.0f, 1.0f) * 255.0f)));
            }
            QCOMPARE(indices, 3 * assets[s].mesh.triangles.size());
        }
        // The ground: a quad under every instance.
        bool ground = false;
        for (const QJsonValue& nv : g.json["nodes"].toArray())
            if (nv.toObject()["name"].toString() == "ground") {
                ground = true;
                const QJsonObject a = g.json["accessors"].toArray()[g.json["meshes"].toArray()[nv.toObject()["mesh"].toInt()].toObject()["primitives"]
                                                                          .toArray()[0].toObject()["attributes"].toObject()["POSITION"].toInt()].toObject();
                for (const SpeciesNode& sn : nodes)
                    for (const FileInstance& fi : sn.instances) {
                        QVERIFY(fi.t.x > a["min"].toArray()[0].toDouble() && fi.t.x < a["max"].toArray()[0].toDouble());
                        QVERIFY(fi.t.z > a["min"].toArray()[2].toDouble() && fi.t.z < a["max"].toArray()[2].toDouble());
                    }
                QCOMPARE(a["min"].toArray()[1].toDouble(), scene.ground.height);
            }
        QVERIFY(ground);
    }

    // An imported tree with textures (Tree_1 of resources/trees, OBJ_textured): the bark's JPEG and the leaves' PNG
    // (its alpha the cut-out) embedded as the files' own bytes; with an opacity map of another file, the colour and
    // the opacity merged into one PNG (the opacity read at the nearest texel), MASK.
    void importedTextures()
    {
        const QString trees = QStringLiteral(SYLVA_RESOURCES "/trees/quaternius");
        Scene scene;
        scene.species.resize(1);
        scene.species[0].name = "Tree_1";
        scene.species[0].meshPath = (trees + "/OBJ_textured/Tree_1.obj").toStdString();
        scene.instances.resize(1);
        std::vector<SpeciesAssets> assets = geometryOf(scene);
        const QString path = m_dir.filePath("textured.glb");
        exportGltf(scene, assets, path.toStdString());
        Glb g = readGlb(path);
        QVERIFY2(structureProblems(g).isEmpty(), qPrintable(structureProblems(g)));
        auto imageOf = [&](const QString& materialSuffix, QString* mime, QString* alphaMode) {
            for (const QJsonValue& mv : g.json["materials"].toArray()) {
                const QJsonObject m = mv.toObject();
                if (!m["name"].toString().endsWith(materialSuffix)) continue;
                *alphaMode = m["alphaMode"].toString("OPAQUE");
                const int tex = m["pbrMetallicRoughness"].toObject()["baseColorTexture"].toObject()["index"].toInt(-1);
                if (tex < 0) return QByteArray();
                const QJsonObject image = g.json["images"].toArray()[g.json["textures"].toArray()[tex].toObject()["source"].toInt()].toObject();
                *mime = image["mimeType"].toString();
                const QJsonObject view = g.json["bufferViews"].toArray()[image["bufferView"].toInt()].toObject();
                return g.bin.mid(qsizetype(view["byteOffset"].toDouble()), qsizetype(view["byteLength"].toDouble()));
            }
            return QByteArray();
        };
        auto fileBytes = [](const QString& f) {
            QFile in(f);
            return in.open(QIODevice::ReadOnly) ? in.readAll() : QByteArray();
        };
        QString mime, mode;
        QCOMPARE(imageOf("/Bark", &mime, &mode), fileBytes(trees + "/Textures/Tree_Bark.jpg"));
        QCOMPARE(mime, QStringLiteral("image/jpeg"));
        QCOMPARE(mode, QStringLiteral("OPAQUE"));
        QCOMPARE(imageOf("/Tree_Leaves", &mime, &mode), fileBytes(trees + "/Textures/Tree_Leaves.png"));
        QCOMPARE(mime, QStringLiteral("image/png"));
        QCOMPARE(mode, QStringLiteral("MASK"));

        // The leaves coloured by the bark's JPEG and cut out by the leaves' PNG: one PNG of the JPEG's size.
        QByteArray obj = fileBytes(trees + "/OBJ_textured/Tree_1.obj");
        obj.replace("mtllib Tree_1.mtl", "mtllib merged.mtl");
        QFile objOut(m_dir.filePath("merged.obj")), mtlOut(m_dir.filePath("merged.mtl"));
        QVERIFY(objOut.open(QIODevice::WriteOnly) && mtlOut.open(QIODevice::WriteOnly));
        objOut.write(obj);
        mtlOut.write(("newmtl Bark\nKd 1 1 1\nmap_Kd " + trees + "/Textures/Tree_Bark.jpg\n\nnewmtl Tree_Leaves\nKd 1 1 1\nmap_Kd " + trees +
                      "/Textures/Tree_Bark.jpg\nmap_d " + trees + "/Textures/Tree_Leaves.png\n").toUtf8());
        objOut.close();
        mtlOut.close();
        scene.species[0].meshPath = m_dir.filePath("merged.obj").toStdString();
        assets = geometryOf(scene);
        exportGltf(scene, assets, path.toStdString());
        g = readGlb(path);
        QVERIFY2(structureProblems(g).isEmpty(), qPrintable(structureProblems(g)));
        QImage merged;
        QVERIFY(merged.loadFromData(imageOf("/Tree_Leaves", &mime, &mode), "PNG"));
        QCOMPARE(mime, QStringLiteral("image/png"));
        QCOMPARE(mode, QStringLiteral("MASK"));
        const ImageRgba bark = readImage((trees + "/Textures/Tree_Bark.jpg").toStdString());   // as the renderer decodes it
        const QImage leaves(trees + "/Textures/Tree_Leaves.png");
        QCOMPARE(merged.size(), QSize(bark.width, bark.height));
        QVERIFY(merged.hasAlphaChannel());
        int wrong = 0;
        for (int y = 0; y < merged.height(); y += 7)
            for (int x = 0; x < merged.width(); x += 7) {
                const int lx = std::min(leaves.width() - 1, int((x + 0.5) * leaves.width() / merged.width()));
                const int ly = std::min(leaves.height() - 1, int((y + 0.5) * leaves.height() / merged.height()));
                wrong += std::abs(qAlpha(merged.pixel(x, y)) - qAlpha(leaves.pixel(lx, ly))) > 1 ||
                         qRed(merged.pixel(x, y)) != int(std::lround(bark.at(x, y)[0] * 255.0f));
            }
        QCOMPARE(wrong, 0);
    }

    // A landscape: the on-terrain instances lifted as the renderer lifts them, the tile plants of a region exactly
    // those the renderer grows there (count) and placed as its landPlantInstance places them (box corners within
    // 2 mm: the renderer's float maps 1 km from the origin), the terrain as a mesh of its samples.
    void landscapeRegion()
    {
        const Scene scene = hillyLandscape();
        const std::vector<SpeciesAssets> assets = geometryOf(scene);
        GltfExportOptions o;
        o.region = std::array<double, 4>{1030.0, -470.0, 1100.0, -410.0};
        const QString path = m_dir.filePath("land.glb");
        const GltfPlan plan = exportGltf(scene, assets, path.toStdString(), o);
        const Glb g = readGlb(path);
        QVERIFY2(structureProblems(g).isEmpty(), qPrintable(structureProblems(g)));

        // The renderer's frame: its landscape arrays, and its maps from the camera-relative frame to each plant.
        RenderScene rs = buildSceneGeometry(scene, assets);
        placeTopLevel(rs, scene, glm::vec3(1.0f), 96, 64, 1);
        const RenderView v = rs.view();
        const LandscapeLayout& L = rs.frame.landscape.layout;
        std::vector<std::pair<uint32_t, uint32_t>> growing;   // (cell, plant) in the export's order
        const HeightFieldView hv = scene.terrain.field->view();
        for (uint32_t cz = 0; cz < L.cellsZ; ++cz)
            for (uint32_t cx = 0; cx < L.cellsX; ++cx) {
                const uint32_t cell = cz * L.cellsX + cx;
                const TileRecord& t = rs.tileRecords[rs.landCells[cell].tile];
                for (uint32_t q = 0; q < t.plantCount; ++q) {
                    const TilePlant& p = rs.tilePlants[t.plantOffset + q];
                    const double x = scene.terrain.origin.x + double(cx) * L.cellSize + double(L.tileScale) * p.x;
                    const double z = scene.terrain.origin.z + double(cz) * L.cellSize + double(L.tileScale) * p.z;
                    float y;
                    if (x < 1030.0 || x >= 1100.0 || z < -470.0 || z >= -410.0) continue;
                    if (landPlantGrows(L, hv, v.terrain.snowY, v.terrain.rockCos, cx, cz, p, y)) growing.emplace_back(cell, t.plantOffset + q);
                }
            }
        QString problem;
        const std::vector<SpeciesNode> nodes = instancedNodes(g, &problem);
        QVERIFY2(problem.isEmpty(), qPrintable(problem));
        QCOMPARE(nodes.size(), size_t(1));
        // Both instances stand in the region, then the plants.
        QCOMPARE(plan.landscapePlants, growing.size());
        QCOMPARE(nodes[0].instances.size(), 2 + growing.size());
        QVERIFY(growing.size() > 20);
        const Bounds3 box = meshBounds(assets[0].mesh);
        double worstOwn = 0.0, worstPlant = 0.0;
        for (size_t k = 0; k < 2; ++k) {
            const InstanceDesc& d = scene.instances[k];
            InstanceDesc lifted = d;
            lifted.position.y += scene.terrain.origin.y + surfaceHeight(*scene.terrain.field, d.position.x - scene.terrain.origin.x, d.position.z - scene.terrain.origin.z);
            worstOwn = std::max(worstOwn, worstCorner(nodes[0].instances[k], makeInstance(lifted, glm::dvec3(0.0)), box, glm::dvec3(0.0)));
        }
        for (size_t k = 0; k < growing.size(); ++k)
            worstPlant = std::max(worstPlant, worstCorner(nodes[0].instances[2 + k], trace_detail::landPlantInstance(v, growing[k].first, growing[k].second),
                                                          box, scene.camera.position));
        qInfo("%zu landscape plants in the region, worst corner %.2e m (instances on the terrain %.2e m)", growing.size(), worstPlant, worstOwn);
        QVERIFY2(worstOwn < 1e-4, qPrintable(QString::number(worstOwn)));
        QVERIFY2(worstPlant < 2e-3, qPrintable(QString::number(worstPlant)));
        for (const FileInstance& fi : nodes[0].instances) QVERIFY(fi.t.x >= 1030.0 && fi.t.x < 1100.0 && fi.t.z >= -470.0 && fi.t.z < -410.0);

        // The terrain: the samples covering the region, at their heights.
        bool terrain = false;
        for (const QJsonValue& nv : g.json["nodes"].toArray())
            if (nv.toObject()["name"].toString() == "terrain") {
                terrain = true;
                const QJsonObject at = g.json["meshes"].toArray()[nv.toObject()["mesh"].toInt()].toObject()["primitives"].toArray()[0].toObject()["attributes"].toObject();
                int n = 0;
                const std::vector<double> p = readAccessor(g, at["POSITION"].toInt(), &n, &problem);
                QCOMPARE(int(p.size() / 3), int(plan.terrainSamplesX * plan.terrainSamplesZ));
                QCOMPARE(plan.terrainSamplesX, size_t(36));   // samples 15 .. 50 (x 1030 .. 1100, 2 m apart)
                const double i = (p[0] - scene.terrain.origin.x) / 2.0, j = (p[2] - scene.terrain.origin.z) / 2.0;
                QCOMPARE(p[1], double(float(scene.terrain.origin.y + scene.terrain.field->at(uint32_t(i), uint32_t(j)))));
                QVERIFY(at.contains("COLOR_0") && at.contains("NORMAL"));
            }
        QVERIFY(terrain);
    }

    // Above the limit: refused with the count and the size, nothing written; forced: written.
    void limitRefusesUnlessForced()
    {
        const Scene scene = hillyLandscape();
        const std::vector<SpeciesAssets> assets = geometryOf(scene);
        GltfExportOptions o;
        o.instanceLimit = 10;
        const GltfPlan plan = planGltfExport(scene, assets, o);
        QVERIFY(plan.instances > 10 && plan.overLimit());
        const QString path = m_dir.filePath("big.glb");
        const std::string message = errorOf([&] { exportGltf(scene, assets, path.toStdString(), o); });
        QVERIFY2(message.find(std::to_string(plan.instances) + " instances") != std::string::npos && message.find("MB") != std::string::npos, message.c_str());
        QVERIFY(!QFile::exists(path));
        o.force = true;
        const GltfPlan written = exportGltf(scene, assets, path.toStdString(), o);
        QCOMPARE(written.instances, plan.instances);
        QVERIFY(QFile::exists(path));
        // The estimate against the file: within a factor 2 (textures are estimated uncompressed).
        qInfo("%zu instances: estimated %.0f bytes, wrote %.0f", plan.instances, plan.estimatedBytes, written.estimatedBytes);
        QVERIFY(plan.estimatedBytes > 0.5 * written.estimatedBytes && plan.estimatedBytes < 2.0 * written.estimatedBytes);
        // A DEM of 3000 x 20 samples: written every 3rd sample along x (1001 with the last), all 20 along z.
        Scene wide;
        wide.terrain.dem = "(in memory)";
        wide.terrain.field = std::make_shared<const HeightField>(buildHeightField(std::vector<float>(3000 * 20, 1.0f), 3000, 20, 1.0f, 1.0f));
        const GltfPlan dem = planGltfExport(wide, {});
        QCOMPARE(dem.terrainSamplesX, size_t(1001));
        QCOMPARE(dem.terrainSamplesZ, size_t(20));
        QVERIFY(errorOf([] { parseGltfRegion("1,2,3"); }).find("x0,z0,x1,z1") != std::string::npos);
        QVERIFY(errorOf([] { parseGltfRegion("5,0,1,1"); }).find("x0 < x1") != std::string::npos);
    }

    // sylva export SCENE -o FILE.glb: the counts printed before the file is written, bad options refused.
    void commandLine()
    {
        Scene scene = smallForest();
        const QString scenePath = m_dir.filePath("forest.sylva.json");
        writeSceneFile(scene, scenePath.toStdString());
        const QString out = m_dir.filePath("cli.glb");
        Run r = runProgram(QStringLiteral(SYLVA_CLI_PATH), {"export", scenePath, "-o", out, "--quiet"});
        QVERIFY2(r.code == 0, qPrintable(r.err));
        QVERIFY2(r.out.contains(QLatin1String("3 instances, about")) && r.out.contains(QLatin1String("broadleaf: 2")), qPrintable(r.out));
        QVERIFY2(r.out.indexOf(QLatin1String("instances, about")) < r.out.indexOf(QLatin1String("wrote")), qPrintable(r.out));
        QVERIFY(structureProblems(readGlb(out)).isEmpty());
        r = runProgram(QStringLiteral(SYLVA_CLI_PATH), {"export", scenePath, "-o", out, "--species", "birch", "--region", "0,0,10,10", "--quiet"});
        QVERIFY2(r.code == 0 && r.out.contains(QLatin1String("1 instance, about")), qPrintable(r.out + r.err));
        r = runProgram(QStringLiteral(SYLVA_CLI_PATH), {"export", scenePath, "-o", out, "--region", "0,0,10"});
        QVERIFY2(r.code == 2 && r.err.contains(QLatin1String("--region")), qPrintable(r.err));
        r = runProgram(QStringLiteral(SYLVA_CLI_PATH), {"export", scenePath, "-o", m_dir.filePath("x.gltf")});
        QVERIFY2(r.code == 2 && r.err.contains(QLatin1String(".glb")), qPrintable(r.err));
        r = runProgram(QStringLiteral(SYLVA_CLI_PATH), {"export", scenePath, "--force"});
        QVERIFY2(r.code == 2, qPrintable(r.err));
    }

    // The Khronos glTF validator and glTF Transform read both files without errors. They are npm packages: when node
    // is there and they are not yet in BUILD/test-output/npm-tools, the test installs them there with npm (once; it
    // skips, naming what is missing, when node, npm or the registry is not there).
    void externalValidators()
    {
        if (QStandardPaths::findExecutable("node").isEmpty()) QSKIP("node is not installed: the external glTF checks need node and npm");
        const QString prefix = QStringLiteral(SYLVA_TEST_OUTPUT "/npm-tools");
        const QString validatorModule = prefix + "/node_modules/gltf-validator";
        const QString transform = prefix + "/node_modules/.bin/gltf-transform";
        if (!QDir(validatorModule).exists() || !QFile::exists(transform)) {
            if (QStandardPaths::findExecutable("npm").isEmpty()) QSKIP("npm is not installed: it installs gltf-validator and @gltf-transform/cli");
            QDir().mkpath(prefix);
            const Run r = runProgram(QStringLiteral("npm"), {"install", "--no-audit", "--no-fund", "--fetch-retries=1", "--fetch-timeout=20000", "--prefix", prefix, "gltf-validator", "@gltf-transform/cli"},
                                     QProcessEnvironment::systemEnvironment(), 300000);
            if (r.code != 0 || !QDir(validatorModule).exists() || !QFile::exists(transform))
                QSKIP(qPrintable("npm could not install gltf-validator and @gltf-transform/cli (no registry?): " + r.err.right(300)));
        }
        const QString script = m_dir.filePath("validate.js");
        QFile js(script);
        QVERIFY(js.open(QIODevice::WriteOnly));
        js.write("const v = require(process.argv[2]); const fs = require('fs');\n"
                 "v.validateBytes(new Uint8Array(fs.readFileSync(process.argv[3]))).then(r => {\n"
                 "  console.log(JSON.stringify(r.issues.messages.filter(m => m.severity <= 1)));\n"
                 "  console.log('errors ' + r.issues.numErrors + ' warnings ' + r.issues.numWarnings);\n"
                 "  process.exit(r.issues.numErrors > 0 ? 1 : 0); });\n");
        js.close();
        for (const char* name : {"forest.glb", "land.glb", "textured.glb"}) {
            const QString file = m_dir.filePath(name);
            if (!QFile::exists(file)) QSKIP("the files of the tests above are missing (run the whole test)");
            Run r = runProgram(QStringLiteral("node"), {script, validatorModule, file}, QProcessEnvironment::systemEnvironment(), 120000);
            qInfo("gltf-validator %s: %s", name, qPrintable(r.out.trimmed().section('\n', -1)));
            QVERIFY2(r.code == 0 && r.out.contains(QLatin1String("errors 0")), qPrintable(r.out + r.err));
            r = runProgram(transform, {"inspect", file}, QProcessEnvironment::systemEnvironment(), 120000);
            QVERIFY2(r.code == 0 && r.out.contains(QLatin1String("EXT_mesh_gpu_instancing")), qPrintable(r.out + r.err));
        }
    }
};

QTEST_GUILESS_MAIN(TstGltfExport)
#include "tst_gltf_export.moc"
