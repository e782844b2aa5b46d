// The mesh surface kind's builder: every species and pruned level of detail flattened into the frame's arrays
// (shading arrays, materials, textures, cut-outs, lighting grids, triangles in BVH order and their 4-wide
// blocks, or kd-trees), one geometry record each.
#include "core/render/scene_build.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <tbb/parallel_for.h>

#include "core/base/error.h"
#include "core/lb/leaf_optics.h"
#include "core/render/prune.h"
#include "core/render/tonemap.h"

namespace sylva::scene_build {

namespace {

void addCutout(const ImageRgba& img, RenderScene& rs, MaterialRecord& m)
{
    if (img.empty() || !hasClearTexels(img)) return;
    AlphaMaskRecord rec{img.width, img.height, uint32_t(rs.alphaBits.size()), 0};
    const size_t bits = size_t(img.width) * size_t(img.height);
    rs.alphaBits.resize(rs.alphaBits.size() + (bits + 31) / 32, 0u);
    for (size_t b = 0; b < bits; ++b)
        if (img.pixels[b * 4 + 3] >= kCutoutThreshold) rs.alphaBits[rec.offset + b / 32] |= 1u << (b % 32);
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

// The level of detail of each of the scene's own instances from the distance of its species' box centre
// to the camera (instances of groups, and every instance when pruning is off: level 0).
std::vector<int> instanceLevels(const Scene& scene, const std::vector<RenderScene::MeshLevels>& ml)
{
    std::vector<int> level(scene.instances.size(), 0);
    const double start = scene.render.pruneDistance;
    if (!(start > 0.0)) return level;
    for (size_t i = 0; i < level.size(); ++i) {
        const InstanceDesc& d = scene.instances[i];
        if (d.group != kNoGroup || d.species >= ml.size()) continue;
        const glm::dvec3 c = rotationDeg(d.rotationDeg) * (double(d.scale) * ml[d.species].centre) + d.position;
        level[i] = pruneLevelFor(glm::length(c - scene.camera.position), start, ml[d.species].levels);
    }
    return level;
}

namespace {

// One mesh geometry record being built: a species (level 0) or one of its pruned levels.
struct MeshBuild {
    uint32_t species;
    int level;
    PrunedLevel pruned;   // level > 0
    Bvh bvh;
    size_t triangles = 0;
};

// Stochastic pruning's analysis of each species (only when the scene prunes): its leaf elements, their
// removal order, the levels it supports and its box centre (rs.meshLevels).
struct PruneInputs {
    std::vector<LeafElements> leaves;
    std::vector<std::vector<uint32_t>> orders;
};
PruneInputs analyseLevels(RenderScene& rs, const std::vector<SpeciesAssets>& assets, bool prune)
{
    const size_t ns = assets.size();
    PruneInputs in;
    in.leaves.resize(prune ? ns : 0);
    in.orders.resize(in.leaves.size());
    rs.meshLevels.resize(ns);
    for (RenderScene::MeshLevels& m : rs.meshLevels) std::fill(std::begin(m.geometry), std::end(m.geometry), kNoHit);
    if (prune) {
        tbb::parallel_for(size_t(0), ns, [&](size_t s) {
            in.leaves[s] = findLeafElements(assets[s].mesh);
            in.orders[s] = pruneOrder(in.leaves[s].count());
            rs.meshLevels[s].levels = pruneLevelCount(in.leaves[s]);
            rs.meshLevels[s].centre = glm::dvec3(meshBounds(assets[s].mesh).center());
        });
    } else {
        for (RenderScene::MeshLevels& m : rs.meshLevels) m.levels = 0;   // not analysed: only level 0 exists
    }
    return in;
}

// The mesh records: the species (0 .. ns-1), then the pruned levels (in order of first use by an instance, or
// every level of every species for LodLevels::All); rs.meshLevels points at them.
std::vector<MeshBuild> chooseMeshRecords(RenderScene& rs, const Scene& scene, size_t ns, bool prune, LodLevels lod)
{
    std::vector<MeshBuild> meshes(ns);
    for (size_t s = 0; s < ns; ++s) {
        meshes[s].species = uint32_t(s);
        meshes[s].level = 0;
        rs.meshLevels[s].geometry[0] = uint32_t(s);
    }
    auto useLevel = [&](uint32_t sp, int level) {
        uint32_t& g = rs.meshLevels[sp].geometry[size_t(level)];
        if (g != kNoHit) return;
        g = uint32_t(meshes.size());
        meshes.push_back(MeshBuild{sp, level, {}, {}, 0});
    };
    if (prune && lod == LodLevels::All) {
        for (uint32_t sp = 0; sp < ns; ++sp)
            for (int l = 1; l < rs.meshLevels[sp].levels; ++l) useLevel(sp, l);
    } else if (prune) {
        const std::vector<int> level = instanceLevels(scene, rs.meshLevels);
        for (size_t i = 0; i < scene.instances.size(); ++i)
            if (scene.instances[i].group == kNoGroup) useLevel(scene.instances[i].species, level[i]);
    }
    return meshes;
}

// Bottom level: one BVH per mesh record (a pruned level's triangles made first), built in parallel.
void buildMeshBvhs(std::vector<MeshBuild>& meshes, const std::vector<SpeciesAssets>& assets, const PruneInputs& in, AccelKind accel)
{
    tbb::parallel_for(size_t(0), meshes.size(), [&](size_t g) {
        MeshBuild& geo = meshes[g];
        const TriangleMesh& m = assets[geo.species].mesh;
        std::vector<Bounds3> boxes;
        if (geo.level == 0) {
            boxes.resize(m.triangles.size());
            for (size_t t = 0; t < boxes.size(); ++t)
                for (int c = 0; c < 3; ++c) boxes[t].extend(m.positions[m.triangles[t][c]]);
        } else {
            geo.pruned = buildPrunedLevel(m, in.leaves[geo.species], in.orders[geo.species], geo.level);
            boxes.resize(geo.pruned.tris.size());
            for (size_t t = 0; t < boxes.size(); ++t)
                for (int c = 0; c < 3; ++c) boxes[t].extend(geo.pruned.corners[3 * t + size_t(c)]);
        }
        geo.triangles = boxes.size();
        BvhBuildSettings bs;
        bs.maxLeafSize = 4;
        bs.leafBlock = 4;   // leaves are tested as one 4-wide block
        bs.wide = accel == AccelKind::Bvh;   // the host traverses 8-wide nodes
        geo.bvh = buildBvh(boxes, bs);
    });
}

// A triangle's corner uvs for TriBlock::uv: each axis shifted by the whole units below its smallest corner
// (the cut-out wraps, so the test sees the same texels), rounded to 1/kBlockUvScale. False when a corner lies
// 4 units or more above that (no room in 16 bits) or is not finite.
bool packBlockUv(const glm::uvec3& corners, const std::vector<glm::vec2>& uvs, uint16_t (&out)[6])
{
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
}

// Triangles of a geometry record in BVH order, then its leaves as 4-wide blocks. corner(prim, c) is the
// species-frame position of corner c of BVH primitive prim, meshTri(prim) its mesh triangle.
template <class Corner, class MeshTri>
void appendTriangles(RenderScene& rs, GeometryRecord& sr, const Bvh& bvh, uint32_t base, Corner corner, MeshTri meshTri)
{
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
    sr.primOffset = uint32_t(rs.blocks.size());
    std::vector<uint32_t> blockOfSlot(bvh.wideNodes.empty() ? 0 : bvh.primOrder.size(), kNoHit);
    for (size_t ni = sr.nodeOffset; ni < rs.blasNodes.size(); ++ni) {
        BvhNode& node = rs.blasNodes[ni];
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
            if (!blockOfSlot.empty()) blockOfSlot[node.child[k]] = uint32_t(rs.blocks.size() - sr.primOffset);
            node.child[k] = uint32_t(rs.blocks.size() - sr.primOffset);
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
}

// Every array the species and levels append to at its final size before the first append: grown by doubling
// instead, they would copy themselves into fresh memory several times (a page fault per page each time), most
// of the serial build.
void reserveMeshArrays(RenderScene& rs, const std::vector<MeshBuild>& meshes, const std::vector<SpeciesAssets>& assets)
{
    size_t nodes = 0, tris = 0, blocks = 0, wide = 0, verts = 0, faces = 0, light = 0;
    for (const MeshBuild& geo : meshes) {
        nodes += geo.bvh.nodes.size();
        tris += geo.bvh.primOrder.size();
        wide += geo.bvh.wideNodes.size();
        for (const BvhNode& node : geo.bvh.nodes)
            for (int k = 0; k < 4; ++k) blocks += node.count[k] != 0 && node.child[k] != kNoHit ? 1 : 0;
    }
    for (const SpeciesAssets& a : assets) {
        verts += a.mesh.positions.size();
        faces += a.mesh.triangles.size();
        light += a.lighting.rgb.size();
    }
    rs.blasNodes.reserve(rs.blasNodes.size() + nodes);
    rs.tris.reserve(rs.tris.size() + tris);
    rs.blocks.reserve(rs.blocks.size() + blocks);
    rs.blasWideNodes.reserve(rs.blasWideNodes.size() + wide);
    rs.normals.reserve(rs.normals.size() + verts);
    rs.uvs.reserve(rs.uvs.size() + verts);
    rs.triVerts.reserve(rs.triVerts.size() + faces);
    rs.triMaterial.reserve(rs.triMaterial.size() + faces);
    rs.lighting.reserve(rs.lighting.size() + light);
}

// A species' shading arrays: unit normals (given, else from the faces), uvs, triangles' vertices and materials.
void appendShadingArrays(RenderScene& rs, const TriangleMesh& m)
{
    const uint32_t vertBase = uint32_t(rs.normals.size());
    const uint32_t matBase = uint32_t(rs.materials.size());
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
}

// A species' materials with their textures and cut-outs (one default material when the mesh names none); the
// leaves' diffuse colour times the scene's leaf tint.
void appendMaterials(RenderScene& rs, const SpeciesAssets& a, const glm::vec3& leafTint)
{
    const TriangleMesh& m = a.mesh;
    const size_t nm = std::max<size_t>(1, m.materials.size());
    for (size_t i = 0; i < nm; ++i) {
        MaterialRecord r{};
        const Material def;
        const Material& mat = i < m.materials.size() ? m.materials[i] : def;
        r.diffuse = mat.isLeaf ? mat.diffuse * leafTint : mat.diffuse;
        r.specular = mat.specular;
        r.shininess = mat.shininess;
        r.isLeaf = mat.isLeaf ? 1u : 0u;
        r.texture = -1;
        r.alphaMask = -1;
        if (i < a.diffuse.size()) addTexture(a.diffuse[i], rs, r);
        if (i < a.cutout.size()) addCutout(a.cutout[i], rs, r);
        rs.materials.push_back(r);
    }
}

// Species s's record: its lighting grid normalized by the unobstructed photon density into rs.lighting, and
// what its surfaces make of it (with lighting.direct once the grid holds scattered light only).
SpeciesRecord speciesRecord(RenderScene& rs, const Scene& scene, size_t s, const SpeciesAssets& a)
{
    SpeciesRecord sr{};
    sr.leafIndirect = glm::vec3(1.0f);
    sr.barkIndirect = 1.0f;
    sr.leafIndirectCap = std::numeric_limits<float>::max();   // the seed's sum: kd x L, uncapped (old pictures)
    if (s < scene.species.size()) sr.leafRatio = lb::leafOptics(scene.species[s].lighting).ratio;
    const LightingGrid& g = a.lighting;
    if (g.rgb.empty()) return sr;
    if (g.rgb.size() != g.geometry.nodeCount() * 3) throw Error("render: lighting grid size does not match its dims");
    sr.gridOrigin = glm::vec3(g.geometry.origin);
    sr.gridInvSpacing = float(1.0 / g.geometry.spacing);
    sr.gridDims = g.geometry.dims;
    sr.gridOffset = uint32_t(rs.lighting.size());
    for (size_t i = 0; i < g.rgb.size(); ++i) {
        const float norm = a.lightingNorm[int(i % 3)];
        rs.lighting.push_back(norm > 0.0f ? g.rgb[i] / norm : 0.0f);
    }
    if (gridDirectLight(scene.lighting) == DirectLight::Once && s < scene.species.size()) {
        // The grid holds scattered light only: each face gets a quarter of its fluence (leaf_optics.h).
        const lb::ScatteredWeights w = lb::scatteredWeights(scene.species[s].lighting);
        sr.leafIndirect = w.leaf;
        sr.barkIndirect = w.bark;
        sr.leafIndirectCap = w.leafCap;
    }
    return sr;
}

// The species (mesh records 0 .. ns-1): shading arrays, materials, triangles in BVH order, species records.
// Returns each species' first triangle in rs.triVerts (its pruned levels index the same triangles).
std::vector<uint32_t> appendSpecies(RenderScene& rs, const Scene& scene, const std::vector<SpeciesAssets>& assets, const std::vector<MeshBuild>& meshes)
{
    std::vector<uint32_t> triBase(assets.size());
    for (size_t s = 0; s < assets.size(); ++s) {
        const SpeciesAssets& a = assets[s];
        const TriangleMesh& m = a.mesh;
        triBase[s] = uint32_t(rs.triVerts.size());
        appendShadingArrays(rs, m);
        appendMaterials(rs, a, scene.render.leafTint);
        GeometryRecord gr{};
        gr.kind = GeometryKind::Mesh;
        gr.species = uint32_t(s);
        appendTriangles(
            rs, gr, meshes[s].bvh, triBase[s], [&m](uint32_t prim, int c) { return m.positions[m.triangles[prim][c]]; },
            [](uint32_t prim) { return prim; });
        rs.geometries.push_back(gr);
        rs.species.push_back(speciesRecord(rs, scene, s, a));
        rs.buildStats.speciesTriangles += m.triangles.size();
        rs.buildStats.maxBlasDepth = std::max(rs.buildStats.maxBlasDepth, meshes[s].bvh.depth);
        rs.buildStats.maxWideBlasDepth = std::max(rs.buildStats.maxWideBlasDepth, meshes[s].bvh.wideDepth);
    }
    return triBase;
}

// Pruned levels (mesh records ns ..): own triangles and BVH, the species' shading data and lighting grid.
void appendPrunedLevels(RenderScene& rs, const std::vector<MeshBuild>& meshes, size_t ns, const std::vector<uint32_t>& triBase)
{
    const size_t nodesBefore = rs.blasNodes.size(), trisBefore = rs.tris.size(), blocksBefore = rs.blocks.size();
    const size_t wideBefore = rs.blasWideNodes.size();
    for (size_t gi = ns; gi < meshes.size(); ++gi) {
        const MeshBuild& geo = meshes[gi];
        GeometryRecord gr{};
        gr.kind = GeometryKind::Mesh;
        gr.species = geo.species;
        const PrunedLevel& p = geo.pruned;
        appendTriangles(
            rs, gr, geo.bvh, triBase[geo.species], [&p](uint32_t prim, int c) { return p.corners[3 * size_t(prim) + size_t(c)]; },
            [&p](uint32_t prim) { return p.tris[prim]; });
        rs.geometries.push_back(gr);
        rs.buildStats.maxBlasDepth = std::max(rs.buildStats.maxBlasDepth, geo.bvh.depth);
        rs.buildStats.maxWideBlasDepth = std::max(rs.buildStats.maxWideBlasDepth, geo.bvh.wideDepth);
    }
    rs.buildStats.prunedLevels = meshes.size() - ns;
    rs.buildStats.pruneBytes = (rs.blasNodes.size() - nodesBefore) * sizeof(BvhNode) + (rs.tris.size() - trisBefore) * sizeof(TriAccel) +
                               (rs.blocks.size() - blocksBefore) * sizeof(TriBlock) +
                               (rs.blasWideNodes.size() - wideBefore) * sizeof(BvhNode8);
}

// Mesh records' bounds and triangle counts.
void setMeshBounds(RenderScene& rs, const std::vector<MeshBuild>& meshes)
{
    const size_t nm = meshes.size();
    rs.geometryBounds.resize(nm);
    rs.geometryTriangles.resize(nm);
    for (size_t g = 0; g < nm; ++g) {
        GeometryRecord& gr = rs.geometries[g];
        rs.geometryBounds[g] = meshes[g].bvh.bounds;
        rs.geometryTriangles[g] = double(meshes[g].triangles);
        gr.primCount = uint32_t(meshes[g].triangles);
        gr.lo = meshes[g].bvh.bounds.lo;
        gr.hi = meshes[g].bvh.bounds.hi;
    }
}

// In kd-tree runs, the mesh records' kd-trees (the seed's structure at the mesh level), indexing triangles by
// BVH slot (the order of rs.tris) and clipping them to the split boxes ("perfect splits").
void buildMeshKdTrees(RenderScene& rs, const std::vector<MeshBuild>& meshes)
{
    const size_t nm = meshes.size();
    rs.buildStats.maxBlasDepth = 0;
    std::vector<KdTree> kd(nm);
    tbb::parallel_for(size_t(0), nm, [&](size_t g) {
        const TriAccel* tris = rs.tris.data() + rs.geometries[g].triOffset;
        const size_t n = meshes[g].triangles;
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
    for (size_t g = 0; g < nm; ++g) {
        GeometryRecord& gr = rs.geometries[g];
        gr.lo = kd[g].bounds.lo;   // the box kd-tree rays are clipped to
        gr.hi = kd[g].bounds.hi;
        gr.kdNodeOffset = uint32_t(rs.kdNodes.size());
        gr.kdRefOffset = uint32_t(rs.kdRefs.size());
        rs.kdNodes.insert(rs.kdNodes.end(), kd[g].nodes.begin(), kd[g].nodes.end());
        rs.kdRefs.insert(rs.kdRefs.end(), kd[g].primRefs.begin(), kd[g].primRefs.end());
        rs.buildStats.maxBlasDepth = std::max(rs.buildStats.maxBlasDepth, kd[g].stats.depth);
    }
}

} // namespace

void buildMeshGeometry(RenderScene& rs, const Scene& scene, const std::vector<SpeciesAssets>& assets, LodLevels lod, Progress* progress)
{
    const bool prune = scene.render.pruneDistance > 0.0;
    const PruneInputs pruneInputs = analyseLevels(rs, assets, prune);
    std::vector<MeshBuild> meshes = chooseMeshRecords(rs, scene, assets.size(), prune, lod);
    buildMeshBvhs(meshes, assets, pruneInputs, scene.render.accel);
    if (progress) progress->report(0.7, "species BVHs built");
    reserveMeshArrays(rs, meshes, assets);
    const std::vector<uint32_t> triBase = appendSpecies(rs, scene, assets, meshes);
    appendPrunedLevels(rs, meshes, assets.size(), triBase);
    setMeshBounds(rs, meshes);
    if (scene.render.accel == AccelKind::KdTree) buildMeshKdTrees(rs, meshes);
}

} // namespace sylva::scene_build
