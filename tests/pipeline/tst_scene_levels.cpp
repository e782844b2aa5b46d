// The scene model's levels: nested instance groups against their flattened two-level copy (closest and
// any hit, BVH and kd-tree, camera and random rays), the nested scene far from the origin, the group
// checks, and the level statistics.
#include <QTest>

#include <cmath>
#include <map>
#include <random>

#include "core/base/error.h"
#include "core/render/render_cpu.h"
#include "core/render/render_scene.h"
#include "core/render/shade.h"
#include "pipeline/render/frame_build.h"
#include "pipeline/grow/tree_grower.h"

using namespace sylva;

namespace {

// R = Rz * Ry * Rx of Euler angles in degrees, written out here (not the renderer's copy).
glm::dmat3 eulerMatrix(const glm::dvec3& deg)
{
    const glm::dvec3 r = deg * (M_PI / 180.0);
    const glm::dmat3 rx(1, 0, 0, 0, std::cos(r.x), std::sin(r.x), 0, -std::sin(r.x), std::cos(r.x));
    const glm::dmat3 ry(std::cos(r.y), 0, -std::sin(r.y), 0, 1, 0, std::sin(r.y), 0, std::cos(r.y));
    const glm::dmat3 rz(std::cos(r.z), std::sin(r.z), 0, -std::sin(r.z), std::cos(r.z), 0, 0, 0, 1);
    return rz * ry * rx;
}

// The Euler angles (degrees) of a rotation R = Rz * Ry * Rx (glm: m[col][row]).
glm::dvec3 eulerAngles(const glm::dmat3& m)
{
    const double sy = std::clamp(-m[0][2], -1.0, 1.0);
    const double x = std::atan2(m[1][2], m[2][2]), y = std::asin(sy), z = std::atan2(m[0][1], m[0][0]);
    return glm::dvec3(x, y, z) * (180.0 / M_PI);
}

// A placement in double: world = p + s R local.
struct Placement {
    glm::dvec3 p{0.0};
    glm::dmat3 r{1.0};
    double s = 1.0;
};

Placement placementOf(const InstanceDesc& d) { return {d.position, eulerMatrix(glm::dvec3(d.rotationDeg)), double(d.scale)}; }

Placement compose(const Placement& parent, const Placement& child)
{
    return {parent.p + parent.s * (parent.r * child.p), parent.r * child.r, parent.s * child.s};
}

InstanceDesc descOf(const Placement& pl, uint32_t species)
{
    InstanceDesc d;
    d.species = species;
    d.position = pl.p;
    d.rotationDeg = glm::vec3(eulerAngles(pl.r));
    d.scale = float(pl.s);
    return d;
}

InstanceDesc randomInstance(std::mt19937& rng, double spread, bool tilt)
{
    std::uniform_real_distribution<double> u(0.0, 1.0);
    InstanceDesc d;
    d.position = {(u(rng) - 0.5) * spread, (u(rng) - 0.5) * 0.2 * spread, (u(rng) - 0.5) * spread};
    d.rotationDeg = glm::vec3(float(tilt ? u(rng) * 30.0 - 15.0 : 0.0), float(u(rng) * 360.0), float(tilt ? u(rng) * 30.0 - 15.0 : 0.0));
    d.scale = float(0.6 + 0.8 * u(rng));
    return d;
}

// A nested scene of `levels` levels (the top level plus levels - 1 nested groups) over two species,
// with a few plain instances at the top too, and its flattened two-level copy: every leaf instance
// placed directly, in the order `flatOf` gives for each instance path.
struct NestedScenes {
    Scene nested, flat;
    std::map<std::vector<uint32_t>, uint32_t> flatOf;   // path (top index, then the index within each group) -> flat instance
};

NestedScenes makeNested(int levels, uint32_t seed)
{
    std::mt19937 rng(seed);
    NestedScenes out;
    Scene& s = out.nested;
    s.species.resize(2);
    s.species[0].name = "shrub";
    s.species[1].name = "birch";
    // Group 0: plants; group k: instances of group k - 1 (and, for variety, one plant).
    const int groups = levels - 1;
    for (int g = 0; g < groups; ++g) {
        GroupDesc gd;
        gd.name = std::to_string(g);
        gd.name.insert(gd.name.begin(), 'g');   // not "g" + to_string: GCC 12 warns falsely (-Wrestrict)
        const double spread = 6.0 * std::pow(2.5, g);
        const int n = g == 0 ? 4 : 3;
        for (int i = 0; i < n; ++i) {
            InstanceDesc d = randomInstance(rng, spread, true);
            if (g == 0) d.species = uint32_t(i % 2);
            else d.group = uint32_t(g - 1);
            gd.instances.push_back(d);
        }
        if (g > 0) {
            InstanceDesc plant = randomInstance(rng, spread, false);
            plant.species = 1;
            gd.instances.push_back(plant);
        }
        s.groups.push_back(gd);
    }
    for (int i = 0; i < 3; ++i) {
        InstanceDesc d = randomInstance(rng, 60.0, true);
        d.position.z += 40.0;
        d.group = uint32_t(groups - 1);
        s.instances.push_back(d);
    }
    for (int i = 0; i < 2; ++i) {
        InstanceDesc d = randomInstance(rng, 30.0, true);
        d.position.z += 30.0;
        d.species = uint32_t(i);
        s.instances.push_back(d);
    }
    s.ground.enabled = false;
    s.render.width = 250;
    s.render.height = 200;
    s.camera.position = {0.0, 8.0, -25.0};
    s.camera.target = {0.0, 0.0, 40.0};

    Scene& f = out.flat;
    f = s;
    f.groups.clear();
    f.instances.clear();
    auto walk = [&](auto&& self, const InstanceDesc& d, const Placement& parent, std::vector<uint32_t> path) -> void {
        const Placement pl = compose(parent, placementOf(d));
        if (d.group == kNoGroup) {
            out.flatOf[path] = uint32_t(f.instances.size());
            f.instances.push_back(descOf(pl, d.species));
            return;
        }
        const GroupDesc& gd = s.groups[d.group];
        for (uint32_t i = 0; i < gd.instances.size(); ++i) {
            std::vector<uint32_t> p = path;
            p.push_back(i);
            self(self, gd.instances[i], pl, p);
        }
    };
    for (uint32_t i = 0; i < s.instances.size(); ++i) walk(walk, s.instances[i], Placement{}, {i});
    return out;
}

// The path of a hit as (top index, index within each group) from the nested scene's arrays.
std::vector<uint32_t> hitPath(const RenderScene& rs, const Hit& h)
{
    std::vector<uint32_t> path{h.inst};
    for (uint32_t k = 0; k < h.depth; ++k) {
        // The group holding groupInstances[nested[k]]: the one whose slots hold that index.
        for (const GeometryRecord& g : rs.geometries) {
            if (g.kind != GeometryKind::Group) continue;
            uint32_t first = ~0u;
            bool holds = false;
            for (uint32_t s = 0; s < g.primCount; ++s) {
                const uint32_t idx = rs.groupOrder[g.primOffset + s];
                first = std::min(first, idx);
                holds = holds || idx == h.nested[k];
            }
            if (holds) {
                path.push_back(h.nested[k] - first);
                break;
            }
        }
    }
    return path;
}

std::vector<SpeciesAssets> twoSpecies()
{
    GrowOptions a, b;
    a.species = TreeSpecies::Shrub;
    a.targetTriangles = 1500;
    a.seed = 3;
    b.species = TreeSpecies::Birch;
    b.targetTriangles = 1500;
    b.seed = 4;
    std::vector<SpeciesAssets> assets(2);
    assets[0].mesh = growTree(a).mesh;
    assets[1].mesh = growTree(b).mesh;
    return assets;
}

// The instanced-vs-flattened tolerance of tst_render (1e-3 relative), with a 1 mm floor for rays that start
// next to a triangle: both copies round their transforms in float (the nested one through up to four maps,
// the flat one through Euler angles stored in float), a few micrometres at these distances, which a grazing
// ray turns into a larger difference along itself.
bool sameT(float a, float b) { return std::fabs(a - b) <= 1e-3f * std::max(1.0f, std::max(a, b)); }

} // namespace

class TestSceneLevels : public QObject {
    Q_OBJECT

    std::vector<SpeciesAssets> m_assets;

private Q_SLOTS:
    void initTestCase() { m_assets = twoSpecies(); }

    void nestedGroupsMatchFlattenedCopy_data()
    {
        QTest::addColumn<int>("levels");
        QTest::addColumn<int>("accel");
        for (int levels : {3, 4})
            for (AccelKind a : {AccelKind::Bvh, AccelKind::KdTree})
                QTest::newRow(qPrintable(QString("%1 levels, %2").arg(levels).arg(accelName(a)))) << levels << int(a);
    }

    // Groups of groups of instances give the same hits, ray for ray, as every leaf instance placed at the
    // top: the same instance (by path), the same triangle, t within float rounding of the longer chain of
    // transforms; any-hit agrees with closest-hit. 50k camera rays and 50k random rays.
    void nestedGroupsMatchFlattenedCopy()
    {
        QFETCH(int, levels);
        QFETCH(int, accel);
        NestedScenes ns = makeNested(levels, 11u + uint32_t(levels));
        ns.nested.render.accel = ns.flat.render.accel = AccelKind(accel);
        const RenderScene nested = buildRenderScene(ns.nested, m_assets, glm::vec3(1.0f));
        const RenderScene flat = buildRenderScene(ns.flat, m_assets, glm::vec3(1.0f));
        QCOMPARE(nested.stats().groups, size_t(levels - 1));
        QCOMPARE(flat.instances.size(), ns.flatOf.size());
        QVERIFY(ns.flatOf.size() > size_t(levels == 3 ? 30 : 100));
        // The flattened placements are the nested ones: the Euler angles round-trip.
        for (const InstanceDesc& d : ns.flat.instances) {
            const glm::dmat3 back = eulerMatrix(glm::dvec3(d.rotationDeg));
            const glm::dmat3 again = eulerMatrix(eulerAngles(back));
            for (int c = 0; c < 3; ++c) QVERIFY(glm::length(back[c] - again[c]) < 1e-6);
        }
        QVERIFY(std::fabs(nested.stats().instancedTriangles - flat.stats().instancedTriangles) < 0.5);
        const RenderView vn = nested.view(), vf = flat.view();

        std::vector<Ray> rays;
        for (int y = 0; y < ns.nested.render.height; ++y)
            for (int x = 0; x < ns.nested.render.width; ++x) rays.push_back(cameraRay(vn, float(x) + 0.5f, float(y) + 0.5f));
        Bounds3 box;
        for (size_t i = 0; i < vf.instanceCount; ++i) box.extend(glm::vec3(ns.flat.instances[i].position - ns.flat.camera.position));
        std::mt19937 rng(7);
        std::uniform_real_distribution<float> u(0.0f, 1.0f);
        const glm::vec3 e = box.extent();
        while (rays.size() < 100000) {
            Ray r;
            r.org = box.lo - 0.2f * e + 1.4f * e * glm::vec3(u(rng), u(rng), u(rng));
            const glm::vec3 target = box.lo + e * glm::vec3(u(rng), u(rng), u(rng));
            r.dir = glm::normalize(target - r.org + glm::vec3(u(rng) - 0.5f, u(rng) - 0.5f, u(rng) - 0.5f));
            r.tmin = 0.0f;
            r.tmax = 1e30f;
            rays.push_back(r);
        }
        int hits = 0, deep = 0, hitMismatch = 0, pathMismatch = 0, notGrazing = 0, anyMismatch = 0, tMismatch = 0;
        for (const Ray& r : rays) {
            Hit hn{}, hf{};
            const bool bn = traceScene<false>(vn, r, hn), bf = traceScene<false>(vf, r, hf);
            Hit an{}, af{};
            if (traceScene<true>(vn, r, an) != bn || traceScene<true>(vf, r, af) != bf) ++anyMismatch;
            if (bn != bf) {
                ++hitMismatch;
                continue;
            }
            if (!bn) continue;
            ++hits;
            if (hn.depth == uint32_t(levels - 1)) ++deep;
            const auto it = ns.flatOf.find(hitPath(nested, hn));
            if (it == ns.flatOf.end() || it->second != hf.inst || hn.prim != hf.prim) {
                // A ray grazing the edge of the nearer of the two triangles: one copy rounds it onto the
                // triangle, the other past it to what lies behind. Anything else is a real difference.
                const Hit& nearer = hn.t < hf.t ? hn : hf;
                const float edge = std::min(std::min(nearer.u, nearer.v), 1.0f - nearer.u - nearer.v);
                if (edge < 1e-3f) ++pathMismatch;
                else ++notGrazing;
            } else if (!sameT(hn.t, hf.t)) {
                ++tMismatch;
            }
            if (it == ns.flatOf.end() || it->second != hf.inst || hn.prim != hf.prim || !sameT(hn.t, hf.t)) {
                if (qEnvironmentVariableIsSet("SYLVA_TEST_VERBOSE"))
                    qInfo("inst %u vs %u, prim %u vs %u, t %.9g vs %.9g (rel %.3g)", it == ns.flatOf.end() ? ~0u : it->second, hf.inst,
                          hn.prim, hf.prim, hn.t, hf.t, std::fabs(hn.t - hf.t) / hf.t);
            }
        }
        qInfo("%d rays: %d hits (%d at the deepest level); %d hit/miss differ, %d instance or triangle differ, %d t differ, "
              "%d any-hit differ",
              int(rays.size()), hits, deep, hitMismatch, pathMismatch, tMismatch, anyMismatch);
        QVERIFY(hits > 20000);
        QVERIFY(deep > hits / 4);
        QCOMPARE(anyMismatch, 0);
        // Only rays grazing a triangle edge may round to the other side after a different chain of float
        // transforms: at most 1 in 10,000.
        QVERIFY2(hitMismatch <= int(rays.size()) / 10000, qPrintable(QString("%1 hit/miss differ").arg(hitMismatch)));
        QVERIFY2(pathMismatch <= hits / 10000, qPrintable(QString("%1 hits differ in instance or triangle").arg(pathMismatch)));
        QCOMPARE(notGrazing, 0);
        QCOMPARE(tMismatch, 0);
    }

    // The same nested scene 1e7 m from the origin (top level and camera moved; group frames are local)
    // renders the picture it renders at the origin.
    void nestedSceneFarFromOrigin()
    {
        NestedScenes ns = makeNested(4, 5u);
        Scene& s = ns.nested;
        s.ground.enabled = true;
        s.ground.height = -3.0;
        s.render.width = 120;
        s.render.height = 90;
        const auto ref = composeMode(renderFilm(buildRenderScene(s, m_assets, glm::vec3(1.0f)).view()), RenderMode::Full, s.sky);
        Scene far = s;
        const glm::dvec3 d(1e7, 0.0, -1e7);
        for (InstanceDesc& i : far.instances) i.position += d;
        far.camera.position += d;
        far.camera.target += d;
        const auto img = composeMode(renderFilm(buildRenderScene(far, m_assets, glm::vec3(1.0f)).view()), RenderMode::Full, far.sky);
        int differ = 0, covered = 0;
        for (size_t i = 0; i < img.size(); ++i) {
            if (glm::any(glm::greaterThan(glm::abs(img[i] - ref[i]), glm::vec3(0.02f)))) ++differ;
            if (glm::any(glm::notEqual(ref[i], s.sky))) ++covered;
        }
        qInfo("%d of %zu pixels differ by more than 0.02 (%d not sky)", differ, img.size(), covered);
        QVERIFY(covered > int(img.size()) / 10);
        QVERIFY2(differ <= int(img.size()) / 500, qPrintable(QString("%1 pixels differ").arg(differ)));
    }

    // Groups that contain themselves, nest deeper than the traversal's levels, are empty or are missing are
    // refused with a message naming the group.
    void badGroupsAreRefused()
    {
        NestedScenes ns = makeNested(4, 9u);
        auto message = [&](const Scene& s) -> std::string {
            try {
                buildRenderScene(s, m_assets, glm::vec3(1.0f));
            } catch (const Error& e) {
                return e.what();
            }
            return {};
        };
        Scene cycle = ns.nested;
        cycle.groups[0].instances[0].group = 2;   // g2 places g1 places g0 places g2
        QVERIFY2(message(cycle).find("group 'g0' contains itself") != std::string::npos, message(cycle).c_str());
        Scene deep = ns.nested;
        GroupDesc g3;
        g3.name = "g3";
        InstanceDesc of2;
        of2.group = 2;
        g3.instances.push_back(of2);
        deep.groups.push_back(g3);
        deep.instances[0].group = 3;
        QVERIFY2(message(deep).find("group 'g3' nests 4 groups deep") != std::string::npos, message(deep).c_str());
        Scene empty = ns.nested;
        empty.groups[1].instances.clear();
        QVERIFY2(message(empty).find("group 'g1' has no instances") != std::string::npos, message(empty).c_str());
        Scene missing = ns.nested;
        missing.instances[1].group = 7;
        QVERIFY2(message(missing).find("instance 1 names a missing group") != std::string::npos, message(missing).c_str());
        Scene missingInner = ns.nested;
        missingInner.groups[0].instances[2].species = 9;
        QVERIFY2(message(missingInner).find("instance 2 of group 'g0' names a missing species") != std::string::npos,
                 message(missingInner).c_str());
    }
};

QTEST_GUILESS_MAIN(TestSceneLevels)
#include "tst_scene_levels.moc"
