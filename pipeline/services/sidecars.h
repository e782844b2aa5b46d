// File names and sidecar parameter JSON of the reference grids `sylva reference` writes. (The LB grid's
// sidecar parameters are lightingParamsJson in pipeline/lighting_job.h, next to its cache keys.)
#pragma once

#include <string>

#include "core/lb/lb_params.h"
#include "core/reference/mc_reference.h"

namespace sylva {

// "REF.npy" -> "REF.stderr.npy" (PATH + ".stderr.npy" when PATH does not end in ".npy").
std::string standardErrorPath(const std::string& meanPath);

enum class ReferenceQuantity { Mean, StandardError };

// The "parameters" object of a reference grid's sidecar: what produced it.
//   {"solver":"reference", <opticsJsonMembers>, "paths":N, "seed":S, "max_bounces":K,
//    "incidence":"lattice"|"collimated", "quantity":"mean fluence"|"standard error of the mean"}
std::string referenceParamsJson(const lb::LbParams& params, const std::string& preset, const ReferenceSettings& settings,
                                ReferenceQuantity quantity);

} // namespace sylva
