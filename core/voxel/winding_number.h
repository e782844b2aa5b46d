// Generalized winding number of a triangle mesh (Jacobson et al. 2013), accelerated by a BVH of dipoles
// (Barill et al. 2018, first order): the robust inside test of the solid voxelizer, public for the
// renderer and tests.
#pragma once

#include <vector>

#include <glm/glm.hpp>

#include "core/mesh/triangle_mesh.h"

namespace sylva {

// Exact solid angle of triangle (a, b, c) seen from the origin, divided by 4 pi (Van Oosterom and
// Strackee 1983): positive when the triangle's normal (b - a) x (c - a) points away from the origin.
double triangleWindingNumber(const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c);

// w(p) = sum over triangles of their winding number seen from p: 1 inside and 0 outside a closed,
// outward-oriented mesh; for an open mesh a smooth field near 1 inside, near 0 outside and about 1/2
// across a hole, so thresholding it at 1/2 fills a solid through gaps and open edges.
class WindingNumber {
public:
    // beta: a node of the hierarchy is replaced by its dipole when the query lies farther than beta
    // times the node's radius from its centre (2: the sum is within about 0.01 of the exact one, far from the 1/2 threshold away from holes).
    explicit WindingNumber(const TriangleMesh& mesh, double beta = 2.0);
    double operator()(const glm::dvec3& p) const;
    // The exact sum over every triangle (the oracle of the accelerated one; O(triangles)).
    double exact(const glm::dvec3& p) const;

private:
    struct Node {
        glm::dvec3 lo, hi;
        glm::dvec3 centre;     // area-weighted centroid
        glm::dvec3 area;       // sum of the vector areas (normal * area)
        double areaSum;        // sum of the triangle areas
        double radius2;        // squared distance from centre to the farthest corner of the box
        int first, count;      // leaf: triangles [first, first + count); inner: count = 0, children first, first + 1
    };
    std::vector<glm::dvec3> m_tri;   // 3 vertices per triangle, in BVH order
    std::vector<Node> m_nodes;
    double m_beta2;
};

} // namespace sylva
