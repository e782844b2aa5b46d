// Parameters of an LB lighting solve: per-channel optics, sun boundary condition, steps or tolerance, storage.
// "The papers" below: Geist & Steele, "A Lighting Model for Fast Rendering of Forest Ecosystems", and
// Geist & Westall, "Lattice-Boltzmann Lighting Models" (docs/LB_MODEL.md).
#pragma once

#include <array>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "core/base/param_spec.h"
#include "core/lb/omega.h"

namespace sylva {
struct DensityGrid;
}

namespace sylva::lb {

enum class Storage { Fp32, Fp16 };

// Bump whenever a change alters the numbers a solve returns (cache keys include it).
inline constexpr int kAlgorithmVersion = 2;

// Steps per node of the longest edge of a fixed-step solve: its range is declared here once; validate(),
// the scene file (species and volume lighting) and docs/SCENE.md read it. The default is LbParams's.
inline constexpr ParamSpec kStepsPerEdge{.key = "steps_per_edge", .kind = ParamSpec::Kind::Integer, .metavar = "N", .lo = 1, .hi = 64,
                                         .def = {2, 0, 0}, .help = "LB steps per node of the longest edge"};

struct LbParams {
    std::array<ChannelParams, 3> channels{};   // R, G, B
    bool zeroF0 = true;                        // plants: true; clouds and plastics keep f_0
    glm::vec3 sun{0.0f, 1.0f, 0.0f};           // direction toward the sun, any length
    glm::vec3 intensity{1.0f};                 // sun intensity per channel
    int steps = 0;                             // fixed step count; 0 = stepsPerEdge x the longest edge
    int stepsPerEdge = int(kStepsPerEdge.def[0]);   // with steps = 0: steps per node of the longest edge (the papers' 2)
    double tolerance = 0.0;                    // > 0: stop when the relative L2 change per step < tolerance
    int checkEvery = 0;                        // tolerance check period in steps; 0 = about every 16 steps
    int maxSteps = 0;                          // tolerance mode cap; 0 = 4 x the longest edge
    bool warmStart = false;                    // start the interior from the unobstructed field instead of 0
                                               // (same steady state, reached in fewer steps; not the papers' start)
    bool coarseStart = false;                  // tolerance mode: start from the same solve on a grid of half the
                                               // resolution (recursively), interpolated; fewer fine steps
    int solvesPerPass = 0;                     // channel solves advanced together (memory allowing); 0 = one
    int blockSteps = 0;                        // steps per cache-blocked wavefront; 0 = sized to the cache
    float brownThreshold = 0.5f;               // wood fraction above which a node is brown (g = -1)
    Storage storage = Storage::Fp32;
    // The boundary distribution f_m for unit intensity, m = 0..18 (19 values, finite, >= 0): empty = the
    // sun's max(0, n_m . d) (docs/LB_MODEL.md "Boundary condition"). A sky boundary, a relighting basis
    // direction (lb_basis.h) or a sum of suns goes here; every channel gets it x its intensity.
    std::vector<float> boundary;
};

struct Preset {
    std::string name;
    std::string description;
    std::array<ChannelParams, 3> channels;
    bool zeroF0;
};

// leaf, dogrose, cloud, pmma (docs/LB_MODEL.md "Parameter presets").
const std::vector<Preset>& presets();
const Preset* findPreset(const std::string& name);
LbParams paramsFromPreset(const Preset& preset);

// Throws Error naming the parameter and its bound when the solve would be unstable or meaningless.
void validate(const LbParams& params);
// Checks the density grid: dims >= 3, values finite in [0,1], sizes consistent. Throws Error.
void validateDensity(const DensityGrid& density);

// The configuration `sylva light` runs by default, a point on the measured front (docs/ACCURACY.md,
// docs/PERFORMANCE.md "sylva light's default"): fp16 storage, 1 x the longest edge in fixed steps (linear
// in the boundary, so a relighting basis of it composes any sun). The papers' 2 x steps in fp32 is
// `--seed-steps`.
void useFrontDefaults(LbParams& params);

// The papers' step count: 2 x the longest edge (Geist & Westall: near equilibrium by then).
int defaultSteps(const glm::ivec3& dims);
// The step count of a fixed-step solve with these parameters: steps, or stepsPerEdge x the longest edge.
int fixedSteps(const LbParams& params, const glm::ivec3& dims);

} // namespace sylva::lb
