// Indexed triangle mesh with per-triangle materials, the pipeline's in-memory plant geometry.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <glm/glm.hpp>

namespace sylva {

// A surface material; textures are paths as the mesh file names them, resolved relative to it.
struct Material {
    std::string name;
    bool isLeaf = false;               // leaf (green) or wood (brown) biomass
    glm::vec3 diffuse{0.8f};           // linear RGB, multiplied by the diffuse texture
    glm::vec3 specular{0.0f};          // linear RGB
    float shininess = 16.0f;           // Phong exponent
    std::string diffuseTexture;        // absolute path or empty
    std::string alphaTexture;          // absolute path or empty (else alpha of diffuseTexture, if any)
};

// Units: metres in the mesh's own frame. 32-bit indices. Normals and uvs are per vertex when present.
struct TriangleMesh {
    std::vector<glm::vec3> positions;
    std::vector<glm::vec3> normals;          // empty or positions.size()
    std::vector<glm::vec2> uvs;              // empty or positions.size()
    std::vector<glm::uvec3> triangles;       // vertex indices
    std::vector<uint32_t> triangleMaterial;  // index into materials, one per triangle
    std::vector<Material> materials;

    size_t triangleCount() const { return triangles.size(); }
    bool isLeafTriangle(size_t t) const
    {
        return !triangleMaterial.empty() && materials[triangleMaterial[t]].isLeaf;
    }
};

struct Bounds3 {
    glm::vec3 lo{1e30f};
    glm::vec3 hi{-1e30f};
    void extend(const glm::vec3& p)
    {
        lo = glm::min(lo, p);
        hi = glm::max(hi, p);
    }
    bool valid() const { return lo.x <= hi.x && lo.y <= hi.y && lo.z <= hi.z; }
    glm::vec3 extent() const { return hi - lo; }
    glm::vec3 center() const { return 0.5f * (lo + hi); }
};

inline Bounds3 meshBounds(const TriangleMesh& mesh)
{
    Bounds3 b;
    for (const auto& t : mesh.triangles)
        for (int c = 0; c < 3; ++c) b.extend(mesh.positions[t[c]]);
    return b;
}

} // namespace sylva
