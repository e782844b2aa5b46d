// Pyroclastic cloud volumes (the graphics-blog post "Adventures in Fluid Simulation",
// its "CreatePyroclasticVolume"): a sphere's distance field displaced
// outward by |fBm Perlin noise|. Public API for the CLI (`sylva volume cloud`) and for scenes that build
// a cloud in place of reading a grid.
#pragma once

#include <cstdint>

#include <glm/glm.hpp>

#include "core/base/param_spec.h"
#include "core/grid/grid.h"

namespace sylva::volume {

// Bump when a change alters the grids makePyroclasticCloud returns (for cache keys).
inline constexpr int kPyroclasticVersion = 1;

// The parameters, each declared once (core/base/param_spec.h): `sylva volume cloud`'s options and
// --help, the studio's Add Cloud form, validatePyroclastic and docs/CLI.md's table read these.
inline constexpr ParamSpec kCloudRadius{.key = "radius", .metavar = "R", .lo = 0.0, .loOpen = true, .def = {1.0},
                                        .help = "radius R of the undisplaced sphere, metres"};
inline constexpr ParamSpec kCloudAmplitude{.key = "amplitude", .metavar = "A", .lo = 0.0, .def = {0.5},
                                           .help = "largest outward displacement A by the noise, metres",
                                           .note = "; the surface radius lies in [R, R + A]"};
inline constexpr ParamSpec kCloudFrequency{.key = "frequency", .metavar = "F", .lo = 0.0, .loOpen = true, .def = {1.5},
                                           .help = "noise cells per metre of the first octave"};
inline constexpr ParamSpec kCloudOctaves{.key = "octaves", .kind = ParamSpec::Kind::Integer, .metavar = "N", .lo = 1, .hi = 12,
                                         .def = {4}, .help = "fBm octaves (lacunarity 2, gain 0.5)"};
inline constexpr ParamSpec kCloudResolution{.key = "resolution", .kind = ParamSpec::Kind::Integer, .metavar = "N", .lo = 8, .hi = 512,
                                            .def = {128}, .help = "nodes per axis of the cubic grid"};
inline constexpr ParamSpec kCloudDensity{.key = "density", .metavar = "D", .lo = 0.0, .hi = 1.0, .loOpen = true, .def = {1.0},
                                         .help = "density inside the cloud"};
inline constexpr ParamSpec kCloudSeed{.key = "seed", .kind = ParamSpec::Kind::Integer, .metavar = "N", .lo = 0, .hi = double(kMaxSeed),
                                      .def = {1}, .help = "noise seed", .note = "; the same seed gives the same grid"};
inline constexpr ParamSpec kCloudCentre{.key = "centre", .metavar = "X,Y,Z", .count = 3, .def = {0.0, 0.0, 0.0},
                                        .help = "world position of the sphere's centre, metres"};
inline constexpr const ParamSpec* kCloudParams[] = {&kCloudRadius,     &kCloudAmplitude, &kCloudFrequency, &kCloudOctaves,
                                                    &kCloudResolution, &kCloudDensity,   &kCloudSeed,      &kCloudCentre};

// 36 bytes.
struct PyroclasticParams {
    float radius = float(kCloudRadius.def[0]);
    float amplitude = float(kCloudAmplitude.def[0]);
    float frequency = float(kCloudFrequency.def[0]);
    int octaves = int(kCloudOctaves.def[0]);
    int resolution = int(kCloudResolution.def[0]);
    float density = float(kCloudDensity.def[0]);
    uint64_t seed = uint64_t(kCloudSeed.def[0]);
    glm::vec3 centre{float(kCloudCentre.def[0]), float(kCloudCentre.def[1]), float(kCloudCentre.def[2])};
};

// The cloud's surface radius toward world point p (relative to the centre):
//   r_s(p) = R + A * |fbm(p * frequency, octaves)|, p inside where |p| < r_s(p).
// Exposed so tests (and a renderer that wants an analytic cloud) evaluate the published formula.
float pyroclasticSurfaceRadius(const PyroclasticParams& params, const glm::vec3& offsetFromCentre);

// Grid geometry of the cloud: resolution^3 nodes, node 0 and resolution-1 an empty margin on every
// axis, the interior cells covering the cube of half side R + A around the centre.
GridGeometry pyroclasticGeometry(const PyroclasticParams& params);

// The density grid: density * clamp(0.5 + (r_s(p) - |p|) / spacing, 0, 1) at every node p (a one-node
// anti-aliased edge), 0 on the margin; woodFraction all 0 (a medium, not biomass). Deterministic: the
// same parameters give the same bits for any thread count. Throws sylva::Error naming the parameter
// for values out of range (NaN included).
DensityGrid makePyroclasticCloud(const PyroclasticParams& params);

// Throws sylva::Error for parameters out of range (as makePyroclasticCloud).
void validatePyroclastic(const PyroclasticParams& params);

} // namespace sylva::volume
