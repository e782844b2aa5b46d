// Procedural trees behind `sylva grow`: curved branch skeletons, tapered bark tubes, alpha-textured leaf cards.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "core/base/progress.h"
#include "core/image/image.h"
#include "core/mesh/triangle_mesh.h"

namespace sylva {

enum class TreeSpecies { Broadleaf, Birch, Conifer, Shrub };

// "broadleaf", "birch", "conifer", "shrub" (case-insensitive); false and *out untouched otherwise.
bool parseSpecies(const std::string& name, TreeSpecies* out);
// As parseSpecies, but throws Error naming the unknown species and the known ones.
TreeSpecies speciesFromName(const std::string& name);
// The lower-case name parseSpecies accepts.
std::string speciesName(TreeSpecies species);
// All names, in enum order.
std::vector<std::string> speciesNames();
// Default height in metres: broadleaf 12, birch 16, conifer 20, shrub 2.
float defaultTreeHeight(TreeSpecies species);

inline constexpr size_t kMinGrowTriangles = 1000;
inline constexpr size_t kMaxGrowTriangles = 1000000;

struct GrowOptions {
    TreeSpecies species = TreeSpecies::Broadleaf;
    uint64_t seed = 1;
    size_t targetTriangles = 100000;  // in [kMinGrowTriangles, kMaxGrowTriangles]
    float height = 0;                 // metres, top of the branch skeleton; 0 = species default
};

// mesh: metres, +Y up, base at the origin. materials[0] "bark" (wood), materials[1] "leaf" (isLeaf).
// Wood triangles come first, then leaf cards (2 triangles, 4 vertices, uv 0..1 each; v = 0 is the
// leaf's stem end and the image's bottom row, as in OBJ). Texture paths in the materials are empty
// until writeObj writes the textures; the pixels are in leafTexture (RGBA, alpha cut-out) and
// barkTexture (RGB, alpha 1), sRGB-encoded, tileable bark.
struct GrownTree {
    TriangleMesh mesh;
    ImageRgba leafTexture;
    ImageRgba barkTexture;
};

// Grows one tree. Deterministic: the same options give a bit-identical mesh on every run and any
// thread count. The triangle count is targetTriangles or one less; the skeleton does not depend on
// the target (a smaller target gives coarser bark tubes and fewer, larger leaf cards of the same
// total area). Throws Error on a target outside [1000, 1000000] or a bad height, Cancelled when
// progress is cancelled.
GrownTree growTree(const GrowOptions& options, Progress* progress = nullptr);

} // namespace sylva
