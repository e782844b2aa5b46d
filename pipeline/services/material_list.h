// The materials of a species' mesh with their leaf/wood assignment: what the importer's rules make
// of each material, and what the species' leaf_materials list makes of it.
#pragma once

#include <string>
#include <vector>

#include "core/base/progress.h"

namespace sylva {

struct MaterialAssignment {
    std::string name;          // as the mesh (its material library) names it
    bool leafByRules = false;  // the importer's rules alone (no leaf_materials)
    bool leaf = false;         // with leafMaterials: named there (case-insensitive); without: leafByRules
};

// The materials of the mesh at meshPath in the importer's order. leafMaterials: the species'
// leaf_materials (empty = the rules). Throws Error (unreadable mesh) or Cancelled.
std::vector<MaterialAssignment> listMaterials(const std::string& meshPath, const std::vector<std::string>& leafMaterials,
                                              Progress* progress = nullptr);

} // namespace sylva
