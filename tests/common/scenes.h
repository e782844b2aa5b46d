// The small scenes, plants and meshes the render tests share, each small enough for CI.
#pragma once

#include <QTest>

#include <vector>

#include "core/lb/lb_params.h"
#include "core/render/render_scene.h"
#include "core/scene/scene.h"
#include "pipeline/grow/tree_grower.h"
#include "pipeline/scene/scene_file.h"
#include "tests/common/files.h"

namespace sylva::test {

// Three grown trees of two species on the ground and a close camera.
inline Scene smallForest()
{
    Scene s;
    s.species.resize(2);
    s.species[0].name = "broadleaf";
    s.species[0].grow = GrowSpec{"broadleaf", 3, 6000, 8.0f};
    s.species[1].name = "birch";
    s.species[1].grow = GrowSpec{"birch", 4, 5000, 9.0f};
    for (SpeciesDesc& sp : s.species) {
        sp.lighting = lb::paramsFromPreset(*lb::findPreset("leaf"));
        sp.grid = 24;
    }
    InstanceDesc a, b, c;
    a.position = {-3.0, 0.0, 4.0};
    b.species = 1;
    b.position = {3.0, 0.0, 6.0};
    b.rotationDeg = {0.0f, 40.0f, 0.0f};
    c.position = {0.0, 0.0, 12.0};
    c.scale = 1.2f;
    c.rotationDeg = {0.0f, 200.0f, 0.0f};
    s.instances = {a, b, c};
    s.camera.position = {0.0, 3.0, -9.0};
    s.camera.target = {0.0, 4.0, 6.0};
    s.sun.direction = sunDirection(40.0, 120.0);
    s.render.width = 120;
    s.render.height = 80;
    s.render.spp = 4;
    return s;
}

// One small grown shrub (1,500 triangles, seed 3) as the assets of a one-species scene, unlit (the
// indirect light as in open sky): the tests that need a plant but no LB solve.
inline std::vector<SpeciesAssets> oneShrub()
{
    GrowOptions a;
    a.species = TreeSpecies::Shrub;
    a.targetTriangles = 1500;
    a.seed = 3;
    std::vector<SpeciesAssets> assets(1);
    assets[0].mesh = growTree(a).mesh;
    return assets;
}

// A scene of the ground alone as the renderer sees it with oneShrub's assets: species "shrub" placed once, 1000 m
// under the ground plane (never seen, never in a shadow ray's way: those all go up). The caller sets the rest.
inline Scene shrubUnderGround()
{
    Scene s;
    s.species.resize(1);
    s.species[0].name = "shrub";
    InstanceDesc d;
    d.position = {0.0, -1000.0, 0.0};
    s.instances.push_back(d);
    return s;
}

// A grown shrub species (the leaf preset's optics) lit on a grid of `grid` nodes: small and quick to grow.
inline SpeciesDesc shrubSpecies(int grid, uint64_t seed = 7, uint64_t triangles = 3000, float height = 0.0f)
{
    SpeciesDesc sp;
    sp.name = "shrub";
    sp.grow = GrowSpec{"shrub", seed, triangles, height};
    sp.lighting = lb::paramsFromPreset(*lb::findPreset("leaf"));
    sp.grid = grid;
    return sp;
}

// Nine instances of species 0 on a 3 x 3 grid `spacing` apart (x from -spacing, z from 2), each turned 40
// degrees further: a patch of plants to see from above.
inline std::vector<InstanceDesc> patchOfNine(double spacing)
{
    std::vector<InstanceDesc> patch;
    for (int k = 0; k < 9; ++k) {
        InstanceDesc d;
        d.position = {double(k % 3) * spacing - spacing, 0.0, double(k / 3) * spacing + 2.0};
        d.rotationDeg = {0.0f, float(k) * 40.0f, 0.0f};
        patch.push_back(d);
    }
    return patch;
}

// The GPU tests' small scene: two grown shrubs (about 4k triangles each) on the ground, leaf preset at
// 16 nodes, 96x64 pixels: seconds to grow, light and trace on the CPU, which is the oracle.
inline Scene twoShrubs()
{
    Scene s;
    s.species = {shrubSpecies(16, 2, 4000, 2.0f)};
    InstanceDesc a, b;
    b.position = {1.5, 0.0, 1.0};
    b.rotationDeg = {0.0f, 70.0f, 0.0f};
    s.instances = {a, b};
    s.camera.position = {0.0, 1.5, -5.0};
    s.camera.target = {0.5, 0.8, 0.5};
    s.render.width = 96;
    s.render.height = 64;
    return s;
}

// A leaf quad at z = 0 (x, y in [-1, 1], uv = (x + 1) / 2, (y + 1) / 2) whose cut-out's left half is
// transparent, and a wood wall quad at z = 2 behind it: rays through the left half hit the wall.
inline SpeciesAssets cardAndWall()
{
    SpeciesAssets a;
    TriangleMesh& m = a.mesh;
    const glm::vec3 q[4] = {{-1, -1, 0}, {1, -1, 0}, {1, 1, 0}, {-1, 1, 0}};
    for (int i = 0; i < 4; ++i) {
        m.positions.push_back(q[i]);
        m.uvs.emplace_back((q[i].x + 1.0f) / 2.0f, (q[i].y + 1.0f) / 2.0f);
    }
    for (int i = 0; i < 4; ++i) {
        m.positions.push_back(q[i] + glm::vec3(0, 0, 2));
        m.uvs.emplace_back(0.0f, 0.0f);
    }
    m.triangles = {{0, 1, 2}, {0, 2, 3}, {4, 5, 6}, {4, 6, 7}};
    m.triangleMaterial = {0, 0, 1, 1};
    m.materials.resize(2);
    m.materials[0].isLeaf = true;
    ImageRgba cut(8, 8, glm::vec4(1.0f));
    for (int y = 0; y < 8; ++y)
        for (int x = 0; x < 4; ++x) cut.at(x, y)[3] = 0.0f;   // left half transparent
    a.cutout = {cut, ImageRgba()};
    return a;
}

// The message readSceneFile refuses the scene file at `path` with, or kNoError.
inline std::string sceneFileError(const std::string& path) { return errorOf([&] { readSceneFile(path); }); }

// The rows of a test function run once per acceleration structure: column "accel" (an AccelKind).
inline void accelRows()
{
    QTest::addColumn<int>("accel");
    QTest::newRow("bvh") << int(AccelKind::Bvh);
    QTest::newRow("kdtree") << int(AccelKind::KdTree);
}

} // namespace sylva::test
