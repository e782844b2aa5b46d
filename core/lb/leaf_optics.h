// The leaf surface optics an LB channel stands for, and how the renderer turns a scattered LB photon
// density into the light a surface sends to the camera (the ground truth against Blender's Cycles: docs/ACCURACY.md).
#pragma once

#include <glm/glm.hpp>

#include "core/lb/lb_params.h"

namespace sylva::lb {

// The leaf's surface optics that one LB channel (sigma_a, sigma_s, g) stands for: of the light a leaf
// scatters, the Henyey-Greenstein phase sends forwardShare(g) through the leaf (transmission) and the
// rest back (reflection); the single-scattering albedo sigma_s / (sigma_a + sigma_s) is their sum.
// forwardShare(g) = integral of the HG phase over the forward hemisphere
//                 = (1 + g) / (2 g) - (1 - g^2) / (2 g sqrt(1 + g^2)), 1/2 at g = 0.
double forwardShare(double g);
struct LeafOptics {
    glm::vec3 albedo;        // sigma_s / sigma_t per channel
    glm::vec3 reflectance;   // albedo x (1 - forwardShare)
    glm::vec3 transmittance; // albedo x forwardShare
    glm::vec3 ratio;         // transmittance / reflectance: the translucent colour per unit of diffuse colour
};
LeafOptics leafOptics(const LbParams& params);

// Scattered light on a surface: a normalized photon density L (fluence / the sun's open-space fluence E0) of
// light coming from all directions gives each face of a surface the irradiance L x E0 / 4 (an isotropic
// field), where the sun facing it gives E0. A face of diffuse colour kd then shows kd x L x sunRadiance / 4
// reflected, and a leaf the same again x t through itself from its other face (t = LeafOptics::ratio).
// The weights the renderer multiplies kd x L x sunRadiance by under `lighting.direct` once: leaves
// (1 + t) / 4 per channel, bark 1 / 4. (The seed's sum weighs the grid by 1: its grid is mostly the
// unscattered sun, a beam, which the seed shows as if it met every face head on.)
// A leaf scatters (reflects plus transmits) at most this share of the light it receives, whatever its
// texture colour kd and the preset's t: kd x (1 + t) is capped at it per channel (kd x (1 + t) exceeds 1
// for a bright green texel under the leaf preset's t = 1.31). The Blender export caps its translucent
// BSDF by the same rule, kd + kd x t <= kMaxLeafScattering.
inline constexpr float kMaxLeafScattering = 0.98f;
struct ScatteredWeights {
    glm::vec3 leaf;
    float bark;
    float leafCap;   // kd x leaf never exceeds it per channel: kMaxLeafScattering / 4
};
ScatteredWeights scatteredWeights(const LbParams& params);

} // namespace sylva::lb
