// The small forest the render tests share: three grown trees of two species on the ground and a
// close camera, small enough for CI.
#pragma once

#include <vector>

#include "core/lb/lb_params.h"
#include "core/render/render_scene.h"
#include "core/scene/scene.h"
#include "pipeline/grow/tree_grower.h"

namespace sylva::test {

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

} // namespace sylva::test
