// placeViewFrame: the top level of buildRenderScene (instances, instance BVH, environment) redone alone.
#include "pipeline/render/view_frame.h"

#include "core/base/error.h"

namespace sylva {

ViewFrame buildViewFrame(const Scene& scene, const std::vector<SpeciesAssets>& assets, const glm::vec3& sunRadiance)
{
    Scene s = scene;
    s.render.accel = AccelKind::Bvh;   // the fast path re-places the BVH top level only
    ViewFrame f;
    f.rs = buildRenderScene(s, assets, sunRadiance);
    f.speciesBounds.reserve(assets.size());
    for (const SpeciesAssets& a : assets) f.speciesBounds.push_back(meshBounds(a.mesh));
    return f;
}

void placeViewFrame(ViewFrame& frame, const Scene& scene, const glm::vec3& sunRadiance, int width, int height, int spp)
{
    RenderScene& rs = frame.rs;
    const size_t ns = frame.speciesBounds.size();
    if (scene.instances.empty()) throw Error("render: the scene has no instances");
    const glm::dvec3 origin = scene.camera.position;
    rs.instances.clear();
    rs.instances.reserve(scene.instances.size());
    std::vector<Bounds3> boxes(scene.instances.size());
    for (size_t i = 0; i < scene.instances.size(); ++i) {
        const InstanceDesc& d = scene.instances[i];
        if (d.species >= ns) throw Error("render: instance " + std::to_string(i) + " names a missing species");
        const InstanceRecord rec = makeInstance(d, origin);
        rs.instances.push_back(rec);
        // The record maps world -> species as M = R^T / s; its inverse s R = s^2 M^T.
        glm::dmat3 m;
        for (int r = 0; r < 3; ++r)
            for (int c = 0; c < 3; ++c) m[c][r] = double(rec.row[r][c]);
        const glm::dmat3 toWorld = glm::transpose(m) * (double(d.scale) * double(d.scale));
        const Bounds3& lb = frame.speciesBounds[d.species];
        for (int c = 0; c < 8; ++c) {
            const glm::dvec3 corner((c & 1) ? lb.hi.x : lb.lo.x, (c & 2) ? lb.hi.y : lb.lo.y, (c & 4) ? lb.hi.z : lb.lo.z);
            boxes[i].extend(glm::vec3(toWorld * corner + (d.position - origin)));
        }
        // A looser pad than buildRenderScene's: this inverse is rebuilt from float rows.
        const glm::vec3 pad = 1e-4f * (glm::abs(boxes[i].lo) + glm::abs(boxes[i].hi)) + 1e-5f;
        boxes[i].lo -= pad;
        boxes[i].hi += pad;
    }
    BvhBuildSettings ts;
    ts.maxLeafSize = 2;
    ts.wide = !rs.tlasWideNodes.empty();   // the host's 8-wide copy, rebuilt with the 4-wide one
    Bvh tlas = buildBvh(boxes, ts);
    rs.tlasNodes = std::move(tlas.nodes);
    rs.tlasWideNodes = std::move(tlas.wideNodes);
    rs.tlasOrder = std::move(tlas.primOrder);

    RenderView& b = rs.base;
    b.groundEnabled = scene.ground.enabled;
    b.groundY = float(scene.ground.height - origin.y);
    b.groundColor = scene.ground.color;
    if (!(glm::length(scene.sun.direction) > 0.0f)) throw Error("sun: direction must not be zero");
    b.sunDir = glm::normalize(scene.sun.direction);
    b.sunRadiance = sunRadiance;
    b.sky = scene.sky;
    b.camera = makeCamera(scene.camera, width, height);
    b.width = width;
    b.height = height;
    b.spp = spp;
    b.accel = AccelKind::Bvh;
    b.shadows = scene.render.shadows;
    b.indirectScale = scene.render.indirectScale;
}

} // namespace sylva
