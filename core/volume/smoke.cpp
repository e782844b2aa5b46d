// The smoke simulation (smoke.h): its settings, their checks and the set-up of the grid. The step's phases
// are in smoke_step.cpp, the advection in smoke_advect.cpp (with smoke_interp.cpp's cubic interpolation),
// the projection in smoke_pressure.cpp and its solver in smoke_multigrid.cpp.
#include "core/volume/smoke.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "core/base/error.h"
#include "core/base/memory.h"
#include "core/volume/smoke_grid.h"
#include "core/volume/smoke_multigrid.h"

namespace sylva::volume {


namespace {

bool finite3(const glm::vec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

} // namespace

bool SmokeShape::contains(const glm::vec3& p) const
{
    if (kind == Kind::Sphere) return glm::dot(p - centre, p - centre) <= radius * radius;
    const glm::vec3 d = glm::abs(p - centre);
    return d.x <= halfSize.x && d.y <= halfSize.y && d.z <= halfSize.z;
}

void setSmokeDomain(SmokeSettings& s, float width)
{
    checkParam(kSmokeWidth, width, "simulate");
    s.cellSize = width / float(std::max(1, s.cells.x));
    s.origin = glm::vec3(-0.5f * width, 0.0f, -0.5f * float(s.cells.z) * s.cellSize);
}

SmokeShape defaultSmokeSource(const SmokeSettings& s, float width)
{
    SmokeShape sphere;
    sphere.centre = glm::vec3(0.0f, 0.15f * float(s.cells.y) * s.cellSize, 0.0f);
    sphere.radius = 0.1f * width;
    return sphere;
}

double smokeBytes(const glm::ivec3& c)
{
    const double cells = double(c.x) * double(c.y) * double(c.z);
    // 5 fields + 5 scratch floats, masks, pressure + 4 CG vectors and the multigrid levels (3 vectors,
    // 1/7 of the cells more) in double.
    return cells * (10.0 * 4.0 + 4.0 + 5.0 * 8.0 + 3.0 * 8.0 * 8.0 / 7.0);
}

void validateSmoke(const SmokeSettings& s)
{
    auto fail = [](const std::string& what) { throw Error("simulate: " + what); };
    for (int a = 0; a < 3; ++a)
        if (!paramHolds(kSmokeCells, (long long)s.cells[a]))
            fail("grid size " + std::to_string(s.cells.x) + "x" + std::to_string(s.cells.y) + "x" + std::to_string(s.cells.z) +
                 ": every axis needs " + paramRange(kSmokeCells) + " cells");
    const double need = smokeBytes(s.cells), have = availableMemoryBytes();
    if (have > 0.0 && need > have)
        fail("a " + std::to_string(s.cells.x) + "x" + std::to_string(s.cells.y) + "x" + std::to_string(s.cells.z) + " grid needs " +
             numberText(need / 1048576.0) + " MiB but only " + numberText(have / 1048576.0) + " MiB are available");
    if (!(std::isfinite(s.cellSize) && s.cellSize > 0.0f)) fail("cell size " + numberText(s.cellSize) + " must be finite and > 0");
    checkParam(kSmokeDt, s.dt, "simulate", "time step");
    if (!finite3(s.origin)) fail("origin must be finite");
    if (!std::isfinite(s.buoyancyDensity) || !std::isfinite(s.buoyancyTemperature)) fail("buoyancy must be finite");
    checkParam(kSmokeVorticity, s.vorticity, "simulate");
    if (!(s.densityDecay >= 0.0f && s.densityDecay * s.dt <= 1.0f))
        fail("density decay " + numberText(s.densityDecay) + " must be >= 0 and at most 1 / dt");
    if (!(s.temperatureDecay >= 0.0f && s.temperatureDecay * s.dt <= 1.0f))
        fail("temperature decay " + numberText(s.temperatureDecay) + " must be >= 0 and at most 1 / dt");
    checkParam(kSmokeJitter, s.jitter, "simulate");
    checkParam(kSmokeTolerance, s.pressureTolerance, "simulate");
    checkParam(kSmokeSeed, s.seed, "simulate");
    if (s.pressureMaxIterations < 1) fail("pressure iterations must be >= 1");
    if (!(std::isfinite(s.cflLimit) && s.cflLimit > 0.0f)) fail("CFL limit must be finite and > 0");
    auto checkShape = [&](const SmokeShape& sh, const std::string& what) {
        if (!finite3(sh.centre)) fail(what + ": centre must be finite");
        if (sh.kind == SmokeShape::Kind::Sphere && !(std::isfinite(sh.radius) && sh.radius > 0.0f))
            fail(what + ": radius " + numberText(sh.radius) + " must be finite and > 0");
        if (sh.kind == SmokeShape::Kind::Box && !(finite3(sh.halfSize) && glm::all(glm::greaterThan(sh.halfSize, glm::vec3(0.0f)))))
            fail(what + ": box half sizes must be finite and > 0");
    };
    for (size_t i = 0; i < s.sources.size(); ++i) {
        const SmokeSource& src = s.sources[i];
        const std::string what = "source " + std::to_string(i + 1);
        checkShape(src.shape, what);
        checkParam(kSmokeSourceDensity, src.density, "simulate: " + what, "density");
        checkParam(kSmokeSourceTemperature, src.temperature, "simulate: " + what, "temperature");
        if (!finite3(src.velocity)) fail(what + ": velocity must be finite");
        const float cfl = glm::length(src.velocity) * s.dt / s.cellSize;
        if (cfl > s.cflLimit)
            fail(what + ": its velocity moves " + numberText(cfl) + " cells per step, over the CFL limit " + numberText(s.cflLimit) +
                 " (lower the time step or the speed)");
    }
    for (size_t i = 0; i < s.obstacles.size(); ++i) checkShape(s.obstacles[i], "obstacle " + std::to_string(i + 1));
}

// ---- the simulation ----

SmokeSim::SmokeSim(const SmokeSettings& settings) : m_s(settings)
{
    validateSmoke(m_s);
    const glm::ivec3 n = m_s.cells;
    const size_t cells = size_t(n.x) * size_t(n.y) * size_t(n.z);
    m_density.assign(cells, 0.0f);
    m_temperature.assign(cells, 0.0f);
    m_u.assign(size_t(n.x + 1) * size_t(n.y) * size_t(n.z), 0.0f);
    m_v.assign(size_t(n.x) * size_t(n.y + 1) * size_t(n.z), 0.0f);
    m_w.assign(size_t(n.x) * size_t(n.y) * size_t(n.z + 1), 0.0f);
    m_solid.assign(cells, 0);
    m_pressure.assign(cells, 0.0);
    const float h = m_s.cellSize;
    for (int i = 0; i < n.x; ++i)
        for (int j = 0; j < n.y; ++j)
            for (int k = 0; k < n.z; ++k) {
                const glm::vec3 p = m_s.origin + h * (glm::vec3(i, j, k) + 0.5f);
                for (const SmokeShape& o : m_s.obstacles)
                    if (o.contains(p)) m_solid[(size_t(i) * size_t(n.y) + size_t(j)) * size_t(n.z) + size_t(k)] = 1;
            }
    // Fluid cells with no path to the open top would make the pressure system singular: they join the
    // obstacles (flood fill from the top row).
    std::vector<uint8_t> reach(cells, 0);
    std::vector<size_t> stack;
    auto cellIndex = [&](int i, int j, int k) { return (size_t(i) * size_t(n.y) + size_t(j)) * size_t(n.z) + size_t(k); };
    for (int i = 0; i < n.x; ++i)
        for (int k = 0; k < n.z; ++k) {
            const size_t c = cellIndex(i, n.y - 1, k);
            if (!m_solid[c]) {
                reach[c] = 1;
                stack.push_back(c);
            }
        }
    while (!stack.empty()) {
        const size_t c = stack.back();
        stack.pop_back();
        const int k = int(c % size_t(n.z)), j = int((c / size_t(n.z)) % size_t(n.y)), i = int(c / (size_t(n.z) * size_t(n.y)));
        const glm::ivec3 nb[6] = {{i - 1, j, k}, {i + 1, j, k}, {i, j - 1, k}, {i, j + 1, k}, {i, j, k - 1}, {i, j, k + 1}};
        for (const glm::ivec3& q : nb) {
            if (q.x < 0 || q.y < 0 || q.z < 0 || q.x >= n.x || q.y >= n.y || q.z >= n.z) continue;
            const size_t d = cellIndex(q.x, q.y, q.z);
            if (m_solid[d] || reach[d]) continue;
            reach[d] = 1;
            stack.push_back(d);
        }
    }
    for (size_t c = 0; c < cells; ++c)
        if (!reach[c]) m_solid[c] = 1;
    std::vector<uint8_t> fluid(cells);
    for (size_t c = 0; c < cells; ++c) fluid[c] = uint8_t(!m_solid[c]);
    m_solver = std::make_unique<PressureSolver>(fluid, n);
}


SmokeSim::~SmokeSim() = default;

DensityGrid SmokeSim::densityGrid() const
{
    DensityGrid g;
    g.geometry.dims = m_s.cells;
    g.geometry.spacing = m_s.cellSize;
    g.geometry.origin = glm::dvec3(m_s.origin) + 0.5 * double(m_s.cellSize);
    g.density = m_density;
    g.woodFraction.assign(m_density.size(), 0.0f);
    return g;
}

DensityGrid SmokeSim::temperatureGrid() const
{
    DensityGrid g = densityGrid();
    g.density = m_temperature;
    return g;
}

} // namespace sylva::volume
