// Mesh clean-up with OpenMesh: weld duplicate vertices, drop bad faces, triangulate, fill in normals.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "core/mesh/triangle_mesh.h"

namespace sylva {

// Polygons as an importer reads them, all in one frame (units of the file). Faces may have any
// number of corners; a face with fewer than three is ignored. 32-bit indices.
struct PolygonSoup {
    std::vector<glm::vec3> positions;
    std::vector<glm::vec3> normals;       // empty or positions.size(); any length, zero = unknown
    std::vector<glm::vec2> uvs;           // empty or positions.size()
    std::vector<uint32_t> corners;        // vertex indices of all faces, one after another
    std::vector<uint32_t> faceStart{0};   // face f has corners [faceStart[f], faceStart[f+1])
    std::vector<uint32_t> faceMaterial;   // one per face; passed through to TriangleMesh::triangleMaterial

    size_t faceCount() const { return faceMaterial.size(); }
    void addFace(const uint32_t* indices, size_t count, uint32_t material)
    {
        corners.insert(corners.end(), indices, indices + count);
        faceStart.push_back(uint32_t(corners.size()));
        faceMaterial.push_back(material);
    }
};

struct CleanupOptions {
    bool weld = true;  // merge vertices whose position, uv, normal and material are all bit-identical
};

// What the clean-up did; triangles are counted after triangulation (an n-gon counts n-2).
struct CleanupStats {
    size_t inputTriangles = 0;
    size_t droppedDegenerate = 0;   // zero area (within float precision) or a repeated corner
    size_t droppedNonFinite = 0;    // a corner with a NaN or infinite coordinate
    size_t weldedVertices = 0;      // input vertices merged into an identical earlier one
    size_t ignoredPrimitives = 0;   // faces with fewer than three corners (points, lines)
    size_t recomputedNormals = 0;   // output vertices whose normal was computed (missing or invalid input)
    size_t nonManifoldFaces = 0;    // faces OpenMesh could not connect; kept with their own vertex copies
};

// Cleans a polygon soup into a triangle mesh (materials left empty; triangleMaterial as given).
// Output normals are always present and unit length (the soup's where valid, else angle-weighted
// means of the adjacent triangles' normals); uvs are present when the soup has them.
// Welding is exact: a vertex is merged only with one that has the same position, uv, normal and
// material, so uv seams, hard edges and material borders stay split. Degenerate means the triangle's
// height is below 1e-6 of its longest edge (zero area in float precision) or two corners coincide.
TriangleMesh cleanupMesh(const PolygonSoup& soup, const CleanupOptions& options = {}, CleanupStats* stats = nullptr);

} // namespace sylva
