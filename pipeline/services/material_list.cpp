// listMaterials (material_list.h).
#include "pipeline/services/material_list.h"

#include <QString>

#include "pipeline/import/mesh_import.h"

namespace sylva {

std::vector<MaterialAssignment> listMaterials(const std::string& meshPath, const std::vector<std::string>& leafMaterials,
                                              Progress* progress)
{
    if (progress) progress->report(0.0, "reading");
    // The rules alone (no override), then what the species' list makes of them.
    const TriangleMesh mesh = importMesh(meshPath, ImportOptions{});
    std::vector<MaterialAssignment> out;
    for (const Material& m : mesh.materials) {
        MaterialAssignment a;
        a.name = m.name;
        a.leafByRules = m.isLeaf;
        a.leaf = m.isLeaf;
        if (!leafMaterials.empty()) {
            const QString name = QString::fromStdString(m.name);
            a.leaf = false;
            for (const std::string& n : leafMaterials)
                a.leaf = a.leaf || QString::fromStdString(n).compare(name, Qt::CaseInsensitive) == 0;
        }
        out.push_back(std::move(a));
    }
    if (progress) progress->report(1.0, "read");
    return out;
}

} // namespace sylva
