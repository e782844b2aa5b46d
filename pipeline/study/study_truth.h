// The scenes of `sylva study truth` (study_truth.cpp): what each is, and the list the part measures. A new
// scene is a function returning a TruthScene and its entry in truthSceneList.
#pragma once

#include <string>
#include <vector>

#include "core/scene/scene.h"
#include "pipeline/study/study.h"

namespace sylva::study {

// One scene compared with Cycles. key names it everywhere: its work folder and pictures (truth/KEY_*.png),
// its row in the summary, SYLVA_TRUTH_SCENES; keys are distinct. A key beginning with "tree" has the camera
// framed on its first species' mesh; "tree" itself also gets the table of the terms that differ.
struct TruthScene {
    std::string key, title;
    Scene scene;
    int refSamples = 1024;     // Cycles' converged reference
    std::vector<int> sweep;    // Cycles' samples along the equal-time curve
};

// Every scene, in the order the report lists them: the tree, the tree under a Preetham sky, the stand, the
// forest's crop.
std::vector<TruthScene> truthSceneList(const Options& o);

// The scenes this run measures: SYLVA_TRUTH_SCENES ("tree,stand") keeps those with these keys, and
// SYLVA_TRUTH_SAMPLE_DIVISOR divides every sample count (a sweep keeps the counts at most a quarter of the
// reference's, at least 1).
std::vector<TruthScene> pickTruthScenes(std::vector<TruthScene> scenes);

// pickTruthScenes(truthSceneList(o)).
inline std::vector<TruthScene> truthScenes(const Options& o) { return pickTruthScenes(truthSceneList(o)); }

} // namespace sylva::study
