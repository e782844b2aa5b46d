// Triangle counts and bounds of a mesh (mesh_stats.h).
#include "pipeline/services/mesh_stats.h"

namespace sylva {

MeshStats meshStats(const TriangleMesh& mesh)
{
    MeshStats s;
    s.triangles = mesh.triangleCount();
    for (size_t t = 0; t < s.triangles; ++t) s.leafTriangles += mesh.isLeafTriangle(t);
    s.woodTriangles = s.triangles - s.leafTriangles;
    s.bounds = meshBounds(mesh);
    return s;
}

} // namespace sylva
