// Wavefront OBJ + MTL writer: lines formatted with std::to_chars into per-chunk buffers in parallel, written in order.
#include "pipeline/grow/obj_writer.h"

#include <cctype>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <memory>
#include <set>
#include <vector>

#include <tbb/parallel_for.h>

#include "core/base/error.h"
#include "pipeline/io/atomic_file.h"
#include "pipeline/io/image_io.h"

namespace sylva {

namespace fs = std::filesystem;

namespace {

// Creates the OBJ's folder first, so a bad folder is reported against the OBJ, not a texture.
void ensureFolder(const std::string& path)
{
    const fs::path parent = fs::path(path).parent_path();
    if (parent.empty()) return;
    std::error_code ec;
    fs::create_directories(parent, ec);
    if (!fs::is_directory(parent))
        throw Error(path + ": cannot create the folder " + parent.string() + (ec ? " (" + ec.message() + ")" : ""));
}

char* putFloat(char* p, float v) { return std::to_chars(p, p + 24, v).ptr; }
char* putIndex(char* p, uint32_t i) { return std::to_chars(p, p + 16, uint64_t(i) + 1).ptr; }

// Formats count lines with format(char* out, size_t i) -> end, maxLine bytes at most each, in
// fixed chunks formatted in parallel and written in order: the bytes never depend on the threads.
template <class Format>
void writeLines(AtomicFile& file, size_t begin, size_t end, size_t maxLine, const Format& format)
{
    constexpr size_t kChunk = 16384, kBatch = 16;
    const size_t count = end - begin;
    const size_t chunks = (count + kChunk - 1) / kChunk;
    std::vector<std::unique_ptr<char[]>> buffers(std::min(kBatch, chunks));
    std::vector<size_t> used(buffers.size());
    for (size_t first = 0; first < chunks; first += kBatch) {
        const size_t n = std::min(kBatch, chunks - first);
        tbb::parallel_for(size_t(0), n, [&](size_t c) {
            if (!buffers[c]) buffers[c].reset(new char[kChunk * maxLine]);
            char* p = buffers[c].get();
            const size_t from = begin + (first + c) * kChunk, to = std::min(end, from + kChunk);
            for (size_t i = from; i < to; ++i) p = format(p, i);
            used[c] = size_t(p - buffers[c].get());
        });
        for (size_t c = 0; c < n; ++c) file.write(buffers[c].get(), used[c]);
    }
}

// Material names as OBJ can carry them: no whitespace, not empty, unique.
std::vector<std::string> materialNames(const std::vector<Material>& materials)
{
    std::vector<std::string> names;
    std::set<std::string> seen;
    for (size_t i = 0; i < materials.size(); ++i) {
        std::string n = materials[i].name;
        for (char& c : n)
            if (std::isspace(static_cast<unsigned char>(c)) || c == '#') c = '_';
        if (n.empty()) n = "material" + std::to_string(i);
        if (seen.count(n)) n.append(1, '_').append(std::to_string(i));
        seen.insert(n);
        names.push_back(n);
    }
    return names;
}

// A texture path as the MTL names it: relative to the OBJ's folder when possible.
std::string texturePath(const std::string& texture, const fs::path& objDir)
{
    const fs::path p(texture);
    if (p.is_relative()) return p.generic_string();
    const fs::path rel = p.lexically_normal().lexically_relative(fs::absolute(objDir).lexically_normal());
    return rel.empty() ? p.generic_string() : rel.generic_string();
}

std::string formatNumber(float v)
{
    char buf[32];
    return std::string(buf, putFloat(buf, v));
}

std::string formatColour(const glm::vec3& c)
{
    return formatNumber(c.x) + " " + formatNumber(c.y) + " " + formatNumber(c.z);
}

void checkMesh(const std::string& objPath, const TriangleMesh& mesh, const std::vector<Material>& materials)
{
    const size_t nv = mesh.positions.size();
    if (nv > size_t(UINT32_MAX)) throw Error(objPath + ": too many vertices for 32-bit indices");
    if (!mesh.normals.empty() && mesh.normals.size() != nv)
        throw Error(objPath + ": mesh has " + std::to_string(mesh.normals.size()) + " normals for " + std::to_string(nv) +
                    " vertices");
    if (!mesh.uvs.empty() && mesh.uvs.size() != nv)
        throw Error(objPath + ": mesh has " + std::to_string(mesh.uvs.size()) + " uvs for " + std::to_string(nv) + " vertices");
    if (!mesh.triangleMaterial.empty() && mesh.triangleMaterial.size() != mesh.triangles.size())
        throw Error(objPath + ": mesh has " + std::to_string(mesh.triangleMaterial.size()) + " triangle materials for " +
                    std::to_string(mesh.triangles.size()) + " triangles");
    for (size_t t = 0; t < mesh.triangles.size(); ++t) {
        const glm::uvec3& tri = mesh.triangles[t];
        if (tri.x >= nv || tri.y >= nv || tri.z >= nv)
            throw Error(objPath + ": triangle " + std::to_string(t) + " indexes a vertex out of range");
        if (!mesh.triangleMaterial.empty() && mesh.triangleMaterial[t] >= materials.size())
            throw Error(objPath + ": triangle " + std::to_string(t) + " has material " +
                        std::to_string(mesh.triangleMaterial[t]) + " of " + std::to_string(materials.size()));
    }
    for (size_t v = 0; v < nv; ++v) {
        const glm::vec3& p = mesh.positions[v];
        if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z))
            throw Error(objPath + ": vertex " + std::to_string(v) + " is not finite");
    }
}

void writeMtl(const std::string& mtlPath, const std::vector<Material>& materials, const std::vector<std::string>& names,
              const fs::path& objDir)
{
    std::string text = "# Sylva material library\n";
    for (size_t i = 0; i < materials.size(); ++i) {
        const Material& m = materials[i];
        const bool specular = m.specular.x > 0 || m.specular.y > 0 || m.specular.z > 0;
        text += "\nnewmtl " + names[i] + "\n";
        text += "Ka 0 0 0\n";
        text += "Kd " + formatColour(m.diffuse) + "\n";
        text += "Ks " + formatColour(m.specular) + "\n";
        text += "Ns " + formatNumber(m.shininess) + "\n";
        text += "d 1\n";
        text += std::string("illum ") + (specular ? "2" : "1") + "\n";
        if (!m.diffuseTexture.empty()) text += "map_Kd " + texturePath(m.diffuseTexture, objDir) + "\n";
        if (!m.alphaTexture.empty()) text += "map_d " + texturePath(m.alphaTexture, objDir) + "\n";
    }
    AtomicFile file(mtlPath, AtomicFile::Sync::No);   // no fsync, as before: regenerable output
    file.write(text);
    file.commit();
}

void writeObjWithMaterials(const std::string& objPath, const TriangleMesh& mesh, const std::vector<Material>& materials)
{
    if (objPath.empty()) throw Error("OBJ output: empty file name");
    checkMesh(objPath, mesh, materials);
    ensureFolder(objPath);
    const fs::path obj(objPath);
    const fs::path objDir = obj.parent_path().empty() ? fs::path(".") : obj.parent_path();
    const std::string stem = obj.stem().string();
    const std::vector<std::string> names = materialNames(materials);
    const bool hasMaterials = !materials.empty();
    if (hasMaterials) writeMtl((objDir / (stem + ".mtl")).string(), materials, names, objDir);

    const bool hasUv = !mesh.uvs.empty(), hasNormal = !mesh.normals.empty();
    AtomicFile file(objPath, AtomicFile::Sync::No);
    std::string header = "# Sylva OBJ: " + std::to_string(mesh.positions.size()) + " vertices, " +
                         std::to_string(mesh.triangles.size()) + " triangles\n";
    if (hasMaterials) header += "mtllib " + stem + ".mtl\n";
    header += "o " + (stem.empty() ? std::string("mesh") : stem) + "\n";
    file.write(header);

    const size_t nv = mesh.positions.size();
    writeLines(file, 0, nv, 64, [&](char* p, size_t i) {
        const glm::vec3& v = mesh.positions[i];
        *p++ = 'v';
        *p++ = ' ';
        p = putFloat(p, v.x);
        *p++ = ' ';
        p = putFloat(p, v.y);
        *p++ = ' ';
        p = putFloat(p, v.z);
        *p++ = '\n';
        return p;
    });
    if (hasUv)
        writeLines(file, 0, nv, 48, [&](char* p, size_t i) {
            const glm::vec2& t = mesh.uvs[i];
            *p++ = 'v';
            *p++ = 't';
            *p++ = ' ';
            p = putFloat(p, t.x);
            *p++ = ' ';
            p = putFloat(p, t.y);
            *p++ = '\n';
            return p;
        });
    if (hasNormal)
        writeLines(file, 0, nv, 64, [&](char* p, size_t i) {
            const glm::vec3& n = mesh.normals[i];
            *p++ = 'v';
            *p++ = 'n';
            *p++ = ' ';
            p = putFloat(p, n.x);
            *p++ = ' ';
            p = putFloat(p, n.y);
            *p++ = ' ';
            p = putFloat(p, n.z);
            *p++ = '\n';
            return p;
        });

    const auto face = [&](char* p, size_t t) {
        const glm::uvec3& tri = mesh.triangles[t];
        *p++ = 'f';
        for (int c = 0; c < 3; ++c) {
            *p++ = ' ';
            p = putIndex(p, tri[c]);
            if (hasUv || hasNormal) {
                *p++ = '/';
                if (hasUv) p = putIndex(p, tri[c]);
                if (hasNormal) {
                    *p++ = '/';
                    p = putIndex(p, tri[c]);
                }
            }
        }
        *p++ = '\n';
        return p;
    };
    // One usemtl per run of triangles with the same material.
    const size_t nt = mesh.triangles.size();
    size_t runStart = 0;
    while (runStart < nt) {
        size_t runEnd = nt;
        if (hasMaterials && !mesh.triangleMaterial.empty()) {
            const uint32_t m = mesh.triangleMaterial[runStart];
            runEnd = runStart + 1;
            while (runEnd < nt && mesh.triangleMaterial[runEnd] == m) ++runEnd;
            file.write("usemtl " + names[m] + "\n");
        }
        writeLines(file, runStart, runEnd, 128, face);
        runStart = runEnd;
    }
    file.commit();
}

} // namespace

void writeObj(const std::string& objPath, const TriangleMesh& mesh)
{
    writeObjWithMaterials(objPath, mesh, mesh.materials);
}

void writeObj(const std::string& objPath, const GrownTree& tree)
{
    if (objPath.empty()) throw Error("OBJ output: empty file name");
    ensureFolder(objPath);
    const fs::path obj(objPath);
    const fs::path dir = obj.parent_path().empty() ? fs::path(".") : obj.parent_path();
    const std::string stem = obj.stem().string();
    const std::string leafPng = fs::absolute(dir / (stem + "_leaf.png")).lexically_normal().string();
    const std::string barkPng = fs::absolute(dir / (stem + "_bark.png")).lexically_normal().string();
    if (tree.leafTexture.empty() || tree.barkTexture.empty())
        throw Error(objPath + ": the grown tree has no leaf or bark texture to write");
    writeImage(leafPng, tree.leafTexture, 4);
    writeImage(barkPng, tree.barkTexture, 3);
    std::vector<Material> materials = tree.mesh.materials;
    for (Material& m : materials) {
        if (m.isLeaf) {
            m.diffuseTexture = leafPng;
            m.alphaTexture = leafPng;
        } else {
            m.diffuseTexture = barkPng;
            m.alphaTexture.clear();
        }
    }
    writeObjWithMaterials(objPath, tree.mesh, materials);
}

} // namespace sylva
