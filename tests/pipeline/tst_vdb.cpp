// OpenVDB grid files: density, wood fraction and lighting written and read back exactly (checked
// through OpenVDB's own API as well as ours), a .vdb made by OpenVDB's API read and lit by `sylva
// light`, bad files refused with clear errors, and every command with -o refusing an extension it
// cannot write.
#include <QDir>
#include <QFile>
#include <QJsonArray>
#include <QJsonDocument>
#include <QJsonObject>
#include <QProcess>
#include <QTest>

#include <cmath>
#include <cstring>
#include <random>

#include <openvdb/io/File.h>
#include <openvdb/openvdb.h>

#include "core/base/error.h"
#include "core/lb/lb_params.h"
#include "pipeline/grow/obj_writer.h"
#include "pipeline/grow/tree_grower.h"
#include "pipeline/io/grid_file.h"
#include "pipeline/io/npy.h"
#include "pipeline/io/vdb_io.h"
#include "pipeline/lighting_job.h"
#include "pipeline/render/render_job.h"
#include "pipeline/scene/scene_file.h"
#include "pipeline/services/exports.h"
#include "tests/common/files.h"
#include "tests/common/run_program.h"

using namespace sylva;

namespace {

using test::errorOf;
using test::Run;
using test::runSylva;

// A density with empty borders (the low corner too, so the dims must come from the metadata), random
// values with many zeros, and a block of 1.0 covering whole 8^3 leaves (stored as tiles).
DensityGrid testDensity()
{
    DensityGrid g;
    g.geometry.dims = {37, 26, 19};
    g.geometry.origin = {-1.25, 3.5, 1000.1};
    g.geometry.spacing = 0.037;
    const size_t n = g.geometry.nodeCount();
    g.density.assign(n, 0.0f);
    g.woodFraction.assign(n, 0.0f);
    std::mt19937 rng(7);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    for (int i = 2; i < 35; ++i)
        for (int j = 3; j < 24; ++j)
            for (int k = 1; k < 18; ++k) {
                const size_t idx = g.geometry.index(i, j, k);
                const bool block = i >= 8 && i < 24 && j >= 8 && j < 16 && k >= 8 && k < 16;
                const float r = u(rng);
                g.density[idx] = block ? 1.0f : (r < 0.4f ? 0.0f : r);
                if (u(rng) < 0.2f) g.woodFraction[idx] = u(rng);
            }
    return g;
}

LightingGrid testLighting(const GridGeometry& geometry)
{
    LightingGrid l;
    l.geometry = geometry;
    std::mt19937 rng(11);
    std::uniform_real_distribution<float> u(0.0f, 2.0f);
    const size_t n = geometry.nodeCount() * 3;
    l.rgb.reserve(n);
    for (size_t i = 0; i < n; ++i) l.rgb.push_back((i % 7 == 0) ? 0.0f : u(rng));
    return l;
}

bool sameBits(const std::vector<float>& a, const std::vector<float>& b)
{
    return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(float)) == 0;
}

template <class GridT>
typename GridT::Ptr openGrid(const std::string& path, const std::string& name)
{
    openvdb::io::File file(path);
    file.open(false);
    typename GridT::Ptr grid = openvdb::gridPtrCast<GridT>(file.readGrid(name));
    file.close();
    return grid;
}

void writeVdbWithApi(const std::string& path, const openvdb::GridPtrVec& grids)
{
    openvdb::io::File file(path);
    file.write(grids);
    file.close();
}

// A float grid with one active voxel per coordinate given (value 0.5) and the transform given.
openvdb::FloatGrid::Ptr sparseFloat(const std::string& name, const openvdb::math::Transform::Ptr& xf,
                                    std::initializer_list<openvdb::Coord> voxels)
{
    openvdb::FloatGrid::Ptr g = openvdb::FloatGrid::create(0.0f);
    g->setName(name);
    g->setTransform(xf);
    auto acc = g->getAccessor();
    for (const openvdb::Coord& c : voxels) acc.setValue(c, 0.5f);
    return g;
}

} // namespace

class TestVdb : public QObject {
    Q_OBJECT

    QString m_dir;

    std::string out(const char* name) const { return (m_dir + "/" + name).toStdString(); }

private Q_SLOTS:
    void initTestCase()
    {
        m_dir = test::outputDir("vdb");
        openvdb::initialize();
    }

    // Our writer, read back by our reader: every value (bits) and the geometry equal; read by
    // OpenVDB's API: voxel (i,j,k) holds node (i,j,k), active exactly where non-zero, its centre at
    // origin + spacing * (i,j,k), the density a fog volume.
    void densityRoundTrip()
    {
        const DensityGrid d = testDensity();
        const std::string path = out("density.vdb");
        writeDensityFile(path, d);
        QCOMPARE(densityFilesFor(path), std::vector<std::string>{path});
        const DensityGrid r = readDensityFile(path);
        QVERIFY(r.geometry == d.geometry);
        QVERIFY(sameBits(r.density, d.density));
        QVERIFY(sameBits(r.woodFraction, d.woodFraction));

        const auto density = openGrid<openvdb::FloatGrid>(path, "density");
        const auto wood = openGrid<openvdb::FloatGrid>(path, "wood_fraction");
        QVERIFY(density && wood);
        QCOMPARE(density->getGridClass(), openvdb::GRID_FOG_VOLUME);
        QCOMPARE(density->background(), 0.0f);
        QCOMPARE(density->voxelSize(), openvdb::Vec3d(d.geometry.spacing));
        QVERIFY(density->tree().activeTileCount() > 0);   // the block of 1.0 is stored sparsely as tiles
        const auto dAcc = density->getConstAccessor();
        const auto wAcc = wood->getConstAccessor();
        size_t nonZero = 0;
        for (int i = 0; i < d.geometry.dims.x; ++i)
            for (int j = 0; j < d.geometry.dims.y; ++j)
                for (int k = 0; k < d.geometry.dims.z; ++k) {
                    const size_t idx = d.geometry.index(i, j, k);
                    const openvdb::Coord c(i, j, k);
                    if (dAcc.getValue(c) != d.density[idx] || dAcc.isValueOn(c) != (d.density[idx] != 0.0f))
                        QFAIL(qPrintable(QString("density voxel %1,%2,%3").arg(i).arg(j).arg(k)));
                    if (wAcc.getValue(c) != d.woodFraction[idx]) QFAIL("wood fraction voxel differs");
                    nonZero += d.density[idx] != 0.0f;
                }
        QCOMPARE(size_t(density->activeVoxelCount()), nonZero);
        for (const openvdb::Coord c : {openvdb::Coord(0, 0, 0), openvdb::Coord(36, 25, 18), openvdb::Coord(5, 17, 3)}) {
            const openvdb::Vec3d w = density->indexToWorld(c);
            for (int a = 0; a < 3; ++a)
                QVERIFY(std::fabs(w[a] - (d.geometry.origin[a] + d.geometry.spacing * c[a])) <= 1e-12 * (1.0 + std::fabs(w[a])));
        }
        const auto dims = density->getMetadata<openvdb::Vec3IMetadata>("sylva_dims");
        QVERIFY(dims);
        QCOMPARE(dims->value(), openvdb::Vec3i(37, 26, 19));
    }

    // Lighting with its density in one file: our reader gives back both exactly; OpenVDB's API sees
    // the vec3 grid, the three channel grids and the solver's parameters as typed metadata.
    void lightingRoundTrip()
    {
        const DensityGrid d = testDensity();
        const LightingGrid l = testLighting(d.geometry);
        lb::LbParams p = lb::paramsFromPreset(*lb::findPreset("dogrose"));
        p.sun = {0.25f, 1.0f, -0.5f};
        p.tolerance = 1e-4;
        const std::string params = lightingParamsJson(p, "dogrose", d.geometry.dims);
        const std::string path = out("lighting.vdb");
        writeLightingFile(path, l, params, &d);
        const LightingGrid r = readLightingFile(path);
        QVERIFY(r.geometry == l.geometry);
        QVERIFY(sameBits(r.rgb, l.rgb));
        const DensityGrid rd = readDensityFile(path);
        QVERIFY(rd.geometry == d.geometry);
        QVERIFY(sameBits(rd.density, d.density));

        const auto vec = openGrid<openvdb::Vec3SGrid>(path, "lighting");
        QVERIFY(vec);
        QCOMPARE(vec->getVectorType(), openvdb::VEC_INVARIANT);
        openvdb::FloatGrid::Ptr channel[3];
        for (int c = 0; c < 3; ++c) {
            channel[c] = openGrid<openvdb::FloatGrid>(path, kVdbLightingChannelGrids[c]);
            QVERIFY(channel[c]);
            QVERIFY(channel[c]->transform() == vec->transform());
        }
        const auto acc = vec->getConstAccessor();
        for (int i = 0; i < l.geometry.dims.x; ++i)
            for (int j = 0; j < l.geometry.dims.y; ++j)
                for (int k = 0; k < l.geometry.dims.z; ++k) {
                    const openvdb::Vec3s v = acc.getValue(openvdb::Coord(i, j, k));
                    for (int c = 0; c < 3; ++c)
                        if (v[c] != l.at(i, j, k, c) || channel[c]->tree().getValue(openvdb::Coord(i, j, k)) != l.at(i, j, k, c))
                            QFAIL(qPrintable(QString("lighting voxel %1,%2,%3 channel %4").arg(i).arg(j).arg(k).arg(c)));
                }
        const QJsonObject json = QJsonDocument::fromJson(QByteArray::fromStdString(params)).object();
        const auto sun = vec->getMetadata<openvdb::Vec3DMetadata>("sylva_sun");
        QVERIFY(sun);
        for (int a = 0; a < 3; ++a) QCOMPARE(sun->value()[a], json["sun"].toArray()[a].toDouble());
        const auto tol = vec->getMetadata<openvdb::DoubleMetadata>("sylva_tolerance");
        QVERIFY(tol);
        QCOMPARE(tol->value(), 1e-4);
        const auto preset = vec->getMetadata<openvdb::StringMetadata>("sylva_preset");
        QVERIFY(preset);
        QCOMPARE(preset->value(), std::string("dogrose"));
        QVERIFY(vec->getMetadata<openvdb::BoolMetadata>("sylva_zero_f0"));
        const auto whole = vec->getMetadata<openvdb::StringMetadata>("sylva_parameters");
        QVERIFY(whole);
        QCOMPARE(QJsonDocument::fromJson(QByteArray::fromStdString(whole->value())).object(), json);
    }

    // A .vdb from OpenVDB's API (no Sylva metadata, a vec3 grid first, the float grid not called
    // "density", negative index coordinates, an active tile) is read as the first float grid inside its
    // active box grown by one node, and `sylva light` lights it: the same grid as the library's solve
    // of that density, brighter above the medium than below it.
    void foreignVdbIsReadAndLit()
    {
        const double voxel = 0.1;
        openvdb::math::Transform::Ptr xf = openvdb::math::Transform::createLinearTransform(voxel);
        xf->postTranslate(openvdb::Vec3d(2.0, 0.5, -1.0));
        openvdb::Vec3SGrid::Ptr vel = openvdb::Vec3SGrid::create();
        vel->setName("vel");
        vel->tree().setValue(openvdb::Coord(0, 0, 0), openvdb::Vec3s(1, 2, 3));
        openvdb::FloatGrid::Ptr smoke = openvdb::FloatGrid::create(0.0f);
        smoke->setName("smoke");
        smoke->setTransform(xf);
        smoke->setGridClass(openvdb::GRID_FOG_VOLUME);
        auto acc = smoke->getAccessor();
        for (int x = -6; x <= 5; ++x)
            for (int y = -6; y <= 5; ++y)
                for (int z = -6; z <= 5; ++z)
                    if (x * x + y * y + z * z <= 25) acc.setValue(openvdb::Coord(x, y, z), 0.3f + 0.02f * float(x + y));
        smoke->tree().addTile(1, openvdb::Coord(8, -8, -8), 0.8f, true);   // an active 8^3 tile beside the ball
        const std::string path = out("foreign.vdb");
        writeVdbWithApi(path, {vel, smoke});

        const DensityGrid d = readDensityFile(path);
        const openvdb::CoordBBox active = smoke->evalActiveVoxelBoundingBox();
        QCOMPARE(d.geometry.dims, glm::ivec3(active.dim().x() + 2, active.dim().y() + 2, active.dim().z() + 2));
        QCOMPARE(d.geometry.spacing, voxel);
        const openvdb::Coord lo = active.min().offsetBy(-1);
        for (int a = 0; a < 3; ++a) QVERIFY(std::fabs(d.geometry.origin[a] - xf->indexToWorld(lo)[a]) < 1e-12);
        const auto cAcc = smoke->getConstAccessor();
        for (int i = 0; i < d.geometry.dims.x; ++i)
            for (int j = 0; j < d.geometry.dims.y; ++j)
                for (int k = 0; k < d.geometry.dims.z; ++k) {
                    const openvdb::Coord c = lo.offsetBy(i, j, k);
                    const float want = cAcc.isValueOn(c) ? cAcc.getValue(c) : 0.0f;
                    if (d.density[d.geometry.index(i, j, k)] != want) QFAIL(qPrintable(QString("node %1,%2,%3").arg(i).arg(j).arg(k)));
                }
        QCOMPARE(d.density[d.geometry.index(0, 0, 0)], 0.0f);   // the border node

        const std::string lit = out("foreign_lit.vdb");
        const Run r = runSylva({"light", "--density", QString::fromStdString(path), "--sun", "0,1,0", "--steps", "40", "--backend",
                                "cpu", "--no-cache", "--quiet", "-o", QString::fromStdString(lit)});
        QVERIFY2(r.code == 0, qPrintable(r.err));
        lb::LbParams p = lb::paramsFromPreset(*lb::findPreset("leaf"));
        lb::useFrontDefaults(p);   // sylva light's default storage (fp16; --steps sets the count)
        p.sun = {0.0f, 1.0f, 0.0f};
        p.steps = 40;
        const LightingGrid want = lightingFor(d, p, nullptr);
        const LightingGrid got = readLightingFile(lit);
        QVERIFY(got.geometry == d.geometry);
        QVERIFY(sameBits(got.rgb, want.rgb));
        // Through OpenVDB's API: the lit file's grid sits where the smoke was (the same world point
        // for the same node).
        const auto lighting = openGrid<openvdb::Vec3SGrid>(lit, "lighting");
        QVERIFY(lighting);
        const openvdb::Vec3d w = lighting->indexToWorld(openvdb::Coord(1, 1, 1));
        for (int a = 0; a < 3; ++a) QVERIFY(std::fabs(w[a] - xf->indexToWorld(lo.offsetBy(1, 1, 1))[a]) < 1e-9);
        // The sun is at +y: light above the ball exceeds light in its shadow below.
        const int ci = 1 + (0 - active.min().x()), ck = 1 + (0 - active.min().z());
        const float above = got.at(ci, d.geometry.dims.y - 2, ck, 1), below = got.at(ci, 1, ck, 1);
        QVERIFY2(above > below * 1.2f, qPrintable(QString("above %1 below %2").arg(above).arg(below)));
    }

    void badFilesAreRefused()
    {
        auto write = [&](const char* name, const QByteArray& bytes) {
            QFile f(QString::fromStdString(out(name)));
            QVERIFY(f.open(QIODevice::WriteOnly));
            f.write(bytes);
        };
        write("garbage.vdb", "this is not an OpenVDB file at all \x01\x02\x03\x04 and some more bytes to read");
        write("empty.vdb", "");
        std::string m = errorOf([&] { readDensityFile(out("garbage.vdb")); });
        QVERIFY2(m.rfind(out("garbage.vdb") + ": not a readable OpenVDB file", 0) == 0, m.c_str());
        m = errorOf([&] { readDensityFile(out("empty.vdb")); });
        QVERIFY2(m.find("empty file") != std::string::npos, m.c_str());
        m = errorOf([&] { readDensityFile(out("missing.vdb")); });
        QVERIFY2(m.find("no such file") != std::string::npos, m.c_str());

        // A valid file cut short.
        writeDensityFile(out("whole.vdb"), testDensity());
        QFile whole(QString::fromStdString(out("whole.vdb")));
        QVERIFY(whole.open(QIODevice::ReadOnly));
        write("truncated.vdb", whole.readAll().left(int(whole.size() / 2)));
        m = errorOf([&] { readDensityFile(out("truncated.vdb")); });
        QVERIFY2(m.rfind(out("truncated.vdb") + ":", 0) == 0, m.c_str());

        const auto linear = openvdb::math::Transform::createLinearTransform(0.1);
        openvdb::Vec3SGrid::Ptr vel = openvdb::Vec3SGrid::create();
        vel->setName("vel");
        vel->tree().setValue(openvdb::Coord(1, 2, 3), openvdb::Vec3s(1.0f));
        openvdb::BoolGrid::Ptr mask = openvdb::BoolGrid::create();
        mask->setName("mask");
        writeVdbWithApi(out("nofloat.vdb"), {vel, mask});
        m = errorOf([&] { readDensityFile(out("nofloat.vdb")); });
        QVERIFY2(m.find("no float grid") != std::string::npos && m.find("'vel' (vec3s)") != std::string::npos, m.c_str());
        m = errorOf([&] { readLightingFile(out("nofloat.vdb")); });
        QVERIFY2(m.find("no lighting grid") != std::string::npos, m.c_str());

        openvdb::math::Mat4d rot = openvdb::math::Mat4d::identity();
        rot.preRotate(openvdb::math::Y_AXIS, 0.3);
        rot.preScale(openvdb::Vec3d(0.1));
        writeVdbWithApi(out("rotated.vdb"), {sparseFloat("density", openvdb::math::Transform::createLinearTransform(rot), {{0, 0, 0}, {3, 3, 3}})});
        m = errorOf([&] { readDensityFile(out("rotated.vdb")); });
        QVERIFY2(m.find("rotated or sheared") != std::string::npos, m.c_str());

        openvdb::math::Mat4d scale = openvdb::math::Mat4d::identity();
        scale.preScale(openvdb::Vec3d(0.1, 0.1, 0.2));
        writeVdbWithApi(out("nonuniform.vdb"), {sparseFloat("density", openvdb::math::Transform::createLinearTransform(scale), {{0, 0, 0}})});
        m = errorOf([&] { readDensityFile(out("nonuniform.vdb")); });
        QVERIFY2(m.find("non-uniform voxel size (0.1, 0.1, 0.2)") != std::string::npos, m.c_str());

        writeVdbWithApi(out("large.vdb"), {sparseFloat("density", linear, {{0, 0, 0}, {600, 600, 600}})});
        m = errorOf([&] { readDensityFile(out("large.vdb")); });
        QVERIFY2(m.find("603x603x603") != std::string::npos && m.find("at most 134217728 nodes") != std::string::npos, m.c_str());

        openvdb::FloatGrid::Ptr sdf = sparseFloat("surface", linear, {{0, 0, 0}});
        sdf->setGridClass(openvdb::GRID_LEVEL_SET);
        writeVdbWithApi(out("levelset.vdb"), {sdf});
        m = errorOf([&] { readDensityFile(out("levelset.vdb")); });
        QVERIFY2(m.find("level set") != std::string::npos, m.c_str());

        openvdb::DoubleGrid::Ptr dbl = openvdb::DoubleGrid::create();
        dbl->setName("density");
        dbl->tree().setValue(openvdb::Coord(0), 0.5);
        writeVdbWithApi(out("double.vdb"), {dbl, sparseFloat("other", linear, {{0, 0, 0}})});
        m = errorOf([&] { readDensityFile(out("double.vdb")); });
        QVERIFY2(m.find("'density' holds double values") != std::string::npos, m.c_str());

        openvdb::FloatGrid::Ptr emptyGrid = openvdb::FloatGrid::create();
        emptyGrid->setName("density");
        writeVdbWithApi(out("noactive.vdb"), {emptyGrid});
        m = errorOf([&] { readDensityFile(out("noactive.vdb")); });
        QVERIFY2(m.find("no active voxels") != std::string::npos, m.c_str());

        // The command line: light exits 1 naming the file; info describes a valid VDB and says why it
        // is no density, and exits 1 for garbage.
        for (const char* name : {"garbage.vdb", "nofloat.vdb", "rotated.vdb"}) {
            const QString p = QString::fromStdString(out(name));
            const Run r = runSylva({"light", "--density", p, "--sun", "0,1,0", "--no-cache", "-o", m_dir + "/never.vdb"});
            QCOMPARE(r.code, 1);
            QVERIFY2(r.err.contains(p), qPrintable(r.err));
        }
        QVERIFY(!QFile::exists(m_dir + "/never.vdb"));
        Run r = runSylva({"info", QString::fromStdString(out("garbage.vdb"))});
        QCOMPARE(r.code, 1);
        QVERIFY2(r.err.contains(QString::fromStdString(out("garbage.vdb"))), qPrintable(r.err));
        r = runSylva({"info", QString::fromStdString(out("rotated.vdb"))});
        QCOMPARE(r.code, 0);
        QVERIFY2(r.out.contains("grid 'density': float") && r.out.contains("as a Sylva density: not readable (grid 'density' has a rotated"),
                 qPrintable(r.out));
    }

    // sylva voxelize -o d.vdb holds what -o d.npy holds; sylva info lists its grids; sylva light of
    // either gives the same lighting; the species grid export writes one .vdb with every grid.
    void commandsWriteAndReadVdb()
    {
        GrowOptions g;
        g.species = TreeSpecies::Shrub;
        g.targetTriangles = 3000;
        const QString mesh = m_dir + "/shrub.obj";
        writeObj(mesh.toStdString(), growTree(g));
        Run r = runSylva({"voxelize", mesh, "--grid", "16", "--no-cache", "-o", m_dir + "/d.npy"});
        QVERIFY2(r.code == 0, qPrintable(r.err));
        r = runSylva({"voxelize", mesh, "--grid", "16", "--no-cache", "-o", m_dir + "/d.vdb"});
        QVERIFY2(r.code == 0, qPrintable(r.err));
        QVERIFY2(r.out.contains("wrote " + m_dir + "/d.vdb\n"), qPrintable(r.out));
        QVERIFY(!QFile::exists(m_dir + "/d.vdb.json") && !QFile::exists(m_dir + "/d.vdb.wood.npy"));
        const DensityGrid fromNpy = readDensityFile(out("d.npy"));
        const DensityGrid fromVdb = readDensityFile(out("d.vdb"));
        QVERIFY(fromVdb.geometry == fromNpy.geometry);
        QVERIFY(sameBits(fromVdb.density, fromNpy.density));
        QVERIFY(sameBits(fromVdb.woodFraction, fromNpy.woodFraction));

        r = runSylva({"info", m_dir + "/d.vdb"});
        QVERIFY2(r.code == 0, qPrintable(r.err));
        QVERIFY2(r.out.contains("OpenVDB file") && r.out.contains("grid 'density': float, class fog volume") &&
                     r.out.contains("grid 'wood_fraction'") && r.out.contains("every grid:\n  sylva_dims = [16"),
                 qPrintable(r.out));

        for (const char* input : {"d.npy", "d.vdb"}) {
            const QString o = m_dir + "/l_" + QString(input).replace('.', '_') + ".vdb";
            r = runSylva({"light", "--density", m_dir + "/" + input, "--sun", "0.3,1,0.2", "--steps", "20", "--backend", "cpu",
                          "--no-cache", "--quiet", "-o", o});
            QVERIFY2(r.code == 0, qPrintable(r.err));
        }
        const LightingGrid a = readLightingFile(out("l_d_npy.vdb")), b = readLightingFile(out("l_d_vdb.vdb"));
        QVERIFY(a.geometry == fromNpy.geometry && b.geometry == a.geometry);
        QVERIFY(sameBits(a.rgb, b.rgb));
        QVERIFY(sameBits(readDensityFile(out("l_d_vdb.vdb")).density, fromNpy.density));   // light -o x.vdb holds the density too

        Scene s;
        s.species.resize(1);
        s.species[0].name = "Shrub 1";
        s.species[0].meshPath = mesh.toStdString();
        s.species[0].lighting = lb::paramsFromPreset(*lb::findPreset("leaf"));
        s.species[0].lighting.steps = 10;
        s.species[0].grid = 12;
        const GridExportFiles files = exportSpeciesGrids(s, 0, m_dir.toStdString(), nullptr, nullptr, nullptr, nullptr, nullptr,
                                                         GridFileFormat::Vdb);
        QCOMPARE(files.density, out("Shrub_1.vdb"));
        QCOMPARE(files.lighting, files.density);
        const DensityGrid ed = readDensityFile(files.density);
        const LightingGrid el = readLightingFile(files.lighting);
        QCOMPARE(ed.geometry.longestEdge(), 12);
        QVERIFY(el.geometry == ed.geometry);
        const SpeciesGrids solved = loadSpeciesGrids(s, 0, nullptr);   // what the export writes, solved again
        QVERIFY(ed.geometry == solved.density.geometry);
        QVERIFY(sameBits(ed.density, solved.density.density));
        QVERIFY(sameBits(ed.woodFraction, solved.density.woodFraction));
        QVERIFY(sameBits(el.rgb, solved.lighting.rgb));
    }

    // sylva export SCENE: one NAME.vdb per species (or the .npy files with --format npy) holding the
    // grids the library's loadSpeciesGrids gives for the scene read back; unknown species exit 1, a bad
    // format 2.
    void exportCommand()
    {
        Scene s;
        s.species.resize(2);
        s.species[0].name = "Shrub A";
        s.species[1].name = "other";
        for (SpeciesDesc& sp : s.species) {
            sp.meshPath = out("shrub.obj");   // written by commandsWriteAndReadVdb
            sp.lighting = lb::paramsFromPreset(*lb::findPreset("leaf"));
            sp.lighting.steps = 8;
            sp.grid = 10;
        }
        s.species[1].grid = 9;
        InstanceDesc a;
        s.instances = {a};
        const QString scenePath = m_dir + "/export.sylva.json";
        writeSceneFile(s, scenePath.toStdString());
        const QString folder = m_dir + "/exported";
        Run r = runSylva({"export", scenePath, "--species", "Shrub A", "--out", folder, "--no-cache", "--backend", "cpu", "--quiet"});
        QVERIFY2(r.code == 0, qPrintable(r.err));
        QVERIFY2(r.out == "wrote " + folder + "/Shrub_A.vdb\n", qPrintable(r.out));
        QVERIFY(!QFile::exists(folder + "/other.vdb"));
        const Scene read = readSceneFile(scenePath.toStdString());
        const SpeciesGrids want = loadSpeciesGrids(read, 0, nullptr);
        const std::string vdb = (folder + "/Shrub_A.vdb").toStdString();
        const DensityGrid d = readDensityFile(vdb);
        const LightingGrid l = readLightingFile(vdb);
        QVERIFY(d.geometry == want.density.geometry && l.geometry == want.lighting.geometry);
        QVERIFY(sameBits(d.density, want.density.density) && sameBits(d.woodFraction, want.density.woodFraction));
        QVERIFY(sameBits(l.rgb, want.lighting.rgb));

        r = runSylva({"export", scenePath, "--format", "npy", "--out", folder, "--no-cache", "--backend", "cpu", "--quiet"});
        QVERIFY2(r.code == 0, qPrintable(r.err));
        for (const char* f : {"Shrub_A.density.npy", "Shrub_A.density.wood.npy", "Shrub_A.lighting.npy", "other.density.npy", "other.lighting.npy.json"})
            QVERIFY2(r.out.contains(folder + "/" + f) && QFile::exists(folder + "/" + f), f);
        QCOMPARE(readDensityFile((folder + "/other.density.npy").toStdString()).geometry.longestEdge(), 9);
        QVERIFY(sameBits(readLightingFile((folder + "/Shrub_A.lighting.npy").toStdString()).rgb, l.rgb));

        r = runSylva({"export", scenePath, "--species", "palm", "--out", folder});
        QCOMPARE(r.code, 1);
        QVERIFY2(r.err.contains("no species 'palm'") && r.err.contains("'Shrub A', 'other'"), qPrintable(r.err));
        r = runSylva({"export", scenePath, "--format", "exr"});
        QCOMPARE(r.code, 2);
    }

    // Every command with -o refuses a name whose extension it cannot write (exit 2), before any work
    // and without writing anything; today's mistake, -o x.vdb for a .npy-only writer, included.
    void unwritableExtensionsAreRefused_data()
    {
        QTest::addColumn<QStringList>("args");
        QTest::addColumn<QString>("output");
        const QString dir = QString(SYLVA_TEST_OUTPUT) + "/vdb";
        const QString density = dir + "/small.npy";
        QTest::newRow("voxelize .png") << QStringList{"voxelize", dir + "/shrub.obj", "--no-cache", "-o"} << dir + "/x.png";
        QTest::newRow("voxelize no extension") << QStringList{"voxelize", dir + "/shrub.obj", "--no-cache", "-o"} << dir + "/x";
        QTest::newRow("light .vdb2") << QStringList{"light", "--density", density, "--sun", "0,1,0", "--no-cache", "-o"} << dir + "/x.vdb2";
        QTest::newRow("light .obj") << QStringList{"light", "--density", density, "--sun", "0,1,0", "--no-cache", "-o"} << dir + "/x.obj";
        QTest::newRow("reference .vdb") << QStringList{"reference", "--density", density, "--sun", "0,1,0", "--paths", "100", "-o"}
                                        << dir + "/x.vdb";
        QTest::newRow("grow .npy") << QStringList{"grow", "--triangles", "1000", "-o"} << dir + "/x.npy";
        QTest::newRow("render .vdb") << QStringList{"render", "--width", "8", "--height", "8", "-o"} << dir + "/x.vdb";
        QTest::newRow("sky .vdb") << QStringList{"sky", "--width", "16", "-o"} << dir + "/x.vdb";
    }
    void unwritableExtensionsAreRefused()
    {
        QFETCH(QStringList, args);
        QFETCH(QString, output);
        DensityGrid d;
        d.geometry.dims = {4, 4, 4};
        d.density.assign(64, 0.5f);
        writeDensityGrid(out("small.npy"), d);
        const Run r = runSylva(args << output);
        QCOMPARE(r.code, 2);
        QVERIFY2(r.err.contains(output), qPrintable(r.err));   // the message names the output
        QVERIFY(!QFile::exists(output));
    }
};

QTEST_GUILESS_MAIN(TestVdb)
#include "tst_vdb.moc"
