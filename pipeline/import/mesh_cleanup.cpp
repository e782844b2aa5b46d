// Mesh clean-up with OpenMesh: weld, drop non-finite and degenerate faces, triangulate, normals.
#include "pipeline/import/mesh_cleanup.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <mutex>
#include <unordered_map>

#include <OpenMesh/Core/Mesh/PolyMesh_ArrayKernelT.hh>
#include <OpenMesh/Core/System/omstream.hh>

#include "core/base/error.h"

namespace sylva {

namespace {

struct CleanupTraits : public OpenMesh::DefaultTraits {
    VertexAttributes(OpenMesh::Attributes::Status);
    EdgeAttributes(OpenMesh::Attributes::Status);
    FaceAttributes(OpenMesh::Attributes::Status);
};
using CleanupPolyMesh = OpenMesh::PolyMesh_ArrayKernelT<CleanupTraits>;

// Keeps OpenMesh from printing to stderr while we add faces it may reject (we handle the rejection).
class QuietOpenMesh {
public:
    QuietOpenMesh()
    {
        std::lock_guard lock(s_mutex);
        if (s_depth++ == 0) {
            s_wasEnabled = ::omerr().is_enabled();
            ::omerr().disable();
        }
    }
    ~QuietOpenMesh()
    {
        std::lock_guard lock(s_mutex);
        if (--s_depth == 0 && s_wasEnabled) ::omerr().enable();
    }
    QuietOpenMesh(const QuietOpenMesh&) = delete;
    QuietOpenMesh& operator=(const QuietOpenMesh&) = delete;

private:
    static inline std::mutex s_mutex;
    static inline int s_depth = 0;
    static inline bool s_wasEnabled = true;
};

bool finite3(const glm::vec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

// -0 and +0 weld together; everything else compares by bits.
uint32_t floatKey(float f)
{
    if (f == 0.0f) f = 0.0f;
    uint32_t bits;
    std::memcpy(&bits, &f, sizeof bits);
    return bits;
}

// The attributes that must all agree for two vertices to weld: position, uv, normal, material.
struct WeldKey {
    uint32_t words[9];
    bool operator==(const WeldKey& o) const { return std::memcmp(words, o.words, sizeof words) == 0; }
};

struct WeldKeyHash {
    size_t operator()(const WeldKey& k) const
    {
        uint64_t h = 1469598103934665603ull;  // FNV-1a over the words
        for (uint32_t w : k.words) {
            h ^= w;
            h *= 1099511628211ull;
        }
        return size_t(h ^ (h >> 29));
    }
};

// Twice the triangle's area over its longest edge squared: height / longest edge (0 for a point).
double relativeHeight(const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c)
{
    const double longest2 = std::max({glm::dot(b - a, b - a), glm::dot(c - a, c - a), glm::dot(c - b, c - b)});
    if (!(longest2 > 0.0)) return 0.0;
    return glm::length(glm::cross(b - a, c - a)) / longest2;
}

constexpr double kDegenerateHeight = 1e-6;  // about 8 float ulps of the longest edge

} // namespace

TriangleMesh cleanupMesh(const PolygonSoup& soup, const CleanupOptions& options, CleanupStats* statsOut)
{
    CleanupStats stats;
    const size_t vertexCount = soup.positions.size();
    const bool hasNormals = !soup.normals.empty();
    const bool hasUvs = !soup.uvs.empty();
    if ((hasNormals && soup.normals.size() != vertexCount) || (hasUvs && soup.uvs.size() != vertexCount) ||
        soup.faceStart.size() != soup.faceCount() + 1 || soup.faceStart.back() != soup.corners.size())
        throw Error("mesh clean-up: inconsistent polygon soup (attribute or face array sizes differ)");
    for (uint32_t v : soup.corners)
        if (v >= vertexCount) throw Error("mesh clean-up: a face refers to vertex " + std::to_string(v) + " of " +
                                          std::to_string(vertexCount));

    // 1. Classify faces and weld the corners of the faces we keep.
    std::vector<glm::vec3> weldedPos, weldedNormal;
    std::vector<glm::vec2> weldedUv;
    std::unordered_map<WeldKey, uint32_t, WeldKeyHash> byKey;
    std::unordered_map<uint64_t, uint32_t> byInput;  // (input vertex, material) -> welded vertex
    std::vector<uint32_t> faceCorners;               // welded corner indices of kept faces
    std::vector<uint32_t> keptStart{0}, keptMaterial;
    size_t referencedInputs = 0;

    for (size_t f = 0; f < soup.faceCount(); ++f) {
        const uint32_t begin = soup.faceStart[f], end = soup.faceStart[f + 1];
        const size_t n = end - begin;
        if (n < 3) {
            ++stats.ignoredPrimitives;
            continue;
        }
        stats.inputTriangles += n - 2;
        bool finite = true;
        for (uint32_t c = begin; c < end; ++c) finite = finite && finite3(soup.positions[soup.corners[c]]);
        if (!finite) {
            stats.droppedNonFinite += n - 2;
            continue;
        }
        const uint32_t material = soup.faceMaterial[f];
        for (uint32_t c = begin; c < end; ++c) {
            const uint32_t v = soup.corners[c];
            const uint64_t pair = (uint64_t(v) << 32) | material;
            auto found = byInput.find(pair);
            uint32_t welded;
            if (found != byInput.end()) {
                welded = found->second;
            } else {
                ++referencedInputs;
                welded = uint32_t(weldedPos.size());
                if (options.weld) {
                    WeldKey key{};
                    const glm::vec3& p = soup.positions[v];
                    const glm::vec2 uv = hasUvs ? soup.uvs[v] : glm::vec2(0.0f);
                    const glm::vec3 nrm = hasNormals ? soup.normals[v] : glm::vec3(0.0f);
                    const float values[8] = {p.x, p.y, p.z, uv.x, uv.y, nrm.x, nrm.y, nrm.z};
                    for (int i = 0; i < 8; ++i) key.words[i] = floatKey(values[i]);
                    key.words[8] = material;
                    welded = byKey.try_emplace(key, welded).first->second;
                }
                if (welded == weldedPos.size()) {
                    weldedPos.push_back(soup.positions[v]);
                    if (hasNormals) weldedNormal.push_back(soup.normals[v]);
                    if (hasUvs) weldedUv.push_back(soup.uvs[v]);
                }
                byInput.emplace(pair, welded);
            }
            faceCorners.push_back(welded);
        }
        keptStart.push_back(uint32_t(faceCorners.size()));
        keptMaterial.push_back(material);
    }
    stats.weldedVertices = referencedInputs - weldedPos.size();

    // 2. Connect the faces in OpenMesh. A face it cannot connect (a repeated corner, or an edge or
    // vertex that would become non-manifold) gets its own copies of its vertices; the copies remember
    // their welded vertex, so the output mesh shares them again.
    CleanupPolyMesh mesh;
    OpenMesh::VPropHandleT<uint32_t> origin;
    OpenMesh::FPropHandleT<uint32_t> faceMaterial;
    mesh.add_property(origin);
    mesh.add_property(faceMaterial);
    std::vector<OpenMesh::VertexHandle> handles(weldedPos.size());
    for (size_t i = 0; i < weldedPos.size(); ++i) {
        const glm::vec3& p = weldedPos[i];
        handles[i] = mesh.add_vertex(CleanupPolyMesh::Point(p.x, p.y, p.z));
        mesh.property(origin, handles[i]) = uint32_t(i);
    }
    {
        QuietOpenMesh quiet;
        std::vector<OpenMesh::VertexHandle> face;
        for (size_t f = 0; f + 1 < keptStart.size(); ++f) {
            face.clear();
            for (uint32_t c = keptStart[f]; c < keptStart[f + 1]; ++c) face.push_back(handles[faceCorners[c]]);
            bool connectable = true;
            for (size_t i = 0; i < face.size() && connectable; ++i) {
                const auto next = face[(i + 1) % face.size()];
                const auto he = mesh.find_halfedge(face[i], next);
                connectable = mesh.is_boundary(face[i]) && (!he.is_valid() || mesh.is_boundary(he)) &&
                              std::count(face.begin(), face.end(), face[i]) == 1;
            }
            OpenMesh::FaceHandle fh;
            if (connectable) fh = mesh.add_face(face);
            if (!fh.is_valid()) {
                ++stats.nonManifoldFaces;
                for (auto& vh : face) {
                    const auto copy = mesh.add_vertex(mesh.point(vh));
                    mesh.property(origin, copy) = mesh.property(origin, vh);
                    vh = copy;
                }
                fh = mesh.add_face(face);
            }
            mesh.property(faceMaterial, fh) = keptMaterial[f];
        }
    }

    // 3. Triangulate what is left of the polygons (a fan; the importer ear-clips concave ones first).
    // OpenMesh copies face properties to the new triangles.
    mesh.triangulate();

    // 4. Drop degenerate triangles.
    for (auto fh : mesh.faces()) {
        glm::dvec3 p[3];
        int k = 0;
        for (auto vh : mesh.fv_range(fh)) p[k++] = glm::dvec3(weldedPos[mesh.property(origin, vh)]);
        if (relativeHeight(p[0], p[1], p[2]) <= kDegenerateHeight) {
            ++stats.droppedDegenerate;
            mesh.delete_face(fh, false);
        }
    }

    // 5. Write the surviving triangles with compact vertex numbering (first use order).
    TriangleMesh out;
    std::vector<uint32_t> outIndex(weldedPos.size(), std::numeric_limits<uint32_t>::max());
    std::vector<uint32_t> outOrigin;
    for (auto fh : mesh.faces()) {
        glm::uvec3 tri;
        int k = 0;
        for (auto vh : mesh.fv_range(fh)) {
            const uint32_t w = mesh.property(origin, vh);
            if (outIndex[w] == std::numeric_limits<uint32_t>::max()) {
                outIndex[w] = uint32_t(outOrigin.size());
                outOrigin.push_back(w);
            }
            tri[k++] = outIndex[w];
        }
        out.triangles.push_back(tri);
        out.triangleMaterial.push_back(mesh.property(faceMaterial, fh));
    }
    out.positions.reserve(outOrigin.size());
    for (uint32_t w : outOrigin) out.positions.push_back(weldedPos[w]);
    if (hasUvs) {
        out.uvs.reserve(outOrigin.size());
        for (uint32_t w : outOrigin) {
            const glm::vec2 uv = weldedUv[w];
            out.uvs.push_back(std::isfinite(uv.x) && std::isfinite(uv.y) ? uv : glm::vec2(0.0f));
        }
    }

    // 6. Normals: the file's where valid, else the mean of the adjacent triangles' unit normals
    // weighted by the triangle's angle at the vertex (independent of how polygons were split);
    // counter-clockwise winding faces the viewer. Where they cancel, the largest triangle's normal.
    std::vector<glm::dvec3> sum(outOrigin.size(), glm::dvec3(0.0));
    std::vector<glm::dvec3> largest(outOrigin.size(), glm::dvec3(0.0));
    std::vector<double> angleSum(outOrigin.size(), 0.0);
    for (const auto& t : out.triangles) {
        const glm::dvec3 p[3] = {glm::dvec3(out.positions[t[0]]), glm::dvec3(out.positions[t[1]]),
                                 glm::dvec3(out.positions[t[2]])};
        const glm::dvec3 n = glm::cross(p[1] - p[0], p[2] - p[0]);
        const glm::dvec3 unit = glm::normalize(n);
        for (int k = 0; k < 3; ++k) {
            const glm::dvec3 e1 = p[(k + 1) % 3] - p[k], e2 = p[(k + 2) % 3] - p[k];
            const double angle = std::atan2(glm::length(glm::cross(e1, e2)), glm::dot(e1, e2));
            sum[t[k]] += angle * unit;
            angleSum[t[k]] += angle;
            if (glm::dot(n, n) > glm::dot(largest[t[k]], largest[t[k]])) largest[t[k]] = n;
        }
    }
    out.normals.resize(outOrigin.size());
    for (size_t i = 0; i < outOrigin.size(); ++i) {
        if (hasNormals) {
            const glm::vec3 given = weldedNormal[outOrigin[i]];
            const float len = glm::length(given);
            if (finite3(given) && std::isfinite(len) && len > 1e-20f) {
                out.normals[i] = given / len;
                continue;
            }
        }
        ++stats.recomputedNormals;
        const double len = glm::length(sum[i]);
        const double scale = glm::length(largest[i]);
        const glm::dvec3 n = len > 1e-6 * angleSum[i] ? sum[i] / len : largest[i] / scale;
        out.normals[i] = glm::vec3(n);
    }

    if (statsOut) *statsOut = stats;
    return out;
}

} // namespace sylva
