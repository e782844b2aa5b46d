// Mesh import: any file Assimp reads -> one cleaned TriangleMesh with leaf/wood materials.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "core/mesh/triangle_mesh.h"

namespace sylva {

struct ImportOptions {
    std::vector<std::string> leafMaterials;  // explicit override: names of leaf materials (case-insensitive); when non-empty, exactly these are leaf
    bool weld = true;                         // weld duplicate vertices (exact matches of position, uv, normal, material)
};

// What the import did. Triangle counts are after triangulation (an n-gon counts n-2):
// inputTriangles = triangles in the file, leafTriangles + woodTriangles = triangles kept.
// weldedVertices counts vertices as Assimp hands them over (its OBJ reader makes one per face corner).
struct ImportReport {
    size_t inputTriangles = 0, droppedDegenerate = 0, droppedNonFinite = 0, weldedVertices = 0;
    size_t leafTriangles = 0, woodTriangles = 0;
    std::vector<std::string> warnings;  // missing textures, ignored points/lines, unmatched leaf names ...
};

// Reads a mesh file (OBJ, FBX, glTF/GLB, PLY, DAE, anything Assimp reads) into one triangle mesh in
// the file's frame: node transforms applied, polygons triangulated, duplicate vertices welded,
// degenerate and non-finite faces dropped, unit vertex normals (computed where the file has none).
// Lengths in metres: FBX units (UnitScaleFactor centimetres) and COLLADA <unit> are converted;
// other formats are taken as metres. uvs follow the OpenGL convention (v = 0 is the image's bottom row).
//
// Materials keep the file's order (unused ones removed) and are never merged, even when identical.
// A material is leaf when options.leafMaterials names it; without that list, when it has an opacity
// texture (OBJ map_d), or its diffuse texture file has an alpha channel, or it is a glTF alphaMode
// MASK material, or its name contains leaf / leaves / foliage / needle (case-insensitive); else wood.
// Texture paths are resolved relative to the mesh file's folder into absolute paths (alphaTexture is
// set from the opacity map even when it names the diffuse file); a texture file that does not exist
// is left out (empty path) with a warning in the report; embedded textures are not extracted.
//
// Throws Error naming the file and the problem for a missing, unreadable or unparsable file and
// for a file that yields no triangles.
TriangleMesh importMesh(const std::string& path, const ImportOptions& options = {}, ImportReport* report = nullptr);

// A few lines for `sylva info`: triangle and vertex counts, bounds, materials (leaf/wood, textures).
std::string describeMesh(const TriangleMesh& mesh);

} // namespace sylva
