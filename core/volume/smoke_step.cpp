// The step of the smoke simulation (smoke.h) as its phases: forces, the CFL check, self-advection
// (smoke_advect.cpp), projection (smoke_pressure.cpp), advection of the scalars, decay and emission.
#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include <tbb/parallel_for.h>

#include "core/base/error.h"
#include "core/base/parallel.h"
#include "core/base/progress.h"
#include "core/volume/noise.h"
#include "core/volume/smoke.h"
#include "core/volume/smoke_grid.h"

namespace sylva::volume {

using smoke_detail::Dims;
using smoke_detail::forFluidCells;

namespace {

// Index ranges [lo, hi) along each axis, within [0, limit), that hold every cell or face whose point can
// lie in the shape (a margin of two cells): the loops over a source's cells and faces visit only these.
struct IndexBox {
    glm::ivec3 lo, hi;
    size_t slabs() const { return size_t(std::max(0, hi.x - lo.x)); }
    size_t slabCells() const { return size_t(std::max(0, hi.y - lo.y)) * size_t(std::max(0, hi.z - lo.z)); }
};

IndexBox shapeBox(const SmokeShape& shape, const SmokeSettings& s, const glm::ivec3& limit)
{
    const glm::vec3 extent = shape.kind == SmokeShape::Kind::Sphere ? glm::vec3(shape.radius) : shape.halfSize;
    const glm::vec3 a = (shape.centre - extent - s.origin) / s.cellSize, b = (shape.centre + extent - s.origin) / s.cellSize;
    const glm::vec3 lo = glm::clamp(glm::floor(a) - 2.0f, glm::vec3(0.0f), glm::vec3(limit));
    const glm::vec3 hi = glm::clamp(glm::ceil(b) + 2.0f, glm::vec3(0.0f), glm::vec3(limit));
    return {glm::ivec3(lo), glm::ivec3(hi)};
}

// The largest squared value in the three face fields, in parallel (a maximum: the same for any thread
// count); NaN when one of them holds a value that is not finite.
double maxSquare(const std::vector<float>& a, const std::vector<float>& b, const std::vector<float>& c)
{
    const std::vector<float>* fields[3] = {&a, &b, &c};
    constexpr size_t kChunk = 1 << 16;
    std::vector<std::pair<size_t, size_t>> chunks;
    for (int f = 0; f < 3; ++f)
        for (size_t at = 0; at < fields[f]->size(); at += kChunk) chunks.push_back({size_t(f), at});
    std::vector<double> partial(chunks.size(), 0.0);
    tbb::parallel_for(size_t(0), chunks.size(), [&](size_t ci) {
        const std::vector<float>& v = *fields[chunks[ci].first];
        const size_t end = std::min(v.size(), chunks[ci].second + kChunk);
        float m = 0.0f;
        bool finite = true;
        for (size_t i = chunks[ci].second; i < end; ++i) {
            finite = finite && std::isfinite(v[i]);
            m = std::max(m, std::fabs(v[i]));
        }
        partial[ci] = finite ? double(m) * double(m) : std::nan("");
    });
    double out = 0.0;
    for (double p : partial) {
        if (std::isnan(p)) return p;
        out = std::max(out, p);
    }
    return out;
}

} // namespace

void SmokeSim::step(Progress* progress)
{
    const float dt = m_s.dt;
    if (progress) progress->throwIfCancelled();
    // 1. Forces on a copy of the velocity (m_u1, m_v1, m_w1): buoyancy on the v faces, vorticity
    // confinement on all, then the sources' velocities on the faces inside them.
    m_u1 = m_u;
    m_v1 = m_v;
    m_w1 = m_w;
    addBuoyancy(dt);
    if (m_s.vorticity > 0.0f) addVorticityConfinement(dt);
    setSourceVelocities();
    // 2. The CFL check on the velocity that will advect: refuse before anything changes.
    m_stats.cfl = checkedCfl();
    if (progress) progress->throwIfCancelled();
    // 3. Self-advection (RK2 back-trace through the forced velocity).
    advectVelocity(dt);
    if (progress) progress->throwIfCancelled();
    // 4. Projection.
    project();
    if (progress) progress->throwIfCancelled();
    // 5. The scalars: advection, decay and emission.
    advectScalars(dt);
    decayScalars(dt);
    emitSources();
    const double speedSq = maxSquare(m_u, m_v, m_w);
    if (std::isnan(speedSq)) throw Error("simulate: the velocity is no longer finite at step " + std::to_string(m_steps + 1));
    m_stats.maxSpeed = std::sqrt(3.0 * speedSq);
    ++m_steps;
}

// Buoyancy on the v faces: down with the density, up with the temperature (the averages of the cells
// either side).
void SmokeSim::addBuoyancy(float dt)
{
    const Dims d{m_s.cells};
    const glm::ivec3 n = d.n;
    HostExec().forEachRow(size_t(n.x), d.slabCells(), [&](size_t slab, size_t, size_t) {
        const int i = int(slab);
        for (int j = 1; j <= n.y; ++j)
            for (int k = 0; k < n.z; ++k) {
                const size_t below = d.cell(i, j - 1, k);
                const size_t above = j < n.y ? d.cell(i, j, k) : below;
                const float rho = 0.5f * (m_density[below] + m_density[above]);
                const float temp = 0.5f * (m_temperature[below] + m_temperature[above]);
                m_v1[d.vIdx(i, j, k)] += dt * (-m_s.buoyancyDensity * rho + m_s.buoyancyTemperature * temp);
            }
    });
}

// Vorticity confinement (Fedkiw et al. 2001, section 4): the force epsilon h (N x omega) at the cell
// centres, N the normalized gradient of |omega|, averaged onto the faces.
void SmokeSim::addVorticityConfinement(float dt)
{
    const Dims d{m_s.cells};
    const glm::ivec3 n = d.n;
    const float h = m_s.cellSize;
    const size_t cells = m_density.size();
    // Every cell of the three is written below before it is read.
    m_centre.resize(cells);
    m_omega.resize(cells);
    m_vorticityMag.resize(cells);
    std::vector<glm::vec3>& centre = m_centre;
    std::vector<glm::vec3>& omega = m_omega;
    std::vector<float>& mag = m_vorticityMag;
    HostExec().forEachRow(size_t(n.x), d.slabCells(), [&](size_t slab, size_t, size_t) {
        const int i = int(slab);
        for (int j = 0; j < n.y; ++j)
            for (int k = 0; k < n.z; ++k)
                centre[d.cell(i, j, k)] = 0.5f * glm::vec3(m_u[d.uIdx(i, j, k)] + m_u[d.uIdx(i + 1, j, k)],
                                                           m_v[d.vIdx(i, j, k)] + m_v[d.vIdx(i, j + 1, k)],
                                                           m_w[d.wIdx(i, j, k)] + m_w[d.wIdx(i, j, k + 1)]);
    });
    auto at = [&](const std::vector<glm::vec3>& f, int i, int j, int k) {
        return f[d.cell(std::clamp(i, 0, n.x - 1), std::clamp(j, 0, n.y - 1), std::clamp(k, 0, n.z - 1))];
    };
    const float inv2h = 0.5f / h;
    HostExec().forEachRow(size_t(n.x), d.slabCells(), [&](size_t slab, size_t, size_t) {
        const int i = int(slab);
        for (int j = 0; j < n.y; ++j)
            for (int k = 0; k < n.z; ++k) {
                const glm::vec3 dx = (at(centre, i + 1, j, k) - at(centre, i - 1, j, k)) * inv2h;
                const glm::vec3 dy = (at(centre, i, j + 1, k) - at(centre, i, j - 1, k)) * inv2h;
                const glm::vec3 dz = (at(centre, i, j, k + 1) - at(centre, i, j, k - 1)) * inv2h;
                const glm::vec3 om(dy.z - dz.y, dz.x - dx.z, dx.y - dy.x);
                omega[d.cell(i, j, k)] = om;
                mag[d.cell(i, j, k)] = glm::length(om);
            }
    });
    auto magAt = [&](int i, int j, int k) {
        return mag[d.cell(std::clamp(i, 0, n.x - 1), std::clamp(j, 0, n.y - 1), std::clamp(k, 0, n.z - 1))];
    };
    std::vector<glm::vec3>& force = centre;   // reused
    HostExec().forEachRow(size_t(n.x), d.slabCells(), [&](size_t slab, size_t, size_t) {
        const int i = int(slab);
        for (int j = 0; j < n.y; ++j)
            for (int k = 0; k < n.z; ++k) {
                const size_t c = d.cell(i, j, k);
                if (m_solid[c]) {
                    force[c] = glm::vec3(0.0f);
                    continue;
                }
                const glm::vec3 g((magAt(i + 1, j, k) - magAt(i - 1, j, k)) * inv2h, (magAt(i, j + 1, k) - magAt(i, j - 1, k)) * inv2h,
                                  (magAt(i, j, k + 1) - magAt(i, j, k - 1)) * inv2h);
                const float len = glm::length(g);
                force[c] = len > 1e-20f ? m_s.vorticity * h * glm::cross(g / len, omega[c]) : glm::vec3(0.0f);
            }
    });
    HostExec().forEachRow(size_t(n.x + 1), d.slabCells(), [&](size_t slab, size_t, size_t) {
        const int i = int(slab);
        for (int j = 0; j < n.y; ++j)
            for (int k = 0; k < n.z; ++k)
                if (i > 0 && i < n.x) m_u1[d.uIdx(i, j, k)] += dt * 0.5f * (force[d.cell(i - 1, j, k)].x + force[d.cell(i, j, k)].x);
        if (i == n.x) return;
        for (int j = 1; j < n.y; ++j)
            for (int k = 0; k < n.z; ++k) m_v1[d.vIdx(i, j, k)] += dt * 0.5f * (force[d.cell(i, j - 1, k)].y + force[d.cell(i, j, k)].y);
        for (int j = 0; j < n.y; ++j)
            for (int k = 1; k < n.z; ++k) m_w1[d.wIdx(i, j, k)] += dt * 0.5f * (force[d.cell(i, j, k - 1)].z + force[d.cell(i, j, k)].z);
    });
}

// The sources' velocities on the faces inside each source.
void SmokeSim::setSourceVelocities()
{
    const Dims d{m_s.cells};
    const glm::ivec3 n = d.n;
    const float h = m_s.cellSize;
    for (const SmokeSource& src : m_s.sources) {
        if (src.velocity == glm::vec3(0.0f)) continue;
        const IndexBox box = shapeBox(src.shape, m_s, n + 1);
        HostExec().forEachRow(box.slabs(), box.slabCells(), [&](size_t slab, size_t, size_t) {
            const int i = box.lo.x + int(slab);
            for (int j = box.lo.y; j < box.hi.y; ++j)
                for (int k = box.lo.z; k < box.hi.z; ++k) {
                    if (j < n.y && k < n.z && src.shape.contains(m_s.origin + h * glm::vec3(float(i), j + 0.5f, k + 0.5f)))
                        m_u1[d.uIdx(i, j, k)] = src.velocity.x;
                    if (i < n.x && k < n.z && src.shape.contains(m_s.origin + h * glm::vec3(i + 0.5f, float(j), k + 0.5f)))
                        m_v1[d.vIdx(i, j, k)] = src.velocity.y;
                    if (i < n.x && j < n.y && src.shape.contains(m_s.origin + h * glm::vec3(i + 0.5f, j + 0.5f, float(k))))
                        m_w1[d.wIdx(i, j, k)] = src.velocity.z;
                }
        });
    }
}

// The CFL number of the forced velocity (a bound: each component at most its maximum); throws Error when
// the velocity is not finite or the number over the limit.
double SmokeSim::checkedCfl() const
{
    const double maxSq = maxSquare(m_u1, m_v1, m_w1);
    if (std::isnan(maxSq)) throw Error("simulate: the velocity is no longer finite at step " + std::to_string(m_steps + 1));
    const double cfl = std::sqrt(3.0 * maxSq) * m_s.dt / m_s.cellSize;
    if (cfl > m_s.cflLimit)
        throw Error("simulate: step " + std::to_string(m_steps + 1) + " would move the smoke " + numberText(cfl) +
                    " cells (CFL number), over the limit " + numberText(m_s.cflLimit) + "; lower the time step (--dt) or the forces");
    return cfl;
}

// The fluid cells' density and temperature lose their decay rates' share over dt.
void SmokeSim::decayScalars(float dt)
{
    const Dims d{m_s.cells};
    const float keepD = 1.0f - m_s.densityDecay * dt, keepT = 1.0f - m_s.temperatureDecay * dt;
    forFluidCells(d, m_solid, [&](int, int, int, size_t c) {
        m_density[c] *= keepD;
        m_temperature[c] *= keepT;
    });
}

// Emission: the maximum of what is there and each source (in any order: max commutes), the density
// jittered per step and cell from the seed.
void SmokeSim::emitSources()
{
    const Dims d{m_s.cells};
    const glm::ivec3 n = d.n;
    const float h = m_s.cellSize;
    const uint64_t stepSeed = m_s.seed * 0x9E3779B97F4A7C15ull + uint64_t(m_steps);
    for (const SmokeSource& src : m_s.sources) {
        const IndexBox box = shapeBox(src.shape, m_s, n);
        HostExec().forEachRow(box.slabs(), box.slabCells(), [&](size_t slab, size_t, size_t) {
            const int i = box.lo.x + int(slab);
            for (int j = box.lo.y; j < box.hi.y; ++j)
                for (int k = box.lo.z; k < box.hi.z; ++k) {
                    const size_t c = d.cell(i, j, k);
                    if (m_solid[c] || !src.shape.contains(m_s.origin + h * (glm::vec3(i, j, k) + 0.5f))) continue;
                    uint64_t state = stepSeed ^ (uint64_t(c) * 0xD1B54A32D192ED03ull);
                    const float r = float(double(splitmix64(state) >> 11) * (1.0 / 9007199254740992.0)) * 2.0f - 1.0f;
                    m_density[c] = std::max(m_density[c], std::clamp(src.density * (1.0f + m_s.jitter * r), 0.0f, 1.0f));
                    m_temperature[c] = std::max(m_temperature[c], src.temperature);
                }
        });
    }
}

} // namespace sylva::volume
