// Wavefront OBJ + MTL writer for triangle meshes and grown trees; atomic, chunk-parallel formatting.
#pragma once

#include <string>

#include "core/mesh/triangle_mesh.h"
#include "pipeline/grow/tree_grower.h"

namespace sylva {

// Writes NAME.obj, NAME.mtl, NAME_leaf.png (RGBA, alpha cut-out) and NAME_bark.png next to objPath
// (NAME = objPath's stem); the MTL's "bark" and "leaf" materials reference the PNGs. Textures first,
// the OBJ last; each file written to a temporary name and renamed. Throws Error naming the file.
void writeObj(const std::string& objPath, const GrownTree& tree);

// Writes any mesh as NAME.obj + NAME.mtl (mtllib, usemtl per material run, v/vt/vn and 1-based
// f a/a/a lines; numbers as shortest round-trip floats). Materials' texture files must already
// exist; map_Kd / map_d are written relative to the OBJ's folder. Folders are created as needed.
// Throws Error naming the file on a bad mesh (index out of range, size mismatch) or a failed write.
void writeObj(const std::string& objPath, const TriangleMesh& mesh);

} // namespace sylva
