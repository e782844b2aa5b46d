// Flattens species, instances, textures and lighting grids into the RenderView arrays; builds the BVHs.
#include "core/render/render_scene.h"

#include <array>
#include <algorithm>
#include <cmath>

#include <tbb/parallel_for.h>

#include "core/base/error.h"
#include "core/render/prune.h"
#include "core/render/tonemap.h"

namespace sylva {
namespace {

glm::dmat3 rotationDeg(const glm::vec3& deg)
{
    const glm::dvec3 r = glm::dvec3(deg) * (M_PI / 180.0);
    const double cx = std::cos(r.x), sx = std::sin(r.x), cy = std::cos(r.y), sy = std::sin(r.y);
    const double cz = std::cos(r.z), sz = std::sin(r.z);
    // glm matrices are column-major: m[col][row].
    const glm::dmat3 rx(1, 0, 0, 0, cx, sx, 0, -sx, cx);
    const glm::dmat3 ry(cy, 0, -sy, 0, 1, 0, sy, 0, cy);
    const glm::dmat3 rz(cz, sz, 0, -sz, cz, 0, 0, 0, 1);
    return rz * ry * rx;
}

void addCutout(const ImageRgba& img, RenderScene& rs, MaterialRecord& m)
{
    if (img.empty()) return;
    bool anyClear = false;
    for (size_t p = 0; p < size_t(img.width) * size_t(img.height) && !anyClear; ++p) anyClear = img.pixels[p * 4 + 3] < 0.5f;
    if (!anyClear) return;
    AlphaMaskRecord rec{img.width, img.height, uint32_t(rs.alphaBits.size()), 0};
    const size_t bits = size_t(img.width) * size_t(img.height);
    rs.alphaBits.resize(rs.alphaBits.size() + (bits + 31) / 32, 0u);
    for (size_t b = 0; b < bits; ++b)
        if (img.pixels[b * 4 + 3] >= 0.5f) rs.alphaBits[rec.offset + b / 32] |= 1u << (b % 32);
    m.alphaMask = int32_t(rs.alphaMasks.size());
    rs.alphaMasks.push_back(rec);
}

void addTexture(const ImageRgba& img, RenderScene& rs, MaterialRecord& m)
{
    if (img.empty()) return;
    TextureRecord rec{img.width, img.height, uint32_t(rs.texels.size()), 0};
    const size_t n = size_t(img.width) * size_t(img.height);
    rs.texels.reserve(rs.texels.size() + n);
    for (size_t p = 0; p < n; ++p) {
        const float* px = &img.pixels[p * 4];
        rs.texels.emplace_back(srgbDecode(px[0]), srgbDecode(px[1]), srgbDecode(px[2]), px[3]);
    }
    m.texture = int32_t(rs.textures.size());
    rs.textures.push_back(rec);
}

} // namespace

CameraRecord makeCamera(const CameraDesc& c, int width, int height)
{
    const glm::dvec3 fwd = c.target - c.position;
    if (!(glm::length(fwd) > 0.0)) throw Error("camera: position and target coincide");
    CameraRecord r;
    r.forward = glm::vec3(glm::normalize(fwd));
    const glm::vec3 right = glm::cross(r.forward, c.up);
    if (!(glm::length(right) > 1e-6f)) throw Error("camera: up is parallel to the view direction");
    r.right = glm::normalize(right);
    r.up = glm::cross(r.right, r.forward);
    r.tanHalfY = std::tan(double(c.fovY) * M_PI / 360.0);
    r.tanHalfX = r.tanHalfY * float(width) / float(height);
    return r;
}

InstanceRecord makeInstance(const InstanceDesc& inst, const glm::dvec3& frameOrigin)
{
    // world = R (s x_local) + p  =>  x_local = R^T (world - p) / s, with world = rel + frameOrigin.
    const glm::dmat3 rt = glm::transpose(rotationDeg(inst.rotationDeg)) * (1.0 / double(inst.scale));
    const glm::dvec3 t = -(rt * (inst.position - frameOrigin));
    InstanceRecord r{};
    for (int i = 0; i < 3; ++i) r.row[i] = glm::vec4(float(rt[0][i]), float(rt[1][i]), float(rt[2][i]), float(t[i]));
    r.species = inst.species;
    r.scale = inst.scale;
    r.geometry = inst.species;   // the full species; buildRenderScene picks a pruned level where it prunes
    return r;
}

RenderView RenderScene::view() const
{
    RenderView v = base;
    v.tlasNodes = tlasNodes.data();
    v.tlasWideNodes = tlasWideNodes.empty() ? nullptr : tlasWideNodes.data();
    v.tlasOrder = tlasOrder.data();
    v.instances = instances.data();
    v.instanceCount = uint32_t(instances.size());
    v.species = species.data();
    v.blasNodes = blasNodes.data();
    v.blasWideNodes = blasWideNodes.empty() ? nullptr : blasWideNodes.data();
    v.tris = tris.data();
    v.blocks = blocks.data();
    v.kdTlasNodes = kdTlasNodes.empty() ? nullptr : kdTlasNodes.data();
    v.kdTlasRefs = kdTlasRefs.data();
    v.kdSpecies = kdSpecies.data();
    v.kdBlasNodes = kdBlasNodes.data();
    v.kdBlasRefs = kdBlasRefs.data();
    v.triVerts = triVerts.data();
    v.triMaterial = triMaterial.data();
    v.normals = normals.data();
    v.uvs = uvs.data();
    v.materials = materials.data();
    v.textures = textures.data();
    v.texels = texels.data();
    v.alphaMasks = alphaMasks.data();
    v.alphaBits = alphaBits.data();
    v.lighting = lighting.data();
    return v;
}

RenderScene buildRenderScene(const Scene& scene, const std::vector<SpeciesAssets>& assets, const glm::vec3& sunRadiance,
                             Progress* progress)
{
    if (assets.size() != scene.species.size()) throw Error("render: one set of assets per species is required");
    if (scene.instances.empty()) throw Error("render: the scene has no instances");
    RenderScene rs;
    const size_t ns = assets.size(), ni = scene.instances.size();
    const glm::dvec3 origin = scene.camera.position;
    for (size_t s = 0; s < ns; ++s)
        if (assets[s].mesh.triangles.empty()) throw Error("render: species '" + scene.species[s].name + "' has no triangles");
    for (size_t i = 0; i < ni; ++i)
        if (scene.instances[i].species >= ns) throw Error("render: instance " + std::to_string(i) + " names a missing species");

    // Stochastic pruning: each instance's level of detail from the distance of its box centre to the camera.
    const double pruneStart = scene.render.pruneDistance;
    std::vector<int> instanceLevel(ni, 0);
    std::vector<LeafElements> leaves(pruneStart > 0.0 ? ns : 0);
    std::vector<std::vector<uint32_t>> orders(leaves.size());
    if (pruneStart > 0.0) {
        std::vector<int> levels(ns, 1);
        std::vector<glm::dvec3> centre(ns);
        tbb::parallel_for(size_t(0), ns, [&](size_t s) {
            leaves[s] = findLeafElements(assets[s].mesh);
            orders[s] = pruneOrder(leaves[s].count());
            levels[s] = pruneLevelCount(leaves[s]);
            centre[s] = glm::dvec3(meshBounds(assets[s].mesh).center());
        });
        for (size_t i = 0; i < ni; ++i) {
            const InstanceDesc& d = scene.instances[i];
            const glm::dvec3 c = rotationDeg(d.rotationDeg) * (double(d.scale) * centre[d.species]) + d.position;
            instanceLevel[i] = pruneLevelFor(glm::length(c - origin), pruneStart, levels[d.species]);
        }
    }

    // Geometry records: the species (0 .. ns-1), then every pruned level some instance uses.
    struct Geometry {
        uint32_t species;
        int level;
        PrunedLevel pruned;   // level > 0
        Bvh bvh;
        size_t triangles = 0;
    };
    std::vector<Geometry> geos(ns);
    std::vector<std::array<uint32_t, kMaxPruneLevels>> geometryOf(ns);
    for (size_t s = 0; s < ns; ++s) {
        geos[s].species = uint32_t(s);
        geos[s].level = 0;
        geometryOf[s].fill(kNoHit);
        geometryOf[s][0] = uint32_t(s);
    }
    for (size_t i = 0; i < ni; ++i) {
        const uint32_t sp = scene.instances[i].species;
        const int level = instanceLevel[i];
        if (geometryOf[sp][size_t(level)] != kNoHit) continue;
        geometryOf[sp][size_t(level)] = uint32_t(geos.size());
        geos.push_back(Geometry{sp, level, {}, {}, 0});
    }

    // Bottom level: one BVH per geometry record, built in parallel.
    tbb::parallel_for(size_t(0), geos.size(), [&](size_t g) {
        Geometry& geo = geos[g];
        const TriangleMesh& m = assets[geo.species].mesh;
        std::vector<Bounds3> boxes;
        if (geo.level == 0) {
            boxes.resize(m.triangles.size());
            for (size_t t = 0; t < boxes.size(); ++t)
                for (int c = 0; c < 3; ++c) boxes[t].extend(m.positions[m.triangles[t][c]]);
        } else {
            geo.pruned = buildPrunedLevel(m, leaves[geo.species], orders[geo.species], geo.level);
            boxes.resize(geo.pruned.tris.size());
            for (size_t t = 0; t < boxes.size(); ++t)
                for (int c = 0; c < 3; ++c) boxes[t].extend(geo.pruned.corners[3 * t + size_t(c)]);
        }
        geo.triangles = boxes.size();
        BvhBuildSettings bs;
        bs.maxLeafSize = 4;
        bs.leafBlock = 4;   // leaves are tested as one 4-wide block
        bs.wide = scene.render.accel == AccelKind::Bvh;   // the host traverses 8-wide nodes
        geo.bvh = buildBvh(boxes, bs);
    });
    if (progress) progress->report(0.7, "species BVHs built");

    // A triangle's corner uvs for TriBlock::uv: each axis shifted by the whole units below its smallest
    // corner (the cut-out wraps, so the test sees the same texels), rounded to 1/kBlockUvScale. False
    // when a corner lies 4 units or more above that (no room in 16 bits) or is not finite.
    auto packBlockUv = [](const glm::uvec3& corners, const std::vector<glm::vec2>& uvs, uint16_t (&out)[6]) {
        for (int axis = 0; axis < 2; ++axis) {
            float lo = uvs[corners[0]][axis];
            for (int c = 1; c < 3; ++c) lo = std::min(lo, uvs[corners[c]][axis]);
            if (!std::isfinite(lo)) return false;
            const double base = std::floor(double(lo));
            for (int c = 0; c < 3; ++c) {
                const double q = std::round((double(uvs[corners[c]][axis]) - base) * double(kBlockUvScale));
                if (!(q >= 0.0 && q <= 65535.0)) return false;
                out[2 * c + axis] = uint16_t(q);
            }
        }
        return true;
    };

    // Triangles of a geometry record in BVH order, then its leaves as 4-wide blocks. corner(prim, c)
    // is the species-frame position of corner c of BVH primitive prim, meshTri(prim) its mesh triangle.
    std::vector<uint32_t> triBase(ns);
    auto appendTriangles = [&rs, &packBlockUv](SpeciesRecord& sr, const Bvh& bvh, uint32_t base, auto corner, auto meshTri) {
        sr.nodeOffset = uint32_t(rs.blasNodes.size());
        sr.triOffset = uint32_t(rs.tris.size());
        rs.blasNodes.insert(rs.blasNodes.end(), bvh.nodes.begin(), bvh.nodes.end());
        for (uint32_t prim : bvh.primOrder) {
            const glm::vec3 v0 = corner(prim, 0);
            TriAccel ta{};
            ta.v0 = v0;
            ta.e1 = corner(prim, 1) - v0;
            ta.e2 = corner(prim, 2) - v0;
            ta.tri = base + meshTri(prim);
            const MaterialRecord& mr = rs.materials[rs.triMaterial[ta.tri]];
            ta.alpha = mr.alphaMask >= 0 ? uint32_t(mr.alphaMask) + 1u : 0u;
            rs.tris.push_back(ta);
        }
        // BVH leaves become 4-wide triangle blocks: leaf children then index blocks, not slots.
        sr.blockOffset = uint32_t(rs.blocks.size());
        std::vector<uint32_t> blockOfSlot(bvh.wideNodes.empty() ? 0 : bvh.primOrder.size(), kNoHit);
        for (size_t ni2 = sr.nodeOffset; ni2 < rs.blasNodes.size(); ++ni2) {
            BvhNode& node = rs.blasNodes[ni2];
            for (int k = 0; k < 4; ++k) {
                if (node.count[k] == 0 || node.child[k] == kNoHit) continue;
                if (node.count[k] > 4) throw Error("render: a BVH leaf holds more than four triangles");
                TriBlock blk{};
                for (uint32_t l = 0; l < node.count[k]; ++l) {
                    const TriAccel& t = rs.tris[sr.triOffset + node.child[k] + l];
                    blk.v0x[l] = t.v0.x, blk.v0y[l] = t.v0.y, blk.v0z[l] = t.v0.z;
                    blk.e1x[l] = t.e1.x, blk.e1y[l] = t.e1.y, blk.e1z[l] = t.e1.z;
                    blk.e2x[l] = t.e2.x, blk.e2y[l] = t.e2.y, blk.e2z[l] = t.e2.z;
                    blk.tri[l] = t.tri;
                    blk.alpha[l] = t.alpha;
                    if (t.alpha != 0u && packBlockUv(rs.triVerts[t.tri], rs.uvs, blk.uv[l])) blk.uvPacked |= 1u << l;
                }
                if (!blockOfSlot.empty()) blockOfSlot[node.child[k]] = uint32_t(rs.blocks.size() - sr.blockOffset);
                node.child[k] = uint32_t(rs.blocks.size() - sr.blockOffset);
                rs.blocks.push_back(blk);
            }
        }
        // The 8-wide flattening has the same leaves: their children become the same blocks.
        sr.wideNodeOffset = uint32_t(rs.blasWideNodes.size());
        for (BvhNode8 node : bvh.wideNodes) {
            for (int k = 0; k < 8; ++k)
                if (node.count[k] > 0) node.child[k] = blockOfSlot.at(node.child[k]);
            rs.blasWideNodes.push_back(node);
        }
    };

    for (size_t s = 0; s < ns; ++s) {
        const SpeciesAssets& a = assets[s];
        const TriangleMesh& m = a.mesh;
        const uint32_t vertBase = uint32_t(rs.normals.size());
        const uint32_t matBase = uint32_t(rs.materials.size());
        triBase[s] = uint32_t(rs.triVerts.size());

        // Shading arrays (normals: given, else from the faces).
        std::vector<glm::vec3> normals = m.normals;
        if (normals.size() != m.positions.size()) {
            normals.assign(m.positions.size(), glm::vec3(0.0f));
            for (const auto& t : m.triangles) {
                const glm::vec3 n = glm::cross(m.positions[t.y] - m.positions[t.x], m.positions[t.z] - m.positions[t.x]);
                for (int c = 0; c < 3; ++c) normals[t[c]] += n;
            }
        }
        for (glm::vec3& n : normals) {
            const float l = glm::length(n);
            n = l > 0.0f ? n / l : glm::vec3(0.0f, 1.0f, 0.0f);
        }
        rs.normals.insert(rs.normals.end(), normals.begin(), normals.end());
        if (m.uvs.size() == m.positions.size()) rs.uvs.insert(rs.uvs.end(), m.uvs.begin(), m.uvs.end());
        else rs.uvs.resize(rs.uvs.size() + m.positions.size(), glm::vec2(0.0f));
        for (const auto& t : m.triangles) rs.triVerts.push_back(t + glm::uvec3(vertBase));
        for (size_t t = 0; t < m.triangles.size(); ++t)
            rs.triMaterial.push_back(matBase + (m.triangleMaterial.empty() ? 0u : m.triangleMaterial[t]));

        // Materials, textures, cut-outs.
        const size_t nm = std::max<size_t>(1, m.materials.size());
        for (size_t i = 0; i < nm; ++i) {
            MaterialRecord r{};
            const Material def;
            const Material& mat = i < m.materials.size() ? m.materials[i] : def;
            r.diffuse = mat.diffuse;
            r.specular = mat.specular;
            r.shininess = mat.shininess;
            r.isLeaf = mat.isLeaf ? 1u : 0u;
            r.texture = -1;
            r.alphaMask = -1;
            if (i < a.diffuse.size()) addTexture(a.diffuse[i], rs, r);
            if (i < a.cutout.size()) addCutout(a.cutout[i], rs, r);
            rs.materials.push_back(r);
        }

        // Triangles in BVH order.
        SpeciesRecord sr{};
        appendTriangles(
            sr, geos[s].bvh, triBase[s], [&m](uint32_t prim, int c) { return m.positions[m.triangles[prim][c]]; },
            [](uint32_t prim) { return prim; });

        // Lighting grid, normalized by the unobstructed photon density.
        const LightingGrid& g = a.lighting;
        if (!g.rgb.empty()) {
            if (g.rgb.size() != g.geometry.nodeCount() * 3) throw Error("render: lighting grid size does not match its dims");
            sr.gridOrigin = glm::vec3(g.geometry.origin);
            sr.gridInvSpacing = float(1.0 / g.geometry.spacing);
            sr.gridDims = g.geometry.dims;
            sr.gridOffset = uint32_t(rs.lighting.size());
            for (size_t i = 0; i < g.rgb.size(); ++i) {
                const float norm = a.lightingNorm[int(i % 3)];
                rs.lighting.push_back(norm > 0.0f ? g.rgb[i] / norm : 0.0f);
            }
        }
        rs.species.push_back(sr);
        rs.m_stats.speciesTriangles += m.triangles.size();
        rs.m_stats.maxBlasDepth = std::max(rs.m_stats.maxBlasDepth, geos[s].bvh.depth);
        rs.m_stats.maxWideBlasDepth = std::max(rs.m_stats.maxWideBlasDepth, geos[s].bvh.wideDepth);
    }

    // Pruned levels: own triangles and BVH, the species' shading data and lighting grid.
    const size_t nodesBefore = rs.blasNodes.size(), trisBefore = rs.tris.size(), blocksBefore = rs.blocks.size();
    const size_t wideBefore = rs.blasWideNodes.size();
    for (size_t gi = ns; gi < geos.size(); ++gi) {
        const Geometry& geo = geos[gi];
        SpeciesRecord sr = rs.species[geo.species];
        const PrunedLevel& p = geo.pruned;
        appendTriangles(
            sr, geo.bvh, triBase[geo.species], [&p](uint32_t prim, int c) { return p.corners[3 * size_t(prim) + size_t(c)]; },
            [&p](uint32_t prim) { return p.tris[prim]; });
        rs.species.push_back(sr);
        rs.m_stats.maxBlasDepth = std::max(rs.m_stats.maxBlasDepth, geo.bvh.depth);
        rs.m_stats.maxWideBlasDepth = std::max(rs.m_stats.maxWideBlasDepth, geo.bvh.wideDepth);
    }
    rs.m_stats.prunedLevels = geos.size() - ns;

    // Top level over the instances' camera-relative boxes.
    rs.instances.reserve(ni);
    std::vector<Bounds3> boxes(ni);
    for (size_t i = 0; i < ni; ++i) {
        const InstanceDesc& d = scene.instances[i];
        InstanceRecord rec = makeInstance(d, origin);
        rec.geometry = geometryOf[d.species][size_t(instanceLevel[i])];
        rs.instances.push_back(rec);
        const Bounds3& lb = geos[rec.geometry].bvh.bounds;
        const glm::dmat3 r = rotationDeg(d.rotationDeg) * double(d.scale);
        for (int c = 0; c < 8; ++c) {
            const glm::dvec3 corner((c & 1) ? lb.hi.x : lb.lo.x, (c & 2) ? lb.hi.y : lb.lo.y, (c & 4) ? lb.hi.z : lb.lo.z);
            boxes[i].extend(glm::vec3(r * corner + (d.position - origin)));
        }
        // Grow by a relative epsilon so float rounding of the transform never clips geometry.
        const glm::vec3 pad = 1e-5f * (glm::abs(boxes[i].lo) + glm::abs(boxes[i].hi)) + 1e-6f;
        boxes[i].lo -= pad;
        boxes[i].hi += pad;
        rs.m_stats.instancedTriangles += double(geos[rec.geometry].triangles);
        ++rs.m_stats.instancesPerLevel[size_t(instanceLevel[i])];
    }
    if (scene.render.accel == AccelKind::KdTree) {
        // The seed's structure at both levels. Species trees index triangles by BVH slot (the order
        // of rs.tris) and clip them to the split boxes ("perfect splits").
        rs.m_stats.maxBlasDepth = 0;
        std::vector<KdTree> kd(geos.size());
        tbb::parallel_for(size_t(0), geos.size(), [&](size_t g) {
            const TriAccel* tris = rs.tris.data() + rs.species[g].triOffset;
            const size_t n = geos[g].triangles;
            std::vector<Bounds3> triBoxes(n);
            for (size_t t = 0; t < n; ++t) {
                triBoxes[t].extend(tris[t].v0);
                triBoxes[t].extend(tris[t].v0 + tris[t].e1);
                triBoxes[t].extend(tris[t].v0 + tris[t].e2);
            }
            KdBuildSettings ks;
            ks.clip = [tris](uint32_t prim, const Bounds3& box) {
                const TriAccel& t = tris[prim];
                return clipTriangleToBox(t.v0, t.v0 + t.e1, t.v0 + t.e2, box);
            };
            kd[g] = buildKdTree(triBoxes, ks);
        });
        for (size_t g = 0; g < geos.size(); ++g) {
            KdSpeciesRecord r{};
            r.lo = kd[g].bounds.lo;
            r.hi = kd[g].bounds.hi;
            r.nodeOffset = uint32_t(rs.kdBlasNodes.size());
            r.refOffset = uint32_t(rs.kdBlasRefs.size());
            rs.kdBlasNodes.insert(rs.kdBlasNodes.end(), kd[g].nodes.begin(), kd[g].nodes.end());
            rs.kdBlasRefs.insert(rs.kdBlasRefs.end(), kd[g].primRefs.begin(), kd[g].primRefs.end());
            rs.kdSpecies.push_back(r);
            rs.m_stats.maxBlasDepth = std::max(rs.m_stats.maxBlasDepth, kd[g].stats.depth);
        }
        KdTree top = buildKdTree(boxes);
        rs.kdTlasNodes = std::move(top.nodes);
        rs.kdTlasRefs = std::move(top.primRefs);
        rs.base.kdTlasLo = top.bounds.lo;
        rs.base.kdTlasHi = top.bounds.hi;
        rs.m_stats.tlasDepth = top.stats.depth;
    }
    BvhBuildSettings ts;
    ts.maxLeafSize = 2;
    ts.wide = scene.render.accel == AccelKind::Bvh;
    Bvh tlas = buildBvh(boxes, ts);
    rs.tlasNodes = std::move(tlas.nodes);
    rs.tlasWideNodes = std::move(tlas.wideNodes);
    rs.tlasOrder = std::move(tlas.primOrder);
    if (scene.render.accel != AccelKind::KdTree) rs.m_stats.tlasDepth = tlas.depth;
    rs.m_stats.wideTlasDepth = tlas.wideDepth;

    // Environment, camera, settings.
    RenderView& b = rs.base;
    b.groundEnabled = scene.ground.enabled;
    b.groundY = float(scene.ground.height - origin.y);
    b.groundColor = scene.ground.color;
    const glm::vec3 sd = scene.sun.direction;
    if (!(glm::length(sd) > 0.0f)) throw Error("sun: direction must not be zero");
    b.sunDir = glm::normalize(sd);
    b.sunRadiance = sunRadiance;
    b.sky = scene.sky;
    b.camera = makeCamera(scene.camera, scene.render.width, scene.render.height);
    b.width = scene.render.width;
    b.height = scene.render.height;
    b.spp = scene.render.spp;
    b.accel = scene.render.accel;
    b.shadows = scene.render.shadows;
    b.indirectScale = scene.render.indirectScale;
    b.alphaDistance = scene.render.alphaDistance;

    AccelStats& st = rs.m_stats;
    if (scene.render.accel == AccelKind::KdTree) {
        st.tlasBytes = rs.kdTlasNodes.size() * sizeof(KdNode) + rs.kdTlasRefs.size() * sizeof(uint32_t);
        st.blasBytes = rs.kdBlasNodes.size() * sizeof(KdNode) + rs.kdBlasRefs.size() * sizeof(uint32_t) +
                       rs.kdSpecies.size() * sizeof(KdSpeciesRecord);
    } else {
        st.tlasBytes = rs.tlasNodes.size() * sizeof(BvhNode) + rs.tlasOrder.size() * sizeof(uint32_t);
        st.wideTlasBytes = rs.tlasWideNodes.size() * sizeof(BvhNode8);
        st.blasBytes = rs.blasNodes.size() * sizeof(BvhNode);
        st.wideBlasBytes = rs.blasWideNodes.size() * sizeof(BvhNode8);
    }
    st.instanceBytes = rs.instances.size() * sizeof(InstanceRecord);
    st.triangleBytes = scene.render.accel == AccelKind::KdTree ? rs.tris.size() * sizeof(TriAccel)
                                                               : rs.blocks.size() * sizeof(TriBlock);
    st.pruneBytes = (rs.blasNodes.size() - nodesBefore) * sizeof(BvhNode) + (rs.tris.size() - trisBefore) * sizeof(TriAccel) +
                    (rs.blocks.size() - blocksBefore) * sizeof(TriBlock) + (rs.blasWideNodes.size() - wideBefore) * sizeof(BvhNode8);
    st.instances = rs.instances.size();
    if (progress) progress->report(1.0, "acceleration structures built");
    return rs;
}

} // namespace sylva
