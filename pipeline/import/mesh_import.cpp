// Mesh import through Assimp: flatten the scene graph, clean up with OpenMesh, split leaf and wood.
#include "pipeline/import/mesh_import.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>
#include <utility>

#include <assimp/GltfMaterial.h>
#include <assimp/Importer.hpp>
#include <assimp/commonMetaData.h>
#include <assimp/material.h>
#include <assimp/metadata.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include "core/base/error.h"
#include "pipeline/import/mesh_cleanup.h"
#include "pipeline/io/image_io.h"

namespace sylva {

namespace fs = std::filesystem;

namespace {

std::string lower(std::string s)
{
    std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return char(std::tolower(c)); });
    return s;
}

bool nameSaysLeaf(const std::string& name)
{
    const std::string n = lower(name);
    for (const char* word : {"leaf", "leaves", "foliage", "needle"})
        if (n.find(word) != std::string::npos) return true;
    return false;
}

// Refuses what Assimp would only fail on with a vaguer message.
void checkReadable(const std::string& path)
{
    std::error_code ec;
    const auto status = fs::status(path, ec);
    if (!fs::exists(status)) throw Error(path + ": no such file");
    if (fs::is_directory(status)) throw Error(path + ": is a folder, not a mesh file");
    std::ifstream in(path, std::ios::binary);
    if (!in) throw Error(path + ": cannot open the file for reading");
    if (in.peek() == std::ifstream::traits_type::eof()) throw Error(path + ": the file is empty");

    // Assimp 5.2's PLY reader loops forever on a header without a clean "end_header" line, and for
    // a very long time on element counts no file of this size can hold (each takes at least a byte).
    char magic[4] = {};
    in.read(magic, 4);
    if (std::string(magic, 3) == "ply" && (magic[3] == '\n' || magic[3] == '\r')) {
        const uintmax_t fileSize = fs::file_size(path, ec);
        in.clear();
        in.seekg(0);
        std::string line;
        bool ended = false;
        uintmax_t declared = 0;
        for (size_t read = 0; !ended && read < (size_t(1) << 20) && std::getline(in, line); read += line.size() + 1) {
            while (!line.empty() && std::isspace(static_cast<unsigned char>(line.back()))) line.pop_back();
            ended = line == "end_header";
            std::istringstream words(line);
            std::string keyword, name, count;
            if (words >> keyword >> name >> count && keyword == "element")
                declared += std::strtoull(count.c_str(), nullptr, 10);
        }
        if (!ended) throw Error(path + ": PLY header has no end_header line");
        if (!ec && declared > fileSize)
            throw Error(path + ": PLY header declares " + std::to_string(declared) + " elements, more than the file can hold");
    }
}

// Structural checks Assimp's validation misses (a PLY face can come back with no vertices) and that
// its triangulation would assert on (abort) rather than report.
void checkScene(const aiScene& scene, const std::string& path)
{
    if (!scene.mRootNode || scene.mNumMeshes == 0) throw Error(path + ": the file holds no meshes");
    for (unsigned m = 0; m < scene.mNumMeshes; ++m) {
        const aiMesh* mesh = scene.mMeshes[m];
        if (!mesh || (mesh->mNumVertices > 0 && !mesh->mVertices) || (mesh->mNumFaces > 0 && !mesh->mFaces))
            throw Error(path + ": mesh " + std::to_string(m) + " is malformed");
        if (mesh->mMaterialIndex >= scene.mNumMaterials) throw Error(path + ": a mesh refers to a missing material");
        for (unsigned f = 0; f < mesh->mNumFaces; ++f) {
            const aiFace& face = mesh->mFaces[f];
            if (face.mNumIndices == 0 || !face.mIndices)
                throw Error(path + ": face " + std::to_string(f) + " of mesh " + std::to_string(m) + " has no vertices");
            for (unsigned c = 0; c < face.mNumIndices; ++c)
                if (face.mIndices[c] >= mesh->mNumVertices)
                    throw Error(path + ": face " + std::to_string(f) + " of mesh " + std::to_string(m) +
                                " refers to a missing vertex");
        }
    }
    std::vector<const aiNode*> stack{scene.mRootNode};
    while (!stack.empty()) {
        const aiNode* node = stack.back();
        stack.pop_back();
        for (unsigned i = 0; i < node->mNumMeshes; ++i)
            if (node->mMeshes[i] >= scene.mNumMeshes) throw Error(path + ": a node refers to a missing mesh");
        for (unsigned c = 0; c < node->mNumChildren; ++c)
            if (node->mChildren[c]) stack.push_back(node->mChildren[c]);
    }
}

const aiScene* readScene(Assimp::Importer& importer, const std::string& path)
{
    auto failed = [&](const std::string& why) {
        if (why.find("mNumMeshes is 0") != std::string::npos) return Error(path + ": the file holds no meshes");
        return Error(path + ": cannot read the mesh (" + (why.empty() ? std::string("unknown reason") : why) + ")");
    };
    // No aiProcess_RemoveRedundantMaterials (it merges identical-looking bark and leaf materials),
    // no JoinIdenticalVertices / FindDegenerates / FindInvalidData: our clean-up does and counts those.
    // Triangulation (ear clipping, right for concave polygons) runs only once the scene is checked.
    const aiScene* scene = nullptr;
    try {
        scene = importer.ReadFile(path, aiProcess_ValidateDataStructure);
        if (!scene) throw failed(importer.GetErrorString());
        checkScene(*scene, path);
        scene = importer.ApplyPostProcessing(aiProcess_Triangulate);
        if (!scene) throw failed(importer.GetErrorString());
    } catch (const Error&) {
        throw;
    } catch (const std::exception& e) {
        throw failed(e.what());
    }
    checkScene(*scene, path);
    return scene;
}

glm::vec3 toGlm(const aiVector3D& v) { return {v.x, v.y, v.z}; }

// Metres per file unit. FBX lengths are in UnitScaleFactor centimetres (Blender writes 1: cm, with
// a x100 object scale); COLLADA's <unit> Assimp applies itself; glTF is metres; OBJ/PLY have no unit.
float metresPerUnit(const aiScene& scene, const std::string& path)
{
    if (!scene.mMetaData) return 1.0f;
    aiString format;
    const bool fbx = (scene.mMetaData->Get(AI_METADATA_SOURCE_FORMAT, format) &&
                      lower(format.C_Str()).find("fbx") != std::string::npos) ||
                     lower(fs::path(path).extension().string()) == ".fbx";
    if (!fbx) return 1.0f;
    float unitF = 0.0f;
    double unitD = 0.0;
    double unit = 1.0;
    if (scene.mMetaData->Get("UnitScaleFactor", unitF)) unit = unitF;
    else if (scene.mMetaData->Get("UnitScaleFactor", unitD)) unit = unitD;
    return std::isfinite(unit) && unit > 0.0 ? float(unit * 0.01) : 0.01f;
}

// Flattens every mesh instance of the node tree into one polygon soup in the file's (root) frame.
PolygonSoup flattenScene(const aiScene& scene, const std::string& path, ImportReport& report)
{
    // Normals only when every instanced mesh has them (else all are computed, consistently);
    // uvs when any mesh has them (meshes without get 0,0).
    bool allNormals = true, anyUvs = false, someWithoutUvs = false;
    aiMatrix4x4 toMetres;
    aiMatrix4x4::Scaling(aiVector3D(metresPerUnit(scene, path)), toMetres);
    std::vector<std::pair<const aiNode*, aiMatrix4x4>> stack{{scene.mRootNode, toMetres * scene.mRootNode->mTransformation}};
    std::vector<std::pair<const aiMesh*, aiMatrix4x4>> instances;
    while (!stack.empty()) {
        auto [node, transform] = stack.back();
        stack.pop_back();
        for (unsigned i = 0; i < node->mNumMeshes; ++i) {
            const aiMesh* mesh = scene.mMeshes[node->mMeshes[i]];
            instances.emplace_back(mesh, transform);
            allNormals = allNormals && mesh->HasNormals();
            anyUvs = anyUvs || mesh->HasTextureCoords(0);
            someWithoutUvs = someWithoutUvs || !mesh->HasTextureCoords(0);
        }
        for (unsigned c = 0; c < node->mNumChildren; ++c)
            stack.emplace_back(node->mChildren[c], transform * node->mChildren[c]->mTransformation);
    }
    if (anyUvs && someWithoutUvs) report.warnings.push_back(path + ": some meshes have no texture coordinates (set to 0,0)");

    PolygonSoup soup;
    std::vector<uint32_t> face;
    for (const auto& [mesh, transform] : instances) {
        const size_t base = soup.positions.size();
        if (base + mesh->mNumVertices > std::numeric_limits<uint32_t>::max())
            throw Error(path + ": too many vertices for 32-bit indices");
        const aiMatrix3x3 linear(transform);
        const bool mirrored = linear.Determinant() < 0.0f;
        aiMatrix3x3 normalMatrix = linear;
        normalMatrix.Inverse().Transpose();  // a singular transform gives NaN normals: recomputed later
        for (unsigned v = 0; v < mesh->mNumVertices; ++v) {
            soup.positions.push_back(toGlm(transform * mesh->mVertices[v]));
            if (allNormals) soup.normals.push_back(toGlm(normalMatrix * mesh->mNormals[v]));
            if (anyUvs)
                soup.uvs.push_back(mesh->HasTextureCoords(0)
                                       ? glm::vec2(mesh->mTextureCoords[0][v].x, mesh->mTextureCoords[0][v].y)
                                       : glm::vec2(0.0f));
        }
        for (unsigned f = 0; f < mesh->mNumFaces; ++f) {
            const aiFace& in = mesh->mFaces[f];
            face.clear();
            for (unsigned c = 0; c < in.mNumIndices; ++c) face.push_back(uint32_t(base + in.mIndices[c]));
            if (mirrored) std::reverse(face.begin(), face.end());  // keep counter-clockwise = front
            soup.addFace(face.data(), face.size(), mesh->mMaterialIndex);
        }
    }
    return soup;
}

// Finds a texture file named by a material: relative to the mesh folder, then with '\' read as '/',
// then by its bare file name in the mesh folder (files exported on another machine). Empty if none.
std::string resolveTexture(const aiMaterial& material, aiTextureType type, const fs::path& meshDir,
                           const std::string& path, const std::string& materialName, ImportReport& report)
{
    aiString ref;
    if (material.GetTextureCount(type) == 0 || material.GetTexture(type, 0, &ref) != AI_SUCCESS) return {};
    std::string name = ref.C_Str();
    if (name.empty()) return {};
    if (name[0] == '*') {
        report.warnings.push_back(path + ": material '" + materialName + "' uses an embedded texture (" + name +
                                  "), which is not extracted");
        return {};
    }
    if (name.rfind("file://", 0) == 0) name = name.substr(7);
    std::string slashed = name;
    std::replace(slashed.begin(), slashed.end(), '\\', '/');
    const fs::path candidates[] = {meshDir / fs::path(name), meshDir / fs::path(slashed),
                                   meshDir / fs::path(slashed).filename()};
    for (const fs::path& candidate : candidates) {
        std::error_code ec;
        if (fs::is_regular_file(candidate, ec)) return candidate.lexically_normal().string();
    }
    report.warnings.push_back(path + ": material '" + materialName + "' refers to texture '" + name +
                              "', which does not exist (" + candidates[0].lexically_normal().string() + ")");
    return {};
}

Material convertMaterial(const aiMaterial& in, size_t index, const fs::path& meshDir, const std::string& path,
                         const ImportOptions& options, ImportReport& report)
{
    Material m;
    aiString name;
    if (in.Get(AI_MATKEY_NAME, name) == AI_SUCCESS) m.name = name.C_Str();
    if (m.name.empty()) m.name = "material " + std::to_string(index);

    aiColor3D colour;
    aiColor4D baseColour;
    if (in.Get(AI_MATKEY_COLOR_DIFFUSE, colour) == AI_SUCCESS)
        m.diffuse = {colour.r, colour.g, colour.b};
    else if (in.Get(AI_MATKEY_BASE_COLOR, baseColour) == AI_SUCCESS)
        m.diffuse = {baseColour.r, baseColour.g, baseColour.b};
    if (in.Get(AI_MATKEY_COLOR_SPECULAR, colour) == AI_SUCCESS) m.specular = {colour.r, colour.g, colour.b};
    float shininess = 0.0f;
    if (in.Get(AI_MATKEY_SHININESS, shininess) == AI_SUCCESS && shininess > 0.0f) m.shininess = shininess;

    m.diffuseTexture = resolveTexture(in, aiTextureType_DIFFUSE, meshDir, path, m.name, report);
    if (m.diffuseTexture.empty() && in.GetTextureCount(aiTextureType_DIFFUSE) == 0)
        m.diffuseTexture = resolveTexture(in, aiTextureType_BASE_COLOR, meshDir, path, m.name, report);
    m.alphaTexture = resolveTexture(in, aiTextureType_OPACITY, meshDir, path, m.name, report);

    if (!options.leafMaterials.empty()) {
        const std::string n = lower(m.name);
        m.isLeaf = std::any_of(options.leafMaterials.begin(), options.leafMaterials.end(),
                               [&](const std::string& leaf) { return lower(leaf) == n; });
        return m;
    }
    // An opacity map marks cut-out foliage even when its file is missing; a diffuse image with an
    // alpha channel does too; so does the name. glTF's alphaMode MASK is the same cut-out.
    bool leaf = in.GetTextureCount(aiTextureType_OPACITY) > 0 || nameSaysLeaf(m.name);
    aiString alphaMode;
    if (!leaf && in.Get(AI_MATKEY_GLTF_ALPHAMODE, alphaMode) == AI_SUCCESS && std::string(alphaMode.C_Str()) == "MASK")
        leaf = true;
    if (!leaf && !m.diffuseTexture.empty()) {
        try {
            leaf = imageHasAlpha(m.diffuseTexture);
        } catch (const Error& e) {
            report.warnings.push_back(path + ": material '" + m.name + "': " + e.what());
        }
    }
    m.isLeaf = leaf;
    return m;
}

} // namespace

TriangleMesh importMesh(const std::string& path, const ImportOptions& options, ImportReport* reportOut)
{
    ImportReport report;
    checkReadable(path);
    Assimp::Importer importer;
    const aiScene* scene = readScene(importer, path);
    if (scene->mFlags & AI_SCENE_FLAGS_INCOMPLETE)
        report.warnings.push_back(path + ": Assimp marked the scene incomplete; importing what it read");

    const PolygonSoup soup = flattenScene(*scene, path, report);
    CleanupOptions cleanupOptions;
    cleanupOptions.weld = options.weld;
    CleanupStats stats;
    TriangleMesh mesh = cleanupMesh(soup, cleanupOptions, &stats);
    report.inputTriangles = stats.inputTriangles;
    report.droppedDegenerate = stats.droppedDegenerate;
    report.droppedNonFinite = stats.droppedNonFinite;
    report.weldedVertices = stats.weldedVertices;
    if (stats.ignoredPrimitives > 0)
        report.warnings.push_back(path + ": ignored " + std::to_string(stats.ignoredPrimitives) + " points and lines");
    if (!soup.normals.empty() && stats.recomputedNormals > 0)
        report.warnings.push_back(path + ": " + std::to_string(stats.recomputedNormals) +
                                  " vertex normals in the file were invalid and were recomputed");
    if (stats.inputTriangles == 0) throw Error(path + ": the file holds no triangles or polygons");
    if (mesh.triangles.empty())
        throw Error(path + ": no triangles left after clean-up (" + std::to_string(stats.inputTriangles) +
                    " in the file: " + std::to_string(stats.droppedDegenerate) + " degenerate, " +
                    std::to_string(stats.droppedNonFinite) + " with non-finite coordinates)");

    // Keep the materials the triangles use, in file order, each converted on its own (never merged).
    const fs::path meshDir = fs::absolute(fs::path(path)).parent_path();
    std::vector<uint32_t> remap(scene->mNumMaterials, std::numeric_limits<uint32_t>::max());
    for (uint32_t m : mesh.triangleMaterial) remap[m] = 0;
    for (unsigned i = 0; i < scene->mNumMaterials; ++i) {
        if (remap[i] == 0) {
            remap[i] = uint32_t(mesh.materials.size());
            mesh.materials.push_back(convertMaterial(*scene->mMaterials[i], i, meshDir, path, options, report));
        }
    }
    for (uint32_t& m : mesh.triangleMaterial) m = remap[m];
    for (const std::string& leaf : options.leafMaterials) {
        const bool found = std::any_of(mesh.materials.begin(), mesh.materials.end(),
                                       [&](const Material& m) { return lower(m.name) == lower(leaf); });
        if (!found) report.warnings.push_back(path + ": leaf material '" + leaf + "' is not a material of the mesh");
    }
    for (size_t t = 0; t < mesh.triangleCount(); ++t) (mesh.isLeafTriangle(t) ? report.leafTriangles : report.woodTriangles)++;

    if (reportOut) *reportOut = std::move(report);
    return mesh;
}

std::string describeMesh(const TriangleMesh& mesh)
{
    std::vector<size_t> perMaterial(mesh.materials.size(), 0);
    size_t leaf = 0;
    for (size_t t = 0; t < mesh.triangleCount(); ++t) {
        if (t < mesh.triangleMaterial.size() && mesh.triangleMaterial[t] < perMaterial.size())
            ++perMaterial[mesh.triangleMaterial[t]];
        if (mesh.isLeafTriangle(t)) ++leaf;
    }
    std::ostringstream s;
    s << "triangles: " << mesh.triangleCount() << " (leaf " << leaf << ", wood " << mesh.triangleCount() - leaf << ")\n";
    s << "vertices:  " << mesh.positions.size() << (mesh.normals.empty() ? "" : ", normals")
      << (mesh.uvs.empty() ? "" : ", uvs") << "\n";
    const Bounds3 b = meshBounds(mesh);
    char line[256];
    if (b.valid()) {
        const glm::vec3 e = b.extent();
        std::snprintf(line, sizeof line, "bounds:    (%g, %g, %g) .. (%g, %g, %g), size %g x %g x %g\n", b.lo.x, b.lo.y,
                      b.lo.z, b.hi.x, b.hi.y, b.hi.z, e.x, e.y, e.z);
        s << line;
    } else {
        s << "bounds:    empty\n";
    }
    s << "materials: " << mesh.materials.size() << "\n";
    for (size_t i = 0; i < mesh.materials.size(); ++i) {
        const Material& m = mesh.materials[i];
        std::snprintf(line, sizeof line, "%s, %zu triangles, diffuse (%.3g, %.3g, %.3g)", m.isLeaf ? "leaf" : "wood",
                      perMaterial[i], m.diffuse.x, m.diffuse.y, m.diffuse.z);
        s << "  " << i << " " << m.name << ": " << line;
        if (!m.diffuseTexture.empty()) s << ", texture " << m.diffuseTexture;
        if (!m.alphaTexture.empty()) s << ", alpha " << m.alphaTexture;
        s << "\n";
    }
    return s.str();
}

} // namespace sylva
