// The scene as binary glTF (gltf_export.h): instances flattened and placed as the renderer places them, the
// species' meshes and materials, the ground or the terrain, through the GLB builder (pipeline/io/glb_writer.h).
#include "pipeline/services/gltf_export.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>
#include <sstream>

#include <QByteArray>
#include <QFile>

#include "core/base/error.h"
#include "core/base/version.h"
#include "core/render/surfaces/terrain.h"
#include "core/terrain/height_field.h"
#include "core/terrain/landscape.h"
#include "pipeline/io/atomic_file.h"
#include "pipeline/io/file_extension.h"
#include "pipeline/io/glb_writer.h"

namespace sylva {

namespace fs = std::filesystem;

namespace {

// An instance's parent -> world placement composed with the placement of its parent (the renderer's instance
// map, makeInstance: world = R (s x) + p, R = rotationDeg).
struct Placement {
    glm::dmat3 rotation{1.0};
    double scale = 1.0;
    glm::dvec3 translation{0.0};
    Placement then(const InstanceDesc& d) const   // d in this placement's frame
    {
        return Placement{rotation * rotationDeg(d.rotationDeg), scale * double(d.scale), translation + rotation * (scale * d.position)};
    }
};

GltfInstance toInstance(const Placement& p)
{
    GltfInstance g;
    g.translation = p.translation;
    g.rotation = glm::normalize(glm::quat_cast(p.rotation));
    if (g.rotation.w < 0.0) g.rotation = -g.rotation;   // one of the two quaternions of R: w >= 0
    g.scale = p.scale;
    return g;
}

bool inRegion(const GltfExportOptions& o, double x, double z)
{
    if (!o.region) return true;
    const auto& r = *o.region;
    return x >= r[0] && x < r[2] && z >= r[1] && z < r[3];
}

bool speciesChosen(const GltfExportOptions& o, uint32_t s)
{
    return o.species.empty() || std::find(o.species.begin(), o.species.end(), size_t(s)) != o.species.end();
}

void visitInstance(const Scene& scene, const InstanceDesc& d, const Placement& parent, int depth, const GltfExportOptions& o,
                   const std::function<void(uint32_t, const GltfInstance&)>& visit)
{
    const Placement p = parent.then(d);
    if (d.group != kNoGroup) {
        if (d.group >= scene.groups.size()) throw Error("glTF export: an instance names a missing group");
        if (depth >= 8) throw Error("glTF export: group '" + scene.groups[d.group].name + "' nests too deep (or contains itself)");
        for (const InstanceDesc& c : scene.groups[d.group].instances) visitInstance(scene, c, p, depth + 1, o, visit);
        return;
    }
    if (d.species >= scene.species.size()) throw Error("glTF export: an instance names a missing species");
    if (!speciesChosen(o, d.species) || !inRegion(o, p.translation.x, p.translation.z)) return;
    visit(d.species, toInstance(p));
}

bool hasLandscape(const Scene& scene) { return scene.terrain.enabled() && scene.terrain.cells > 0; }

// The landscape's plants as the renderer builds and thins them (buildLandscapeArrays, landPlantGrows), placed in
// the world: root = terrain origin + the cell corner + tileScale x the plant's tile position, lifted onto the
// ground; rotation and scale from the plant's map (TilePlant::row = R^T / scale) times the tile's scale.
void visitLandscape(const Scene& scene, const std::vector<Bounds3>& boxes, const GltfExportOptions& o,
                    const std::function<void(uint32_t, const GltfInstance&)>& visit)
{
    const TerrainDesc& t = scene.terrain;
    if (!t.field) throw Error("glTF export: the terrain's heights were not loaded (" + t.dem + ")");
    if (boxes.size() < scene.species.size()) throw Error("glTF export: the species' meshes are not loaded");
    std::vector<LandscapeSpecies> ls(scene.species.size());
    for (size_t s = 0; s < ls.size(); ++s) ls[s] = LandscapeSpecies{uint32_t(s), boxes[s].lo, boxes[s].hi, 0.0};
    const LandscapeBuild b = buildLandscape(*t.field, uint32_t(t.cells), t.tiles, t.tiling, t.density, t.origin.y, 0.0f, 0.0f, ls);
    const LandscapeLayout& L = b.layout;
    const HeightFieldView hv = t.field->view();
    const float snowY = terrainSnowY(t), rockCos = terrainRockCos(t);
    const double cs = double(L.cellSize), k = double(L.tileScale);
    for (uint32_t cz = 0; cz < L.cellsZ; ++cz)
        for (uint32_t cx = 0; cx < L.cellsX; ++cx) {
            const double x0 = t.origin.x + double(cx) * cs, z0 = t.origin.z + double(cz) * cs;
            if (o.region) {
                const auto& r = *o.region;
                if (x0 >= r[2] || z0 >= r[3] || x0 + cs < r[0] || z0 + cs < r[1]) continue;
            }
            const TileRecord& tile = b.tiles[b.cells[size_t(cz) * L.cellsX + cx].tile];
            for (uint32_t q = 0; q < tile.plantCount; ++q) {
                const TilePlant& p = b.plants[tile.plantOffset + q];
                if (!speciesChosen(o, p.species)) continue;
                const double x = x0 + k * double(p.x), z = z0 + k * double(p.z);
                if (!inRegion(o, x, z)) continue;
                float y = 0.0f;
                if (!landPlantGrows(L, hv, snowY, rockCos, cx, cz, p, y)) continue;
                Placement pl;
                for (int i = 0; i < 3; ++i)
                    for (int j = 0; j < 3; ++j) pl.rotation[i][j] = double(p.row[i][j]) * double(p.scale);   // column i of R = row i of R^T
                pl.scale = k * double(p.scale);
                pl.translation = glm::dvec3(x, t.origin.y + double(y), z);
                GltfInstance in = toInstance(pl);
                in.landscape = true;
                visit(p.species, in);
            }
        }
}

// Samples of the terrain mesh along one axis: every `step`-th of [first, last], the last always kept.
std::vector<uint32_t> terrainSamples(uint32_t first, uint32_t last)
{
    const size_t n = size_t(last - first) + 1;
    const uint32_t step = n <= kGltfTerrainMaxSamples ? 1u : uint32_t((n - 1 + kGltfTerrainMaxSamples - 2) / (kGltfTerrainMaxSamples - 1));
    std::vector<uint32_t> out;
    for (uint32_t i = first; i < last; i += step) out.push_back(i);
    out.push_back(last);
    return out;
}

// The terrain's sample range in the region (all of it without one); false when the region misses it.
bool terrainRange(const Scene& scene, const GltfExportOptions& o, uint32_t r[4])
{
    const TerrainDesc& t = scene.terrain;
    const HeightFieldLayout& L = t.field->layout;
    r[0] = 0, r[1] = 0, r[2] = L.nx - 1, r[3] = L.nz - 1;
    if (!o.region) return true;
    const auto& g = *o.region;
    const double i0 = std::floor((g[0] - t.origin.x) / double(L.dx)), i1 = std::ceil((g[2] - t.origin.x) / double(L.dx));
    const double j0 = std::floor((g[1] - t.origin.z) / double(L.dz)), j1 = std::ceil((g[3] - t.origin.z) / double(L.dz));
    const double lo[2] = {std::max(0.0, i0), std::max(0.0, j0)}, hi[2] = {std::min(double(L.nx - 1), i1), std::min(double(L.nz - 1), j1)};
    if (!(hi[0] > lo[0]) || !(hi[1] > lo[1])) return false;
    r[0] = uint32_t(lo[0]), r[1] = uint32_t(lo[1]), r[2] = uint32_t(hi[0]), r[3] = uint32_t(hi[1]);
    return true;
}

// A material's base colour texture: the file's own bytes (PNG or JPEG, its alpha the cut-out), or the colour and
// cut-out images as one PNG. Empty bytes: none.
struct TextureBytes {
    std::string key;           // shared by materials that use the same texture
    QByteArray bytes;
    const char* mime = "image/png";
    double estimate = 0.0;     // bytes, before encoding
};

TextureBytes textureFor(const SpeciesAssets& a, size_t s, size_t m, bool encode)
{
    TextureBytes t;
    const Material& mat = a.mesh.materials[m];
    static const ImageRgba kNone;
    const ImageRgba& diffuse = m < a.diffuse.size() ? a.diffuse[m] : kNone;
    const ImageRgba& cutout = m < a.cutout.size() ? a.cutout[m] : kNone;
    const bool mask = !cutout.empty() && hasClearTexels(cutout);
    if (diffuse.empty() && !mask) return t;
    const std::string ext = lowerExtension(mat.diffuseTexture);
    // The file itself when its own alpha is the cut-out (no opacity map, or the same file read alike).
    const bool ownAlpha = mat.alphaTexture.empty() || (mat.alphaTexture == mat.diffuseTexture && cutout.pixels == diffuse.pixels);
    if (!diffuse.empty() && ownAlpha && !mat.diffuseTexture.empty() && (ext == ".png" || ext == ".jpg" || ext == ".jpeg")) {
        t.key = "file:" + mat.diffuseTexture;
        t.mime = ext == ".png" ? "image/png" : "image/jpeg";
        t.estimate = double(fs::file_size(mat.diffuseTexture));
        if (encode) {
            QFile f(QString::fromStdString(mat.diffuseTexture));
            if (!f.open(QIODevice::ReadOnly)) throw Error(mat.diffuseTexture + ": cannot read the texture");
            t.bytes = f.readAll();
        }
        return t;
    }
    char key[96];
    std::snprintf(key, sizeof key, "image:%p:%p:%d", static_cast<const void*>(diffuse.pixels.data()), static_cast<const void*>(cutout.pixels.data()),
                  int(mask));
    t.key = key + std::to_string(s);
    const ImageRgba& shape = diffuse.empty() ? cutout : diffuse;
    t.estimate = double(shape.width) * double(shape.height) * (mask ? 4.0 : 3.0);
    if (!encode) return t;
    if (!mask || (cutout.width == diffuse.width && cutout.height == diffuse.height && cutout.pixels == diffuse.pixels)) {
        t.bytes = encodePng(shape, mask);
        return t;
    }
    // Colour (white without one) with the cut-out's coverage as alpha, the cut-out read at the nearest texel.
    ImageRgba rgba = diffuse.empty() ? ImageRgba(cutout.width, cutout.height, glm::vec4(1.0f)) : diffuse;
    for (int y = 0; y < rgba.height; ++y)
        for (int x = 0; x < rgba.width; ++x) {
            const int cx = std::min(cutout.width - 1, int((double(x) + 0.5) * cutout.width / rgba.width));
            const int cy = std::min(cutout.height - 1, int((double(y) + 0.5) * cutout.height / rgba.height));
            rgba.at(x, y)[3] = cutout.at(cx, cy)[3];
        }
    t.bytes = encodePng(rgba, true);
    return t;
}

// The materials' alpha modes and bytes an export of species s writes (per material used by a triangle).
std::vector<bool> usedMaterials(const TriangleMesh& mesh)
{
    std::vector<bool> used(std::max<size_t>(mesh.materials.size(), 1), false);
    if (mesh.triangleMaterial.empty()) used[0] = true;
    for (uint32_t m : mesh.triangleMaterial) used[std::min<size_t>(m, used.size() - 1)] = true;
    return used;
}

double meshBytes(const TriangleMesh& mesh)
{
    return double(mesh.positions.size()) * (12.0 + (mesh.normals.empty() ? 0.0 : 12.0) + (mesh.uvs.empty() ? 0.0 : 8.0)) +
           double(mesh.triangles.size()) * 12.0;
}

glm::vec3 unitNormal(glm::vec3 n)
{
    const float l = glm::length(n);
    return l > 1e-20f && std::isfinite(l) ? n / l : glm::vec3(0.0f, 1.0f, 0.0f);
}

int addMaterial(GlbBuilder& g, const QJsonObject& m)
{
    QJsonArray a = g.json.value("materials").toArray();
    a.append(m);
    g.json.insert("materials", a);
    return int(a.size()) - 1;
}

int addTo(GlbBuilder& g, const char* array, const QJsonObject& o)
{
    QJsonArray a = g.json.value(QLatin1String(array)).toArray();
    a.append(o);
    g.json.insert(QLatin1String(array), a);
    return int(a.size()) - 1;
}

// Species s's mesh (one primitive per material) and materials; returns the mesh index.
int addSpeciesMesh(GlbBuilder& g, const SpeciesDesc& sp, const SpeciesAssets& a, size_t s, std::map<std::string, int>& textures)
{
    const TriangleMesh& mesh = a.mesh;
    if (mesh.positions.empty() || mesh.triangles.empty()) throw Error("glTF export: species '" + sp.name + "' has no triangles");
    QJsonObject attributes;
    attributes.insert("POSITION", g.addFloats(&mesh.positions[0].x, mesh.positions.size(), "VEC3", gltf::kArrayBuffer, true));
    if (mesh.normals.size() == mesh.positions.size()) {
        std::vector<glm::vec3> n(mesh.normals.size());
        for (size_t i = 0; i < n.size(); ++i) n[i] = unitNormal(mesh.normals[i]);
        attributes.insert("NORMAL", g.addFloats(&n[0].x, n.size(), "VEC3", gltf::kArrayBuffer));
    }
    const bool uvs = mesh.uvs.size() == mesh.positions.size();
    if (uvs) {
        std::vector<glm::vec2> uv(mesh.uvs.size());
        for (size_t i = 0; i < uv.size(); ++i) uv[i] = glm::vec2(mesh.uvs[i].x, 1.0f - mesh.uvs[i].y);   // OBJ's v up, glTF's down
        attributes.insert("TEXCOORD_0", g.addFloats(&uv[0].x, uv.size(), "VEC2", gltf::kArrayBuffer));
    }
    const std::vector<bool> used = usedMaterials(mesh);
    QJsonArray primitives;
    for (size_t m = 0; m < used.size(); ++m) {
        if (!used[m]) continue;
        std::vector<uint32_t> idx;
        for (size_t t = 0; t < mesh.triangles.size(); ++t) {
            const size_t tm = mesh.triangleMaterial.empty() ? 0 : std::min<size_t>(mesh.triangleMaterial[t], used.size() - 1);
            if (tm != m) continue;
            for (int c = 0; c < 3; ++c) idx.push_back(mesh.triangles[t][c]);
        }
        QJsonObject material;
        QJsonObject pbr{{"metallicFactor", 0.0}, {"roughnessFactor", 1.0}};
        bool leaf = false;
        std::string name = sp.name;
        glm::vec3 base(0.8f);
        if (m < mesh.materials.size()) {
            const Material& mat = mesh.materials[m];
            leaf = mat.isLeaf;
            base = mat.diffuse;
            name += "/" + mat.name;
            if (uvs) {
                TextureBytes tex = textureFor(a, s, m, true);
                if (!tex.bytes.isEmpty()) {
                    auto it = textures.find(tex.key);
                    if (it == textures.end()) {
                        const int image = g.addImage(tex.bytes, tex.mime);
                        it = textures.emplace(tex.key, addTo(g, "textures", QJsonObject{{"source", image}, {"sampler", 0}})).first;
                    }
                    pbr.insert("baseColorTexture", QJsonObject{{"index", it->second}});
                    if (m < a.cutout.size() && !a.cutout[m].empty() && hasClearTexels(a.cutout[m])) {
                        material.insert("alphaMode", "MASK");
                        material.insert("alphaCutoff", double(kCutoutThreshold));   // the renderer's cut-out threshold
                    }
                }
            }
        }
        pbr.insert("baseColorFactor", QJsonArray{double(base.x), double(base.y), double(base.z), 1.0});
        material.insert("name", QString::fromStdString(name));
        material.insert("pbrMetallicRoughness", pbr);
        if (leaf) material.insert("doubleSided", true);
        const int mi = addMaterial(g, material);
        primitives.append(QJsonObject{{"attributes", attributes}, {"indices", g.addIndices(idx.data(), idx.size())}, {"material", mi}});
    }
    return addTo(g, "meshes", QJsonObject{{"name", QString::fromStdString(sp.name)}, {"primitives", primitives}});
}

// A mesh of one primitive (positions with bounds, normals, optional vertex colours) in one material.
int addPlainMesh(GlbBuilder& g, const char* name, const std::vector<glm::vec3>& pos, const std::vector<glm::vec3>& nrm,
                 const std::vector<glm::vec4>& colors, const std::vector<uint32_t>& idx, const QJsonObject& material)
{
    QJsonObject attributes{{"POSITION", g.addFloats(&pos[0].x, pos.size(), "VEC3", gltf::kArrayBuffer, true)},
                           {"NORMAL", g.addFloats(&nrm[0].x, nrm.size(), "VEC3", gltf::kArrayBuffer)}};
    if (!colors.empty()) attributes.insert("COLOR_0", g.addFloats(&colors[0].x, colors.size(), "VEC4", gltf::kArrayBuffer));
    const int mi = addMaterial(g, material);
    const QJsonObject prim{{"attributes", attributes}, {"indices", g.addIndices(idx.data(), idx.size())}, {"material", mi}};
    return addTo(g, "meshes", QJsonObject{{"name", name}, {"primitives", QJsonArray{prim}}});
}

QJsonObject plainMaterial(const char* name, const glm::vec3& color)
{
    return QJsonObject{{"name", name},
                       {"pbrMetallicRoughness", QJsonObject{{"baseColorFactor", QJsonArray{double(color.x), double(color.y), double(color.z), 1.0}},
                                                            {"metallicFactor", 0.0},
                                                            {"roughnessFactor", 1.0}}}};
}

// The terrain's samples in the region, every step-th above kGltfTerrainMaxSamples a side, triangulated as the
// renderer splits its cells; vertex colours by its colour rule (snow above the snow line, rock on steep slopes,
// else the ground colour).
int addTerrainMesh(GlbBuilder& g, const Scene& scene, const GltfExportOptions& o)
{
    const TerrainDesc& t = scene.terrain;
    uint32_t r[4];
    if (!terrainRange(scene, o, r)) return -1;
    const std::vector<uint32_t> is = terrainSamples(r[0], r[2]), js = terrainSamples(r[1], r[3]);
    const HeightFieldLayout& L = t.field->layout;
    const size_t nx = is.size(), nz = js.size();
    std::vector<glm::vec3> pos(nx * nz), nrm(nx * nz);
    std::vector<glm::vec4> col(nx * nz);
    auto at = [&](size_t a, size_t b) { return glm::dvec3(double(is[a]) * double(L.dx), double(t.field->at(is[a], js[b])), double(js[b]) * double(L.dz)); };
    const float snowY = terrainSnowY(t), rockCos = terrainRockCos(t);
    for (size_t b = 0; b < nz; ++b)
        for (size_t a = 0; a < nx; ++a) {
            const glm::dvec3 p = at(a, b);
            pos[b * nx + a] = glm::vec3(t.origin + p);
            const glm::dvec3 ddx = at(std::min(a + 1, nx - 1), b) - at(a > 0 ? a - 1 : 0, b);
            const glm::dvec3 ddz = at(a, std::min(b + 1, nz - 1)) - at(a, b > 0 ? b - 1 : 0);
            const glm::vec3 n = unitNormal(glm::vec3(glm::cross(ddz, ddx)));
            nrm[b * nx + a] = n;
            col[b * nx + a] = glm::vec4(terrainAlbedo(float(p.y), n.y, snowY, rockCos, t.snow, t.rock, scene.ground.color), 1.0f);
        }
    std::vector<uint32_t> idx;
    idx.reserve((nx - 1) * (nz - 1) * 6);
    for (size_t b = 0; b + 1 < nz; ++b)
        for (size_t a = 0; a + 1 < nx; ++a) {
            const uint32_t p00 = uint32_t(b * nx + a), p10 = p00 + 1, p01 = uint32_t((b + 1) * nx + a), p11 = p01 + 1;
            for (uint32_t v : {p00, p11, p10, p00, p01, p11}) idx.push_back(v);   // the renderer's (p00, p11, p10), (p00, p01, p11)
        }
    return addPlainMesh(g, "terrain", pos, nrm, col, idx, plainMaterial("terrain", glm::vec3(1.0f)));
}

// The ground plane as a quad: the region, or the instances' box (their meshes' boxes placed) grown by 10% of its
// longer side and at least 10 m.
int addGroundMesh(GlbBuilder& g, const Scene& scene, const GltfExportOptions& o, const std::vector<Bounds3>& boxes,
                  const std::vector<std::vector<GltfInstance>>& perSpecies)
{
    double x0 = -50.0, z0 = -50.0, x1 = 50.0, z1 = 50.0;
    if (o.region) {
        x0 = (*o.region)[0], z0 = (*o.region)[1], x1 = (*o.region)[2], z1 = (*o.region)[3];
    } else {
        double lo[2] = {1e300, 1e300}, hi[2] = {-1e300, -1e300};
        for (size_t s = 0; s < perSpecies.size(); ++s) {
            const Bounds3& b = boxes[s];
            const double reach = b.valid() ? glm::length(glm::dvec3(glm::max(glm::abs(b.lo), glm::abs(b.hi)))) : 0.0;
            for (const GltfInstance& in : perSpecies[s]) {
                const double rr = reach * in.scale;
                lo[0] = std::min(lo[0], in.translation.x - rr), hi[0] = std::max(hi[0], in.translation.x + rr);
                lo[1] = std::min(lo[1], in.translation.z - rr), hi[1] = std::max(hi[1], in.translation.z + rr);
            }
        }
        if (lo[0] <= hi[0]) {
            const double margin = std::max(10.0, 0.1 * std::max(hi[0] - lo[0], hi[1] - lo[1]));
            x0 = lo[0] - margin, z0 = lo[1] - margin, x1 = hi[0] + margin, z1 = hi[1] + margin;
        }
    }
    const float y = float(scene.ground.height);
    const std::vector<glm::vec3> pos{{float(x0), y, float(z0)}, {float(x1), y, float(z0)}, {float(x0), y, float(z1)}, {float(x1), y, float(z1)}};
    const std::vector<glm::vec3> nrm(4, glm::vec3(0.0f, 1.0f, 0.0f));
    return addPlainMesh(g, "ground", pos, nrm, {}, {0, 3, 1, 0, 2, 3}, plainMaterial("ground", scene.ground.color));
}

std::string megabytes(double bytes)
{
    char buf[64];
    std::snprintf(buf, sizeof buf, bytes < 1e6 ? "%.2f MB" : "%.1f MB", bytes / 1e6);
    return buf;
}

std::string limitMessage(const GltfPlan& plan)
{
    char buf[256];
    std::snprintf(buf, sizeof buf, " is above the export's limit (%zu instances, %s); export a smaller region, or force it", plan.instanceLimit,
                  megabytes(plan.byteLimit).c_str());
    return "glTF export: " + plan.summary() + buf;
}

} // namespace

void forEachGltfInstance(const Scene& sceneIn, const std::vector<Bounds3>& speciesBoxes, const GltfExportOptions& options,
                         const std::function<void(uint32_t species, const GltfInstance& instance)>& visit)
{
    Scene lifted;
    const Scene& scene = sceneOnTerrain(sceneIn, lifted);
    for (const InstanceDesc& d : scene.instances) visitInstance(scene, d, Placement{}, 0, options, visit);
    if (hasLandscape(scene)) visitLandscape(scene, speciesBoxes, options, visit);
}

std::vector<Bounds3> speciesMeshBoxes(const std::vector<SpeciesAssets>& assets)
{
    std::vector<Bounds3> out;
    for (const SpeciesAssets& a : assets) out.push_back(meshBounds(a.mesh));
    return out;
}

std::string GltfPlan::summary() const
{
    std::string s = std::to_string(instances) + (instances == 1 ? " instance" : " instances");
    if (landscapePlants > 0) s += " (" + std::to_string(landscapePlants) + " landscape plants)";
    return s + ", about " + megabytes(estimatedBytes);
}

GltfPlan planGltfExport(const Scene& scene, const std::vector<SpeciesAssets>& assets, const GltfExportOptions& options)
{
    if (assets.size() != scene.species.size()) throw Error("glTF export: the species' meshes are not loaded");
    GltfPlan plan;
    plan.instanceLimit = options.instanceLimit;
    plan.byteLimit = options.byteLimit;
    plan.perSpecies.assign(scene.species.size(), 0);
    size_t own = 0;
    forEachGltfInstance(scene, speciesMeshBoxes(assets), options, [&](uint32_t sp, const GltfInstance& in) {
        ++plan.perSpecies[sp];
        own += in.landscape ? 0 : 1;
    });
    double bytes = 4096.0;   // the JSON
    for (size_t s = 0; s < plan.perSpecies.size(); ++s) {
        plan.instances += plan.perSpecies[s];
        if (plan.perSpecies[s] == 0) continue;
        bytes += meshBytes(assets[s].mesh) + 40.0 * double(plan.perSpecies[s]) + 512.0;
        std::map<std::string, double> textures;
        const std::vector<bool> used = usedMaterials(assets[s].mesh);
        for (size_t m = 0; m < assets[s].mesh.materials.size() && !assets[s].mesh.uvs.empty(); ++m) {
            if (!used[m]) continue;
            const TextureBytes t = textureFor(assets[s], s, m, false);
            if (!t.key.empty()) textures[t.key] = t.estimate;
        }
        for (const auto& [key, b] : textures) bytes += b;
    }
    plan.landscapePlants = plan.instances - own;
    if (scene.terrain.enabled() && scene.terrain.field) {
        uint32_t r[4];
        if (terrainRange(scene, options, r)) {
            plan.terrainSamplesX = terrainSamples(r[0], r[2]).size();
            plan.terrainSamplesZ = terrainSamples(r[1], r[3]).size();
            bytes += double(plan.terrainSamplesX * plan.terrainSamplesZ) * 40.0 +
                     double((plan.terrainSamplesX - 1) * (plan.terrainSamplesZ - 1)) * 24.0;
        }
    }
    plan.estimatedBytes = bytes;
    return plan;
}

GltfPlan exportGltf(const Scene& scene, const std::vector<SpeciesAssets>& assets, const std::string& path, const GltfExportOptions& options,
                    Progress* progress)
{
    if (lowerExtension(path) != ".glb") throw Error(path + ": a glTF export is a .glb file");
    if (progress) progress->report(0.0, "counting instances");
    const GltfPlan plan = planGltfExport(scene, assets, options);
    if (plan.overLimit() && !options.force) throw Error(limitMessage(plan));
    if (plan.estimatedBytes > 4.0 * 1024 * 1024 * 1024) throw Error("glTF export: " + plan.summary() + " does not fit in a .glb (4 GiB at most)");

    if (progress) progress->report(0.05, "placing instances");
    const std::vector<Bounds3> boxes = speciesMeshBoxes(assets);
    std::vector<std::vector<GltfInstance>> perSpecies(scene.species.size());
    for (size_t s = 0; s < perSpecies.size(); ++s) perSpecies[s].reserve(plan.perSpecies[s]);
    forEachGltfInstance(scene, boxes, options, [&](uint32_t s, const GltfInstance& in) { perSpecies[s].push_back(in); });

    GlbBuilder g;
    g.json.insert("asset", QJsonObject{{"version", "2.0"}, {"generator", QStringLiteral("Sylva %1").arg(QLatin1String(versionString()))}});
    g.json.insert("extensionsUsed", QJsonArray{"EXT_mesh_gpu_instancing"});
    g.json.insert("extensionsRequired", QJsonArray{"EXT_mesh_gpu_instancing"});
    g.json.insert("samplers", QJsonArray{QJsonObject{{"magFilter", 9729}, {"minFilter", 9987}, {"wrapS", 10497}, {"wrapT", 10497}}});
    QJsonArray nodes;
    std::map<std::string, int> textures;
    for (size_t s = 0; s < perSpecies.size(); ++s) {
        if (progress) progress->report(0.1 + 0.8 * double(s) / double(perSpecies.size()), scene.species[s].name);   // throws Cancelled
        const std::vector<GltfInstance>& list = perSpecies[s];
        if (list.empty()) continue;
        const int mesh = addSpeciesMesh(g, scene.species[s], assets[s], s, textures);
        std::vector<glm::vec3> tr(list.size()), sc(list.size());
        std::vector<glm::vec4> ro(list.size());
        for (size_t i = 0; i < list.size(); ++i) {
            tr[i] = glm::vec3(list[i].translation);
            const glm::vec4 q(float(list[i].rotation.x), float(list[i].rotation.y), float(list[i].rotation.z), float(list[i].rotation.w));
            ro[i] = q / glm::length(q);   // unit in float32 too
            sc[i] = glm::vec3(float(list[i].scale));
        }
        const QJsonObject attributes{{"TRANSLATION", g.addFloats(&tr[0].x, tr.size(), "VEC3", 0, true)},
                                     {"ROTATION", g.addFloats(&ro[0].x, ro.size(), "VEC4", 0)},
                                     {"SCALE", g.addFloats(&sc[0].x, sc.size(), "VEC3", 0)}};
        nodes.append(QJsonObject{{"name", QString::fromStdString(scene.species[s].name)},
                                 {"mesh", mesh},
                                 {"extensions", QJsonObject{{"EXT_mesh_gpu_instancing", QJsonObject{{"attributes", attributes}}}}}});
    }
    if (progress) progress->report(0.9, "ground");
    if (scene.terrain.enabled() && scene.terrain.field) {
        const int mesh = addTerrainMesh(g, scene, options);
        if (mesh >= 0) nodes.append(QJsonObject{{"name", "terrain"}, {"mesh", mesh}});
    } else if (groundPlaneShown(scene)) {
        nodes.append(QJsonObject{{"name", "ground"}, {"mesh", addGroundMesh(g, scene, options, boxes, perSpecies)}});
    }
    if (textures.empty()) g.json.remove("samplers");
    QJsonArray roots;
    for (qsizetype n = 0; n < nodes.size(); ++n) roots.append(int(n));
    g.json.insert("nodes", nodes);
    g.json.insert("scenes", QJsonArray{QJsonObject{{"nodes", roots}}});
    g.json.insert("scene", 0);
    const QByteArray bytes = g.glb();
    AtomicFile file(path, AtomicFile::Sync::Yes, "glTF file");
    file.write(bytes.constData(), size_t(bytes.size()));
    file.commit();
    if (progress) progress->report(1.0, "written");
    GltfPlan written = plan;
    written.estimatedBytes = double(bytes.size());
    return written;
}

std::array<double, 4> parseGltfRegion(const std::string& text)
{
    std::array<double, 4> r{};
    std::stringstream in(text);
    std::string part;
    int n = 0;
    while (std::getline(in, part, ',')) {
        if (n >= 4) throw Error("region '" + text + "': expected x0,z0,x1,z1 (four numbers, metres)");
        size_t used = 0;
        try {
            r[size_t(n)] = std::stod(part, &used);
        } catch (const std::exception&) {
            used = 0;
        }
        if (used == 0 || used != part.size() || !std::isfinite(r[size_t(n)])) throw Error("region '" + text + "': '" + part + "' is not a number");
        ++n;
    }
    if (n != 4) throw Error("region '" + text + "': expected x0,z0,x1,z1 (four numbers, metres)");
    if (!(r[0] < r[2]) || !(r[1] < r[3])) throw Error("region '" + text + "': expected x0 < x1 and z0 < z1");
    return r;
}

} // namespace sylva
