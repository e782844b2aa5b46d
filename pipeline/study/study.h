// `sylva study`: measured speed/accuracy trade-offs (LB, voxelization, rendering) regenerating docs/ACCURACY.md.
#pragma once

#include <functional>
#include <string>
#include <vector>

namespace sylva {

class GridCache;

namespace study {

enum class Part { Lb, Voxel, Render, Scene, Truth, Sky };   // Scene: the forest-level grid and the relighting basis   // Truth: against Cycles (needs `blender`; skipped without it and with --quick)   // Sky: virtual lights x subsets x spp, the LB with the sky

struct Options {
    std::vector<Part> parts;            // measured now; the others' stored results are reused (empty: report only)
    std::string outDir = "docs";        // ACCURACY.md here, plots and stored results in outDir/accuracy
    bool quick = false;                 // small grids, fewer paths and samples: a few minutes on 2 cores
    std::string treeMesh;               // the real tree (empty: resources/trees/quaternius/OBJ/Tree_1.obj)
    GridCache* cache = nullptr;         // Monte Carlo references and the renders' lighting grids (null: none)
    std::function<void(const std::string&)> log;   // one line per measurement
};

struct Result {
    std::string markdown;               // path of the written ACCURACY.md
    std::vector<std::string> plots;     // PNG files written
    std::string plotNote;               // why plots were skipped, empty when written
    double seconds = 0.0;               // measuring and writing
};

// Runs the parts' measurements, stores each part's numbers in outDir/accuracy/<part>.json, then writes
// ACCURACY.md from every stored part (the "The reference solver" and "Normalization" sections of an
// existing ACCURACY.md are kept word for word) and, when gnuplot is found (SYLVA_GNUPLOT overrides the
// program), the plots. Throws Error on failures.
Result run(const Options& options);

// "lb", "voxel", "render", "scene", "truth", "sky" -> Part; false otherwise.
bool parsePart(const std::string& name, Part* out);

} // namespace study
} // namespace sylva
