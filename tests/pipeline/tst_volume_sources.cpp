// Tests of the sources of density: the pyroclastic cloud generator against its published
// formula, the solid voxelizer against closed-form volumes and brute-force winding numbers (a sphere,
// a sphere with a hole, the open Utah teapot of tests/data/models), and the commands `sylva volume cloud`,
// `sylva simulate` and `sylva voxelize --solid` (files read back, bad input refused with exit 1).
#include <QTemporaryDir>
#include <QTest>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <map>
#include <random>

#include <tbb/global_control.h>

#include "core/base/error.h"
#include "core/volume/pyroclastic.h"
#include "core/voxel/solid_voxelize.h"
#include "core/voxel/winding_number.h"
#include "pipeline/import/mesh_import.h"
#include "pipeline/io/grid_file.h"
#include "tests/common/run_program.h"

using namespace sylva;
using namespace sylva::volume;

namespace {

constexpr double kPi = 3.14159265358979323846;

// An icosphere of radius r (subdivided `levels` times), outward oriented, watertight.
TriangleMesh icosphere(float r, int levels)
{
    TriangleMesh m;
    const float t = (1.0f + std::sqrt(5.0f)) / 2.0f;
    m.positions = {{-1, t, 0}, {1, t, 0}, {-1, -t, 0}, {1, -t, 0}, {0, -1, t}, {0, 1, t},
                   {0, -1, -t}, {0, 1, -t}, {t, 0, -1}, {t, 0, 1}, {-t, 0, -1}, {-t, 0, 1}};
    m.triangles = {{0, 11, 5}, {0, 5, 1}, {0, 1, 7}, {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4}, {11, 10, 2}, {10, 7, 6}, {7, 1, 8},
                   {3, 9, 4}, {3, 4, 2}, {3, 2, 6}, {3, 6, 8}, {3, 8, 9}, {4, 9, 5}, {2, 4, 11}, {6, 2, 10}, {8, 6, 7}, {9, 8, 1}};
    for (auto& p : m.positions) p = glm::normalize(p);
    for (int l = 0; l < levels; ++l) {
        std::vector<glm::uvec3> next;
        std::map<std::pair<uint32_t, uint32_t>, uint32_t> mid;
        auto middle = [&](uint32_t a, uint32_t b) {
            const auto key = std::make_pair(std::min(a, b), std::max(a, b));
            auto it = mid.find(key);
            if (it != mid.end()) return it->second;
            m.positions.push_back(glm::normalize(m.positions[a] + m.positions[b]));
            return mid[key] = uint32_t(m.positions.size() - 1);
        };
        for (const auto& tri : m.triangles) {
            const uint32_t a = middle(tri[0], tri[1]), b = middle(tri[1], tri[2]), c = middle(tri[2], tri[0]);
            next.push_back({tri[0], a, c});
            next.push_back({tri[1], b, a});
            next.push_back({tri[2], c, b});
            next.push_back({a, b, c});
        }
        m.triangles = next;
    }
    for (auto& p : m.positions) p *= r;
    return m;
}

double gridVolume(const DensityGrid& g)
{
    double s = 0.0;
    for (float d : g.density) s += d;
    return s * g.geometry.spacing * g.geometry.spacing * g.geometry.spacing;
}

float trilinear(const DensityGrid& g, const glm::dvec3& world)
{
    const glm::dvec3 s = (world - g.geometry.origin) / g.geometry.spacing;
    const glm::ivec3 n = g.geometry.dims;
    glm::ivec3 i0;
    glm::dvec3 t;
    for (int a = 0; a < 3; ++a) {
        const double c = std::clamp(s[a], 0.0, double(n[a] - 1));
        i0[a] = std::min(int(c), n[a] - 2);
        t[a] = c - i0[a];
    }
    double v = 0.0;
    for (int c = 0; c < 8; ++c) {
        const glm::ivec3 o((c & 1), (c >> 1) & 1, (c >> 2) & 1);
        const double w = (o.x ? t.x : 1 - t.x) * (o.y ? t.y : 1 - t.y) * (o.z ? t.z : 1 - t.z);
        v += w * g.density[g.geometry.index(i0.x + o.x, i0.y + o.y, i0.z + o.z)];
    }
    return float(v);
}

QString teapotPath() { return QStringLiteral(SYLVA_TEST_DATA "/models/teapot.obj"); }

} // namespace

class TestVolumeSources : public QObject {
    Q_OBJECT
private Q_SLOTS:
    // Same parameters, same bits (on one thread and on all); another seed, another cloud.
    void pyroclasticIsDeterministic()
    {
        PyroclasticParams p;
        p.resolution = 48;
        p.seed = 11;
        const DensityGrid a = makePyroclasticCloud(p);
        DensityGrid b;
        {
            tbb::global_control one(tbb::global_control::max_allowed_parallelism, 1);
            b = makePyroclasticCloud(p);
        }
        QVERIFY(a.density == b.density);
        QVERIFY(std::memcmp(a.density.data(), b.density.data(), a.density.size() * sizeof(float)) == 0);
        p.seed = 12;
        QVERIFY(makePyroclasticCloud(p).density != a.density);
    }

    // The grid's surface radius along 300 random directions (outermost 0.5 crossing of the trilinear
    // density) against the published formula's outermost root of R + A |fbm(t d f)| - t (solved here by
    // bisection): within one node spacing; every radius in [R, R + A]; with A = 0 a sphere whose volume
    // is 4/3 pi R^3 within 1%.
    void pyroclasticRadiusFollowsParameters()
    {
        PyroclasticParams p;
        p.radius = 1.0f;
        p.amplitude = 0.6f;
        p.frequency = 1.2f;
        p.octaves = 3;
        p.resolution = 96;
        p.seed = 5;
        const DensityGrid g = makePyroclasticCloud(p);
        const double h = g.geometry.spacing;
        std::mt19937 rng(2);
        std::normal_distribution<double> nd;
        double sumGrid = 0.0, sumFormula = 0.0, worst = 0.0;
        const int rays = 300;
        for (int r = 0; r < rays; ++r) {
            glm::dvec3 d(nd(rng), nd(rng), nd(rng));
            d = glm::normalize(d);
            auto f = [&](double t) { return double(pyroclasticSurfaceRadius(p, glm::vec3(d * t))) - t; };
            double t = p.radius + p.amplitude + 0.01;
            const double dt = 0.002;
            while (f(t) < 0.0) t -= dt;
            double lo = t, hi = t + dt;
            for (int it = 0; it < 40; ++it) {
                const double m = 0.5 * (lo + hi);
                (f(m) >= 0.0 ? lo : hi) = m;
            }
            const double formula = lo;
            double s = p.radius + p.amplitude + 2 * h;
            while (trilinear(g, glm::dvec3(p.centre) + d * s) < 0.5f * p.density) s -= 0.05 * h;
            QVERIFY(formula >= p.radius - 1e-6 && formula <= p.radius + p.amplitude + 1e-6);
            worst = std::max(worst, std::fabs(s - formula));
            sumGrid += s;
            sumFormula += formula;
        }
        QVERIFY2(worst < h, qPrintable(QString("worst radius error %1 m, spacing %2 m").arg(worst).arg(h)));
        QVERIFY(std::fabs(sumGrid - sumFormula) / rays < 0.25 * h);
        QVERIFY(sumFormula / rays > p.radius + 0.05 * p.amplitude);   // the noise does displace
        p.amplitude = 0.0f;
        const double v = gridVolume(makePyroclasticCloud(p));
        QVERIFY2(std::fabs(v - 4.0 / 3.0 * kPi) < 0.01 * 4.0 / 3.0 * kPi, qPrintable(QString::number(v)));
    }

    void pyroclasticRefusesBadParameters()
    {
        PyroclasticParams p;
        p.radius = -1.0f;
        QVERIFY_THROWS_EXCEPTION(Error, makePyroclasticCloud(p));
        p = {};
        p.resolution = 4;
        QVERIFY_THROWS_EXCEPTION(Error, makePyroclasticCloud(p));
        p = {};
        p.density = std::nanf("");
        QVERIFY_THROWS_EXCEPTION(Error, makePyroclasticCloud(p));
    }

    // The accelerated winding number against the exact sum, on points near and far from the surface:
    // within 0.02 (first-order dipoles at beta 2; the inside test thresholds at 0.5).
    void windingNumberMatchesExact()
    {
        const TriangleMesh m = icosphere(1.0f, 3);
        const WindingNumber w(m);
        std::mt19937 rng(4);
        std::uniform_real_distribution<double> u(-1.6, 1.6);
        for (int i = 0; i < 200; ++i) {
            const glm::dvec3 p(u(rng), u(rng), u(rng));
            QVERIFY2(std::fabs(w(p) - w.exact(p)) < 2e-2, qPrintable(QString("%1 vs %2").arg(w(p)).arg(w.exact(p))));
        }
        QVERIFY(std::fabs(w.exact({0.1, 0.2, -0.1}) - 1.0) < 1e-9);
        QVERIFY(std::fabs(w.exact({1.5, 0.2, -0.1})) < 1e-9);
    }

    // A watertight sphere's filled volume within 1% of 4/3 pi r^3 (and the mesh inward-oriented too).
    void solidSphereVolume()
    {
        TriangleMesh m = icosphere(1.0f, 5);   // polyhedron volume 0.1% under the sphere's
        VoxelizeSettings s;
        s.longestAxisNodes = 48;
        s.solid = true;
        const DensityGrid g = voxelize(m, s);
        const double exact = 4.0 / 3.0 * kPi;
        QVERIFY2(std::fabs(gridVolume(g) - exact) < 0.01 * exact, qPrintable(QString::number(gridVolume(g))));
        for (float w : g.woodFraction) QCOMPARE(w, 0.0f);
        // The surface voxelizer alone is a shell, far from the volume.
        s.solid = false;
        QVERIFY(gridVolume(voxelize(m, s)) < 0.5 * exact);
        for (auto& t : m.triangles) std::swap(t[1], t[2]);
        s.solid = true;
        QVERIFY(std::fabs(gridVolume(voxelize(m, s)) - exact) < 0.01 * exact);
    }

    // A sphere with a cap of 35 degrees removed (an open mesh): still filled (within 4% of the volume
    // of the sphere; the cut-off cap is 1.6% of it), nothing outside the sphere filled.
    void solidOpenSphereDoesNotLeak()
    {
        TriangleMesh m = icosphere(1.0f, 4);
        std::vector<glm::uvec3> kept;
        const float cosCap = std::cos(35.0f * float(kPi) / 180.0f);
        for (const auto& t : m.triangles) {
            const glm::vec3 c = (m.positions[t[0]] + m.positions[t[1]] + m.positions[t[2]]) / 3.0f;
            if (glm::normalize(c).y < cosCap) kept.push_back(t);
        }
        m.triangles = kept;
        VoxelizeSettings s;
        s.longestAxisNodes = 48;
        s.solid = true;
        const DensityGrid g = voxelize(m, s);
        const double exact = 4.0 / 3.0 * kPi;
        QVERIFY2(std::fabs(gridVolume(g) - exact) < 0.04 * exact, qPrintable(QString::number(gridVolume(g) / exact)));
        const GridGeometry& geo = g.geometry;
        for (int i = 0; i < geo.dims.x; ++i)
            for (int j = 0; j < geo.dims.y; ++j)
                for (int k = 0; k < geo.dims.z; ++k) {
                    const glm::dvec3 p = geo.origin + geo.spacing * glm::dvec3(i, j, k);
                    if (glm::length(p) > 1.0 + geo.spacing) QCOMPARE(g.density[geo.index(i, j, k)], 0.0f);
                    if (glm::length(p) < 0.8) QCOMPARE(g.density[geo.index(i, j, k)], 1.0f);
                }
    }

    // The open teapot (256 open edges; spout and handle are tubes whose ends are open): body, spout and
    // handle filled, nothing leaks through the open ends, corners empty, and the filled volume equal to
    // a Monte Carlo estimate of the inside volume by the exact winding number within 3 sigma + 2%.
    void teapotIsFilled()
    {
        QVERIFY2(QFile::exists(teapotPath()), qPrintable(teapotPath()));
        const TriangleMesh mesh = importMesh(teapotPath().toStdString());
        VoxelizeSettings s;
        s.longestAxisNodes = 48;
        s.solid = true;
        const DensityGrid g = voxelize(mesh, s);
        const GridGeometry& geo = g.geometry;
        auto nearest = [&](const glm::dvec3& p) {
            const glm::ivec3 i = glm::ivec3(glm::round((p - geo.origin) / geo.spacing));
            return g.density[geo.index(i.x, i.y, i.z)];
        };
        const Bounds3 b = meshBounds(mesh);
        // Tube axes: the centroids of the vertices in a thin x band of the handle and of the spout.
        auto bandCentroid = [&](float x0, float x1) {
            glm::dvec3 c(0.0);
            int n = 0;
            for (const auto& p : mesh.positions)
                if (p.x > x0 && p.x < x1) {
                    c += glm::dvec3(p);
                    ++n;
                }
            return c / double(n);
        };
        const glm::dvec3 handle = bandCentroid(b.lo.x, b.lo.x + 0.08f), spout = bandCentroid(1.55f, 1.65f);
        qInfo("handle axis (%.2f %.2f %.2f), spout axis (%.2f %.2f %.2f)", handle.x, handle.y, handle.z, spout.x, spout.y, spout.z);
        QVERIFY(nearest({0.0, -0.2, 0.0}) == 1.0f);
        QVERIFY(nearest({0.0, 0.6, 0.0}) == 1.0f);
        QVERIFY(nearest(handle + glm::dvec3(0.04, 0, 0)) > 0.5f);
        QVERIFY(nearest(spout) > 0.5f);
        // Above the spout's open tip (a ring in a nearly horizontal plane) and at the corners of the
        // box: empty.
        const glm::dvec3 tip = bandCentroid(b.hi.x - 0.06f, b.hi.x + 1.0f);
        QCOMPARE(nearest(tip + glm::dvec3(0.0, 3.0 * geo.spacing, 0.0)), 0.0f);
        QCOMPARE(nearest(tip + glm::dvec3(0.0, 6.0 * geo.spacing, 0.0)), 0.0f);
        for (int c = 0; c < 8; ++c) {
            const glm::dvec3 p((c & 1) ? b.hi.x - 0.05 : b.lo.x + 0.05, (c & 2) ? b.hi.y - 0.05 : b.lo.y + 0.05,
                               (c & 4) ? b.hi.z - 0.05 : b.lo.z + 0.05);
            QCOMPARE(nearest(p), 0.0f);
        }
        // Volume against the exact winding number at random points of the mesh box.
        const WindingNumber w(mesh);
        std::mt19937 rng(9);
        std::uniform_real_distribution<double> ux(b.lo.x, b.hi.x), uy(b.lo.y, b.hi.y), uz(b.lo.z, b.hi.z);
        const int samples = 1000;
        int inside = 0;
        for (int i = 0; i < samples; ++i)
            if (std::fabs(w.exact({ux(rng), uy(rng), uz(rng)})) >= 0.5) ++inside;
        const glm::dvec3 ext = glm::dvec3(b.hi) - glm::dvec3(b.lo);
        const double boxVolume = ext.x * ext.y * ext.z, frac = double(inside) / samples;
        const double mc = frac * boxVolume, sigma = std::sqrt(frac * (1 - frac) / samples) * boxVolume;
        qInfo("teapot solid volume %.4f, Monte Carlo %.4f +- %.4f", gridVolume(g), mc, sigma);
        QVERIFY(std::fabs(gridVolume(g) - mc) < 3.0 * sigma + 0.02 * mc);
    }

    void commands()
    {
        QTemporaryDir dir;
        const QString d = dir.path();
        using sylva::test::runSylva;
        auto r = runSylva({"volume", "cloud", "--resolution", "32", "--seed", "3", "--radius", "0.5", "-o", d + "/c.npy"});
        QVERIFY2(r.code == 0, qPrintable(r.err));
        PyroclasticParams p;
        p.resolution = 32;
        p.seed = 3;
        p.radius = 0.5f;
        const DensityGrid read = readDensityFile((d + "/c.npy").toStdString());
        QVERIFY(read.density == makePyroclasticCloud(p).density);
        QCOMPARE(read.geometry.dims, glm::ivec3(32));
        r = runSylva({"volume", "cloud", "--resolution", "32", "--radius", "0", "-o", d + "/bad.npy"});
        QCOMPARE(r.code, 1);
        QVERIFY(r.err.contains("radius"));
        QVERIFY(!QFile::exists(d + "/bad.npy"));
        r = runSylva({"volume", "fog", "-o", d + "/bad.npy"});
        QCOMPARE(r.code, 2);

        // Two runs of the same simulation write the same bytes; frames every 3 steps and the last.
        for (const char* name : {"a", "b"}) {
            r = runSylva({"simulate", "--grid", "12,16,12", "--steps", "7", "--every", "3", "--temperature", "--quiet", "-o",
                          d + "/" + name + ".npy"});
            QVERIFY2(r.code == 0, qPrintable(r.err));
        }
        for (const char* f : {"_0003.npy", "_0006.npy", "_0007.npy", "_0007.temperature.npy"}) {
            QFile a(d + "/a" + f), b(d + "/b" + f);
            QVERIFY2(a.open(QIODevice::ReadOnly) && b.open(QIODevice::ReadOnly), f);
            QCOMPARE(a.readAll(), b.readAll());
        }
        const DensityGrid smoke = readDensityFile((d + "/a_0007.npy").toStdString());
        QCOMPARE(smoke.geometry.dims, glm::ivec3(12, 16, 12));
        r = runSylva({"simulate", "--grid", "0,16,12", "-o", d + "/s.npy"});
        QCOMPARE(r.code, 1);
        QVERIFY(r.err.contains("grid size"));
        r = runSylva({"simulate", "--grid", "12,16,12", "--dt", "1", "--source-velocity", "0,1,0", "-o", d + "/s.npy"});
        QCOMPARE(r.code, 1);
        QVERIFY(r.err.contains("CFL"));

        if (QFile::exists(teapotPath())) {
            r = runSylva({"voxelize", teapotPath(), "--solid", "--grid", "24", "--no-cache", "-o", d + "/t.npy"});
            QVERIFY2(r.code == 0, qPrintable(r.err));
            const TriangleMesh mesh = importMesh(teapotPath().toStdString());
            VoxelizeSettings s;
            s.longestAxisNodes = 24;
            s.solid = true;
            QVERIFY(readDensityFile((d + "/t.npy").toStdString()).density == voxelize(mesh, s).density);
        }
    }

    // Bad volume input in a scene: negative, NaN and over-range densities, a grid of
    // size 0, optics out of range (sigma < 0, g outside [-1, 1], sigma_t over the LB's bound of 1 for a
    // tracer that solves the LB) each exit 1 with the volume or file named and write no picture; single
    // scattering needs no LB and takes that medium. --volume-tracer replaces every volume's tracer: its
    // picture is the one of the scene file saying the same, and a name it does not know exits 2.
    void badVolumeInputAndTracerFlag()
    {
        QTemporaryDir dir;
        const std::string d = dir.path().toStdString();
        auto grid = [&](const char* name, float last, glm::ivec3 dims = glm::ivec3(6)) {
            DensityGrid g;
            g.geometry.dims = dims;
            g.geometry.spacing = 0.5;
            g.density.assign(g.geometry.nodeCount(), 0.5f);
            if (!g.density.empty()) g.density.back() = last;
            g.woodFraction.assign(g.density.size(), 0.0f);
            const std::string path = d + "/" + name + ".npy";
            if (dims.x > 0) writeDensityFile(path, g);
            return path;
        };
        auto scene = [&](const char* name, const std::string& gridPath, const std::string& extra) {
            const std::string path = d + "/" + name + ".sylva.json";
            std::FILE* f = std::fopen(path.c_str(), "w");
            std::fprintf(f,
                         "{\"version\": 1, \"species\": [{\"name\": \"s\", \"grow\": {\"species\": \"shrub\", \"triangles\": 2000}, "
                         "\"lighting\": {\"grid\": 8}}], \"instances\": [{\"species\": \"s\", \"position\": [0, 0, 6]}], "
                         "\"volumes\": [{\"name\": \"puff\", \"grid\": \"%s\"%s, \"instances\": [{\"position\": [0, 1.5, 3]}]}], "
                         "\"camera\": {\"position\": [0, 1.5, -3], \"target\": [0, 1.5, 3]}, \"render\": {\"width\": 24, \"height\": 16}}",
                         gridPath.c_str(), extra.c_str());
            std::fclose(f);
            return QString::fromStdString(path);
        };
        using sylva::test::runSylva;
        const QString out = QString::fromStdString(d + "/out.png");   // PNG: no timestamp in the file
        auto refused = [&](const QString& file, const char* says, const QStringList& more = {}) {
            const auto r = runSylva(QStringList{"render", file, "--no-cache", "--quiet", "-o", out} + more);
            QVERIFY2(r.code == 1, qPrintable(file + ": " + r.err));
            QVERIFY2(r.err.contains(says), qPrintable(r.err));
            QVERIFY(!QFile::exists(out));
        };
        const std::string good = grid("good", 0.5f);
        refused(scene("neg", grid("neg", -0.25f), ""), "holds -0.25");
        refused(scene("nan", grid("nan", std::nanf("")), ""), "holds nan");
        refused(scene("over", grid("over", 0.6f), ", \"density_scale\": 2"), "in [0, 1]");
        {   // a grid of size 0: a .npy of shape (0, 6, 6) beside a valid sidecar
            grid("empty_src", 0.5f);
            QFile::copy(QString::fromStdString(d + "/empty_src.npy.json"), QString::fromStdString(d + "/empty.npy.json"));
            QFile f(QString::fromStdString(d + "/empty.npy"));
            QVERIFY(f.open(QIODevice::WriteOnly));
            std::string header = "{'descr': '<f4', 'fortran_order': False, 'shape': (0, 6, 6), }";
            header.append(size_t(63 - (header.size() + 10) % 64), ' ');
            header += '\n';
            const char magic[8] = {'\x93', 'N', 'U', 'M', 'P', 'Y', 1, 0};
            f.write(magic, 8);
            const char len[2] = {char(header.size() & 0xff), char(header.size() >> 8)};
            f.write(len, 2);
            f.write(header.data(), qint64(header.size()));
            f.close();
            refused(scene("empty", d + "/empty.npy", ""), "zero-sized");
        }
        refused(scene("siga", good, ", \"sigma_a\": -0.1"), "must be >= 0");
        refused(scene("g", good, ", \"g\": 1.5"), "g must lie in [-1, 1]");
        refused(scene("lbbound", good, ", \"sigma_s\": 3"), "volume 'puff'");   // sigma_t 3.008 x density 0.5 > 1

        // The same medium under single scattering: no LB solve, a finite picture.
        auto r = runSylva({"render", scene("lbbound_single", good, ", \"sigma_s\": 3, \"tracer\": \"single\""), "--no-cache", "--quiet", "-o", out});
        QVERIFY2(r.code == 0, qPrintable(r.err));
        QFile::remove(out);

        // --volume-tracer against the scene key.
        auto bytes = [&](const QStringList& args) {
            const auto run = runSylva(args);
            if (run.code != 0) qWarning("%s", qPrintable(run.err));
            QFile f(out);
            QByteArray b = f.open(QIODevice::ReadOnly) ? f.readAll() : QByteArray();
            f.close();
            QFile::remove(out);
            return b;
        };
        const QString plain = scene("plain", good, ""), single = scene("single", good, ", \"tracer\": \"single\"");
        const QByteArray flagSingle = bytes({"render", plain, "--volume-tracer", "single", "--no-cache", "--quiet", "-o", out});
        const QByteArray keySingle = bytes({"render", single, "--no-cache", "--quiet", "-o", out});
        const QByteArray lb = bytes({"render", single, "--volume-tracer", "lb", "--no-cache", "--quiet", "-o", out});
        const QByteArray keyLb = bytes({"render", plain, "--no-cache", "--quiet", "-o", out});
        QVERIFY(!flagSingle.isEmpty() && !lb.isEmpty());
        QCOMPARE(flagSingle, keySingle);
        QCOMPARE(lb, keyLb);
        QVERIFY(flagSingle != lb);
        r = runSylva({"render", plain, "--volume-tracer", "fog", "--no-cache", "--quiet", "-o", out});
        QCOMPARE(r.code, 2);
        QVERIFY(r.err.contains("lb, single or combined"));
    }
};

QTEST_GUILESS_MAIN(TestVolumeSources)
#include "tst_volume_sources.moc"
