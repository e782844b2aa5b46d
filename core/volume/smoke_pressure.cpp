// The smoke simulation's pressure projection (smoke.h): the walls' and obstacles' faces fixed, the
// pressure Poisson problem solved (smoke_multigrid.h), its gradient subtracted over the open faces.
#include <cmath>
#include <vector>

#include "core/base/parallel.h"
#include "core/volume/smoke.h"
#include "core/volume/smoke_grid.h"
#include "core/volume/smoke_multigrid.h"

namespace sylva::volume {

using smoke_detail::Dims;
using smoke_detail::forFluidCells;

double SmokeSim::divergenceNorm() const
{
    const Dims d{m_s.cells};
    const glm::ivec3 n = d.n;
    const double h = m_s.cellSize;
    // Slab by slab in parallel, the slabs' sums added in slab order.
    double out = 0.0;
    HostExec().sumRows<1>(size_t(n.x), d.slabCells(), [&](size_t slab, size_t, size_t, double* t) {
        const int i = int(slab);
        double acc = 0.0;
        for (int j = 0; j < n.y; ++j)
            for (int k = 0; k < n.z; ++k) {
                if (m_solid[d.cell(i, j, k)]) continue;
                const double div = (double(m_u[d.uIdx(i + 1, j, k)]) - double(m_u[d.uIdx(i, j, k)]) + double(m_v[d.vIdx(i, j + 1, k)]) -
                                    double(m_v[d.vIdx(i, j, k)]) + double(m_w[d.wIdx(i, j, k + 1)]) - double(m_w[d.wIdx(i, j, k)])) / h;
                acc += div * div;
            }
        t[0] = acc;
    }, &out);
    return std::sqrt(out);
}

void SmokeSim::project()
{
    const Dims d{m_s.cells};
    const glm::ivec3 n = d.n;
    // Faces next to a wall or an obstacle carry velocity 0 (the top faces stay free).
    HostExec().forEachRow(size_t(n.x + 1), d.slabCells(), [&](size_t slab, size_t, size_t) {
        const int i = int(slab);
        for (int j = 0; j < n.y; ++j)
            for (int k = 0; k < n.z; ++k)
                if (i == 0 || i == n.x || m_solid[d.cell(i - 1, j, k)] || m_solid[d.cell(i, j, k)]) m_u[d.uIdx(i, j, k)] = 0.0f;
    });
    HostExec().forEachRow(size_t(n.x), d.slabCells(), [&](size_t slab, size_t, size_t) {
        const int i = int(slab);
        for (int j = 0; j <= n.y; ++j)
            for (int k = 0; k < n.z; ++k) {
                const bool fixed = j == 0 || (j < n.y && m_solid[d.cell(i, j, k)]) || m_solid[d.cell(i, j - 1, k)];
                if (fixed) m_v[d.vIdx(i, j, k)] = 0.0f;
            }
        for (int j = 0; j < n.y; ++j)
            for (int k = 0; k <= n.z; ++k)
                if (k == 0 || k == n.z || m_solid[d.cell(i, j, k - 1)] || m_solid[d.cell(i, j, k)]) m_w[d.wIdx(i, j, k)] = 0.0f;
    });
    m_stats.divergenceBefore = divergenceNorm();
    // A psi = -D (D: the flux difference of a cell), then u -= grad psi over the open faces.
    std::vector<double>& rhs = m_rhs;
    rhs.assign(d.cell(n.x - 1, n.y - 1, n.z - 1) + 1, 0.0);
    forFluidCells(d, m_solid, [&](int i, int j, int k, size_t c) {
        rhs[c] = -(double(m_u[d.uIdx(i + 1, j, k)]) - double(m_u[d.uIdx(i, j, k)]) + double(m_v[d.vIdx(i, j + 1, k)]) -
                   double(m_v[d.vIdx(i, j, k)]) + double(m_w[d.wIdx(i, j, k + 1)]) - double(m_w[d.wIdx(i, j, k)]));
    });
    const auto [it, res] = m_solver->solve(rhs, m_pressure, m_s.pressureTolerance, m_s.pressureMaxIterations);
    m_stats.pressureIterations = it;
    m_stats.pressureResidual = res;
    const std::vector<double>& p = m_pressure;
    forFluidCells(d, m_solid, [&](int i, int j, int k, size_t c) {
        if (i + 1 < n.x && !m_solid[d.cell(i + 1, j, k)])
            m_u[d.uIdx(i + 1, j, k)] = float(double(m_u[d.uIdx(i + 1, j, k)]) - (p[d.cell(i + 1, j, k)] - p[c]));
        if (j + 1 < n.y && !m_solid[d.cell(i, j + 1, k)])
            m_v[d.vIdx(i, j + 1, k)] = float(double(m_v[d.vIdx(i, j + 1, k)]) - (p[d.cell(i, j + 1, k)] - p[c]));
        if (j + 1 == n.y) m_v[d.vIdx(i, n.y, k)] = float(double(m_v[d.vIdx(i, n.y, k)]) + p[c]);   // ghost pressure 0
        if (k + 1 < n.z && !m_solid[d.cell(i, j, k + 1)])
            m_w[d.wIdx(i, j, k + 1)] = float(double(m_w[d.wIdx(i, j, k + 1)]) - (p[d.cell(i, j, k + 1)] - p[c]));
    });
    m_stats.divergenceAfter = divergenceNorm();
}

} // namespace sylva::volume
