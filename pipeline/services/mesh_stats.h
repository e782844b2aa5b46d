// What a grown or imported mesh holds, in numbers (`sylva grow` prints them).
#pragma once

#include <algorithm>
#include <cstddef>

#include "core/mesh/triangle_mesh.h"

namespace sylva {

struct MeshStats {
    size_t triangles = 0, leafTriangles = 0, woodTriangles = 0;   // wood: every triangle that is not leaf
    Bounds3 bounds;                                               // of the triangles' corners
    float height() const { return bounds.extent().y; }
    float width() const { return std::max(bounds.extent().x, bounds.extent().z); }   // the wider horizontal extent
};
MeshStats meshStats(const TriangleMesh& mesh);

} // namespace sylva
