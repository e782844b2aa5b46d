// The group geometry kind's builder: each instance group's instances in its own frame under a BVH, after
// the groups it places.
#include "core/render/scene_build.h"

namespace sylva::scene_build {

// The parent-frame box of an instance of a geometry whose own-frame bounds are `b`, from the instance's
// description in double, grown by a relative epsilon so float rounding of the transform never clips geometry.
Bounds3 instanceBox(const InstanceDesc& d, const Bounds3& b, const glm::dvec3& frameOrigin)
{
    Bounds3 box;
    const glm::dmat3 r = rotationDeg(d.rotationDeg) * double(d.scale);
    for (int c = 0; c < 8; ++c) {
        const glm::dvec3 corner((c & 1) ? b.hi.x : b.lo.x, (c & 2) ? b.hi.y : b.lo.y, (c & 4) ? b.hi.z : b.lo.z);
        box.extend(glm::vec3(r * corner + (d.position - frameOrigin)));
    }
    const glm::vec3 pad = 1e-5f * (glm::abs(box.lo) + glm::abs(box.hi)) + 1e-6f;
    box.lo -= pad;
    box.hi += pad;
    return box;
}

void buildGroupGeometry(RenderScene& rs, const Scene& scene, const std::vector<uint32_t>& groupOrder)
{
    // Instance groups, each after the groups it places: its instances in its own frame under a BVH.
    const size_t meshRecords = rs.geometries.size();
    rs.groupGeometry.assign(scene.groups.size(), kNoHit);
    for (size_t g = 0; g < scene.groups.size(); ++g) {
        rs.groupGeometry[g] = uint32_t(meshRecords + g);
        rs.geometries.push_back(GeometryRecord{});
        rs.geometryBounds.emplace_back();
        rs.geometryTriangles.push_back(0.0);
    }
    for (uint32_t g : groupOrder) {
        const GroupDesc& gd = scene.groups[g];
        const uint32_t record = rs.groupGeometry[g];
        const uint32_t first = uint32_t(rs.groupInstances.size());
        std::vector<Bounds3> boxes(gd.instances.size());
        double triangles = 0.0;
        for (size_t i = 0; i < gd.instances.size(); ++i) {
            const InstanceDesc& d = gd.instances[i];
            InstanceRecord rec = makeInstance(d, glm::dvec3(0.0));
            rec.geometry = d.group != kNoGroup ? rs.groupGeometry[d.group] : uint32_t(d.species);
            boxes[i] = instanceBox(d, rs.geometryBounds[rec.geometry], glm::dvec3(0.0));
            triangles += rs.geometryTriangles[rec.geometry];
            rs.groupInstances.push_back(rec);
        }
        BvhBuildSettings gs;
        gs.maxLeafSize = 2;
        gs.wide = true;   // the host's 8-wide copy
        const Bvh bvh = buildBvh(boxes, gs);
        GeometryRecord& gr = rs.geometries[record];
        gr.kind = GeometryKind::Group;
        gr.species = kNoHit;
        gr.nodeOffset = uint32_t(rs.groupNodes.size());
        gr.wideNodeOffset = uint32_t(rs.groupWideNodes.size());
        gr.primOffset = uint32_t(rs.groupOrder.size());
        gr.primCount = uint32_t(gd.instances.size());
        gr.lo = bvh.bounds.lo;
        gr.hi = bvh.bounds.hi;
        rs.groupNodes.insert(rs.groupNodes.end(), bvh.nodes.begin(), bvh.nodes.end());
        rs.groupWideNodes.insert(rs.groupWideNodes.end(), bvh.wideNodes.begin(), bvh.wideNodes.end());
        for (uint32_t slot : bvh.primOrder) rs.groupOrder.push_back(first + slot);
        rs.geometryBounds[record] = bvh.bounds;
        rs.geometryTriangles[record] = triangles;
    }
    rs.buildStats.groups = scene.groups.size();
    rs.buildStats.groupInstances = rs.groupInstances.size();
}

} // namespace sylva::scene_build
