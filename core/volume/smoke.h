// Smoke simulation (the graphics-blog post "Adventures in Fluid Simulation"; Fedkiw, Stam & Jensen 2001 "Visual
// Simulation of Smoke"): stable fluids on a MAC grid with buoyancy from temperature, vorticity
// confinement, sources and obstacles. Public API for `sylva simulate` and for a studio job.
//
// Grid: nx x ny x nz cubic cells of side h, y up. Scalars (density, temperature) at cell centres;
// velocity components on the faces (u on x faces, (nx+1) ny nz of them, and so on). The top face
// (y = ny h) is open (pressure 0, smoke leaves); the other five are walls; obstacles are cells whose
// centre lies in an obstacle shape (their faces carry velocity 0).
// One step (dt): sources -> forces (buoyancy, vorticity confinement) -> self-advection of the velocity
// (semi-Lagrangian, RK2 back-trace) -> pressure projection (CG preconditioned by a geometric multigrid
// V-cycle, in double, relative residual below pressureTolerance) -> advection of density and temperature
// by the divergence-free velocity. Interpolation: trilinear, or monotonic tricubic (Fedkiw et al. 2001,
// section 5: Hermite with slopes zeroed where they disagree with the secant).
// Deterministic: every parallel loop writes disjoint cells and every sum is added in a fixed chunk
// order (HostExec), so the same settings (seed included) give the same bits for any thread count.
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include <glm/glm.hpp>

#include "core/base/param_spec.h"
#include "core/grid/grid.h"

namespace sylva {
class Progress;
}

namespace sylva::volume {

class PressureSolver;   // smoke_multigrid.h

// The parameters `sylva simulate` and the studio's smoke form set, each declared once
// (core/base/param_spec.h): the members' defaults, validateSmoke, the options and --help, the form's
// widgets and docs/CLI.md's table read these.
inline constexpr ParamSpec kSmokeCells{.key = "grid", .kind = ParamSpec::Kind::Integer, .metavar = "X,Y,Z", .count = 3, .lo = 3, .hi = 512,
                                       .def = {64, 96, 64}, .help = "cells per axis"};
inline constexpr ParamSpec kSmokeWidth{.key = "size", .metavar = "W", .lo = 0.0, .loOpen = true, .def = {1.0},
                                       .help = "domain width along x, metres; cells are cubes"};
inline constexpr ParamSpec kSmokeDt{.key = "dt", .metavar = "S", .lo = 0.0, .loOpen = true, .def = {0.02},
                                    .help = "time step, seconds"};
inline constexpr ParamSpec kSmokeSteps{.key = "steps", .kind = ParamSpec::Kind::Integer, .metavar = "N", .lo = 1, .hi = 1000000,
                                       .def = {100}, .help = "steps to run"};
inline constexpr ParamSpec kSmokeBuoyancy{.key = "buoyancy", .metavar = "A,B", .count = 2, .def = {0.05, 2.0},
                                          .help = "force per unit density (down) and per unit temperature (up), m/s^2"};
inline constexpr ParamSpec kSmokeVorticity{.key = "vorticity", .metavar = "E", .lo = 0.0, .def = {0.3},
                                           .help = "vorticity confinement epsilon, 0 = off"};
inline constexpr ParamSpec kSmokeJitter{.key = "jitter", .metavar = "J", .lo = 0.0, .hi = 1.0, .def = {0.2},
                                        .help = "source density noise"};
inline constexpr ParamSpec kSmokeTolerance{.key = "tol", .metavar = "T", .lo = 0.0, .hi = 1.0, .loOpen = true, .hiOpen = true,
                                           .def = {1e-6}, .help = "relative residual of the pressure solve"};
inline constexpr ParamSpec kSmokeSeed{.key = "seed", .kind = ParamSpec::Kind::Integer, .metavar = "N", .lo = 0, .hi = double(kMaxSeed),
                                      .def = {1}, .help = "seed of the source noise", .note = "; the same seed gives the same bits"};
inline constexpr ParamSpec kSmokeSourceDensity{.key = "source-density", .metavar = "D", .lo = 0.0, .hi = 1.0, .def = {1.0},
                                               .help = "density the sources set"};
inline constexpr ParamSpec kSmokeSourceTemperature{.key = "source-temperature", .metavar = "T", .lo = 0.0, .def = {1.0},
                                                   .help = "temperature the sources set, above ambient"};
inline constexpr ParamSpec kSmokeSourceVelocity{.key = "source-velocity", .metavar = "X,Y,Z", .count = 3, .def = {0.0, 0.0, 0.0},
                                                .help = "velocity inside the sources, m/s"};
inline constexpr const ParamSpec* kSmokeParams[] = {&kSmokeCells,     &kSmokeWidth,         &kSmokeDt,
                                                    &kSmokeSteps,     &kSmokeBuoyancy,      &kSmokeVorticity,
                                                    &kSmokeJitter,    &kSmokeTolerance,     &kSmokeSeed,
                                                    &kSmokeSourceDensity, &kSmokeSourceTemperature, &kSmokeSourceVelocity};

enum class SmokeInterp { Linear, MonotonicCubic };

// A sphere (radius > 0) or an axis-aligned box (halfSize > 0 on every axis), world metres.
struct SmokeShape {
    enum class Kind { Sphere, Box } kind = Kind::Sphere;
    glm::vec3 centre{0.0f};
    float radius = 0.1f;
    glm::vec3 halfSize{0.1f};
    bool contains(const glm::vec3& p) const;
};

// Each step, cells whose centre lies in the shape get density = max(density, this density * (1 + jitter
// * r)) (r in [-1, 1] from the seed, the step and the cell), temperature = max(temperature, this one),
// and the faces inside take the source velocity.
struct SmokeSource {
    SmokeShape shape;
    float density = float(kSmokeSourceDensity.def[0]);
    float temperature = float(kSmokeSourceTemperature.def[0]);   // in the simulation's temperature unit
    glm::vec3 velocity{float(kSmokeSourceVelocity.def[0]), float(kSmokeSourceVelocity.def[1]), float(kSmokeSourceVelocity.def[2])};
};

struct SmokeSettings {
    glm::ivec3 cells{int(kSmokeCells.def[0]), int(kSmokeCells.def[1]), int(kSmokeCells.def[2])};   // nx, ny, nz
    float cellSize = float(kSmokeWidth.def[0]) / float(kSmokeCells.def[0]);   // h, metres
    glm::vec3 origin{0.0f};         // world position of the domain's lower corner
    float dt = float(kSmokeDt.def[0]);   // seconds per step
    float buoyancyDensity = float(kSmokeBuoyancy.def[0]);       // alpha: downward force per unit density
    float buoyancyTemperature = float(kSmokeBuoyancy.def[1]);   // beta: upward force per unit temperature
    float vorticity = float(kSmokeVorticity.def[0]);            // epsilon of the confinement force
    float densityDecay = 0.0f;      // fraction of density lost per second (0: none)
    float temperatureDecay = 0.5f;  // fraction of temperature lost per second
    float jitter = float(kSmokeJitter.def[0]);
    SmokeInterp interp = SmokeInterp::Linear;
    double pressureTolerance = kSmokeTolerance.def[0];
    int pressureMaxIterations = 200;
    float cflLimit = 5.0f;          // a step that moves anything more than this many cells is refused
    uint64_t seed = uint64_t(kSmokeSeed.def[0]);
    std::vector<SmokeSource> sources;
    std::vector<SmokeShape> obstacles;
};

// Statistics of the last step.
struct SmokeStepStats {
    int pressureIterations = 0;
    double pressureResidual = 0.0;    // relative
    double divergenceBefore = 0.0;    // L2 norm over fluid cells of div u before projection (1/s)
    double divergenceAfter = 0.0;     // ... after
    double maxSpeed = 0.0;            // m/s, after the step
    double cfl = 0.0;                 // maxSpeed * dt / h of the velocity that advected this step
};

// Throws sylva::Error naming the setting for values out of range (sizes 0 or over 512, a grid over the
// memory limit (SYLVA_MEMORY_LIMIT_MB or what the machine has), dt <= 0, NaN, densities outside [0, 1]).
void validateSmoke(const SmokeSettings& settings);
// The domain `sylva simulate` and the studio's smoke job set up: cubic cells, `width` metres along x, the
// floor at y = 0 and the domain centred on the y axis (sets cellSize and origin from cells). Width must be > 0.
void setSmokeDomain(SmokeSettings& settings, float width);
// Their default source: one sphere at the bottom centre (15% of the height up), a tenth of the width in radius.
SmokeShape defaultSmokeSource(const SmokeSettings& settings, float width);

// Bytes the simulation holds for these cells (the memory check uses it).
double smokeBytes(const glm::ivec3& cells);

class SmokeSim {
public:
    explicit SmokeSim(const SmokeSettings& settings);   // validates; starts at rest, empty
    ~SmokeSim();
    SmokeSim(const SmokeSim&) = delete;
    SmokeSim& operator=(const SmokeSim&) = delete;

    // One step. Throws sylva::Error when the step would violate the CFL limit (the velocity times dt
    // exceeds cflLimit cells; nothing is changed) or the fields stop being finite; Cancelled when the
    // progress object was cancelled (between stages).
    void step(Progress* progress = nullptr);
    int stepCount() const { return m_steps; }
    const SmokeStepStats& lastStats() const { return m_stats; }
    const SmokeSettings& settings() const { return m_s; }

    // Fields (z fastest, as every grid): density and temperature per cell; velocity per face.
    std::vector<float>& density() { return m_density; }
    std::vector<float>& temperature() { return m_temperature; }
    std::vector<float>& u() { return m_u; }
    std::vector<float>& v() { return m_v; }
    std::vector<float>& w() { return m_w; }
    const std::vector<float>& density() const { return m_density; }
    const std::vector<float>& temperature() const { return m_temperature; }
    const std::vector<uint8_t>& solid() const { return m_solid; }   // 1 for obstacle cells

    // Stages, public for tests: project the current velocity (returns the stats' divergence fields)
    // and advect the scalars by the current velocity for dt.
    void project();
    void advectScalars(float dt);
    // L2 norm of the divergence over fluid cells (1/s).
    double divergenceNorm() const;

    // The density (or temperature) as a grid: node (i,j,k) at the centre of cell (i,j,k).
    DensityGrid densityGrid() const;
    DensityGrid temperatureGrid() const;   // temperature in .density (not bounded to [0, 1])

private:
    // The phases of step() after the copy of the velocity into m_u1, m_v1, m_w1 (smoke_step.cpp; the
    // self-advection in smoke_advect.cpp): the forces on the copy, the CFL number of the copy (throws
    // over the limit), the copy advected into m_u, m_v, m_w, then (after project and advectScalars) the
    // scalars' decay and the sources' emission.
    void addBuoyancy(float dt);
    void addVorticityConfinement(float dt);
    void setSourceVelocities();
    double checkedCfl() const;
    void advectVelocity(float dt);
    void decayScalars(float dt);
    void emitSources();

    SmokeSettings m_s;
    int m_steps = 0;
    SmokeStepStats m_stats;
    std::vector<float> m_density, m_temperature, m_u, m_v, m_w;
    std::vector<uint8_t> m_solid;
    std::vector<double> m_pressure;
    std::unique_ptr<PressureSolver> m_solver;
    // Scratch kept from step to step: a step allocating these afresh spent over a third of its time
    // in the kernel clearing new pages (perf, 128^3). Their values never carry over.
    std::vector<float> m_u1, m_v1, m_w1, m_oldDensity, m_oldTemperature, m_vorticityMag;
    std::vector<glm::vec3> m_centre, m_omega;
    std::vector<double> m_rhs;
};

} // namespace sylva::volume
