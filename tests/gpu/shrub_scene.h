// The GPU tests' small scene: two grown shrubs (about 4k triangles each) on the ground, leaf preset at
// 16 nodes, 96x64 pixels: seconds to grow, light and trace on the CPU, which is the oracle.
#pragma once

#include "core/lb/lb_params.h"
#include "core/scene/scene.h"

namespace sylva::test {

inline Scene twoShrubs()
{
    Scene s;
    s.species.resize(1);
    s.species[0].name = "shrub";
    s.species[0].grow = GrowSpec{"shrub", 2, 4000, 2.0f};
    s.species[0].lighting = lb::paramsFromPreset(*lb::findPreset("leaf"));
    s.species[0].grid = 16;
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

} // namespace sylva::test
