// The pressure solve of the smoke simulation (smoke_multigrid.h): CG in double, preconditioned by a
// geometric multigrid V-cycle in float.
#include "core/volume/smoke_multigrid.h"

#include <algorithm>
#include <bit>
#include <cmath>

#include "core/base/parallel.h"

namespace sylva::volume {
namespace {

// The rows around row (i, j) of a grid of n cells: the row itself and its four neighbours along x and y,
// a row of zeros where the neighbour lies beyond the wall. The operator reads its neighbours without
// masks: every vector it is applied to is 0 off the fluid, so a solid neighbour adds nothing either.
template <class T>
struct StencilRows {
    const T *c, *xm, *xp, *ym, *yp;
    int nz;
    StencilRows(const glm::ivec3& n, const T* x, const T* zeros, int i, int j)
    {
        const size_t sx = size_t(n.y) * size_t(n.z), sy = size_t(n.z);
        c = x + (size_t(i) * size_t(n.y) + size_t(j)) * size_t(n.z);
        xm = i > 0 ? c - sx : zeros;
        xp = i + 1 < n.x ? c + sx : zeros;
        ym = j > 0 ? c - sy : zeros;
        yp = j + 1 < n.y ? c + sy : zeros;
        nz = n.z;
    }
    T neighbours(int k) const
    {
        T s = xm[k] + xp[k] + ym[k] + yp[k];
        if (k > 0) s += c[k - 1];
        if (k + 1 < nz) s += c[k + 1];
        return s;
    }
    // neighbours(k) for 0 < k < nz - 1, without the branches: the same sum, so loops over the row's
    // inside vectorize (the ends go through neighbours).
    T inner(int k) const { return xm[k] + xp[k] + ym[k] + yp[k] + c[k - 1] + c[k + 1]; }
};

// 1 / the neighbour count, 0 for count 0 (a cell off the fluid, so a sweep writes 0 there), in arithmetic a
// loop vectorizes.
[[gnu::always_inline]] inline float inverseCount(uint8_t count)
{
    const int c = count;
    return float(c != 0 ? 1 : 0) / float(c > 1 ? c : 1);
}

// pick ? a : b, and keep ? a : +0, on the bits: GCC does not turn a ?: of floats into a vector blend under
// -ftrapping-math (the default), so the stencil loops select this way; the same values as the ?:.
[[gnu::always_inline]] inline float selectBits(bool pick, float a, float b)
{
    const uint32_t m = uint32_t(0) - uint32_t(pick);
    return std::bit_cast<float>((std::bit_cast<uint32_t>(a) & m) | (std::bit_cast<uint32_t>(b) & ~m));
}
[[gnu::always_inline]] inline float keepOrZero(bool keep, float a)
{
    return std::bit_cast<float>(std::bit_cast<uint32_t>(a) & (uint32_t(0) - uint32_t(keep)));
}
[[gnu::always_inline]] inline double keepOrZero(bool keep, double a)
{
    return std::bit_cast<double>(std::bit_cast<uint64_t>(a) & (uint64_t(0) - uint64_t(keep)));
}

} // namespace

PressureSolver::PressureSolver(const std::vector<uint8_t>& fluid0, const glm::ivec3& n0)
{
    std::vector<std::vector<uint8_t>> fluid{fluid0};
    Level l0;
    l0.n = n0;
    levels.push_back(std::move(l0));
    while (true) {
        const Level& f = levels.back();
        if (glm::min(f.n.x, glm::min(f.n.y, f.n.z)) < 8 || f.cells() <= 4096) break;
        Level c;
        c.n = (f.n + 1) / 2;
        std::vector<uint8_t> cf(c.cells(), 0);
        const std::vector<uint8_t>& ff = fluid.back();
        for (int i = 0; i < f.n.x; ++i)
            for (int j = 0; j < f.n.y; ++j)
                for (int k = 0; k < f.n.z; ++k)
                    if (ff[f.index(i, j, k)]) cf[c.index(i / 2, j / 2, k / 2)] = 1;
        levels.push_back(std::move(c));
        fluid.push_back(std::move(cf));
    }
    for (size_t li = 0; li < levels.size(); ++li) {
        Level& l = levels[li];
        const std::vector<uint8_t>& fl = fluid[li];
        l.count.assign(l.cells(), 0);
        for (int i = 0; i < l.n.x; ++i)
            for (int j = 0; j < l.n.y; ++j)
                for (int k = 0; k < l.n.z; ++k) {
                    const size_t c = l.index(i, j, k);
                    if (!fl[c]) continue;
                    int d = j == l.n.y - 1 ? 1 : 0;   // the open top: a pressure-0 ghost
                    if (i > 0) d += fl[l.index(i - 1, j, k)];
                    if (i < l.n.x - 1) d += fl[l.index(i + 1, j, k)];
                    if (j > 0) d += fl[l.index(i, j - 1, k)];
                    if (j < l.n.y - 1) d += fl[l.index(i, j + 1, k)];
                    if (k > 0) d += fl[l.index(i, j, k - 1)];
                    if (k < l.n.z - 1) d += fl[l.index(i, j, k + 1)];
                    l.count[c] = uint8_t(d);   // 0 for a fluid cell with no fluid neighbour: it leaves the system
                }
        l.x.assign(l.cells(), 0.0f);
        l.b.assign(l.cells(), 0.0f);
        l.tmp.assign(l.cells(), 0.0f);
        l.zeros.assign(size_t(l.n.z), 0.0f);
    }
    const size_t n = levels[0].cells();
    r.assign(n, 0.0);
    s.assign(n, 0.0);
    q.assign(n, 0.0);
    zeros.assign(size_t(n0.z), 0.0);
}

// q = A x on the finest level (0 off the fluid); returns x . q.
double PressureSolver::applyDot(const double* x, double* out) const
{
    const Level& l = levels[0];
    double xq = 0.0;
    HostExec().sumRows<1>(size_t(l.n.x), size_t(l.n.y) * size_t(l.n.z), [&](size_t slab, size_t, size_t, double* t) {
        const int i = int(slab);
        double acc = 0.0;
        for (int j = 0; j < l.n.y; ++j) {
            const StencilRows<double> rows(l.n, x, zeros.data(), i, j);
            const size_t base = l.index(i, j, 0);
            const uint8_t* cnt = l.count.data() + base;
            double* y = out + base;
            const int nz = l.n.z;
            const auto edge = [&](int k) { y[k] = cnt[k] ? double(cnt[k]) * rows.c[k] - rows.neighbours(k) : 0.0; };
            edge(0);
            for (int k = 1; k < nz - 1; ++k) y[k] = keepOrZero(cnt[k] != 0, double(cnt[k]) * rows.c[k] - rows.inner(k));
            if (nz > 1) edge(nz - 1);
            for (int k = 0; k < nz; ++k) acc += rows.c[k] * y[k];
        }
        t[0] = acc;
    }, &xq);
    return xq;
}

// One Gauss-Seidel sweep over the cells of one colour ((i + j + k) % 2 == colour) of slab i, in place: the
// cells of a colour depend only on the other colour, so slabs run in any order and the result does not
// depend on the thread count.
void PressureSolver::sweepSlab(Level& l, int colour, int i)
{
    for (int j = 0; j < l.n.y; ++j) {
        const StencilRows<float> rows(l.n, l.x.data(), l.zeros.data(), i, j);
        const size_t base = l.index(i, j, 0);
        float* x = l.x.data() + base;
        const float* b = l.b.data() + base;
        const uint8_t* cnt = l.count.data() + base;
        const int nz = l.n.z, first = (i + j + colour) & 1;
        if (first == 0) x[0] = (b[0] + rows.neighbours(0)) * inverseCount(cnt[0]);
        // The row's inside in blocks, 8 lanes at a time: both colours computed into a block buffer,
        // then the sweep's colour stored. A cell of the colour reads only the other colour's cells,
        // which the store leaves as they were, so the blocks see what a cell-by-cell sweep sees.
        constexpr int kBlock = 128;
        float v[kBlock];
        for (int k0 = 1; k0 < nz - 1; k0 += kBlock) {
            const int k1 = std::min(nz - 1, k0 + kBlock);
            for (int k = k0; k < k1; ++k) v[k - k0] = (b[k] + rows.inner(k)) * inverseCount(cnt[k]);
            for (int k = k0; k < k1; ++k) x[k] = selectBits((k & 1) == first, v[k - k0], x[k]);
        }
        if (nz > 1 && ((nz - 1) & 1) == first) x[nz - 1] = (b[nz - 1] + rows.neighbours(nz - 1)) * inverseCount(cnt[nz - 1]);
    }
}

// The first sweep from x = 0: colour 0 from b alone (its neighbours are 0: the same bits as a sweep over
// zeros), colour 1 set to 0. Reads nothing of the slabs beside it.
void PressureSolver::firstSweepSlab(Level& l, int i)
{
    for (int j = 0; j < l.n.y; ++j) {
        const size_t base = l.index(i, j, 0);
        float* x = l.x.data() + base;
        const float* b = l.b.data() + base;
        const uint8_t* cnt = l.count.data() + base;
        for (int k = 0; k < l.n.z; ++k) x[k] = ((i + j + k) & 1) == 0 ? (b[k] + 0.0f) * inverseCount(cnt[k]) : 0.0f;
    }
}

// The residual b - A x of slab i into tmp (0 off the fluid).
void PressureSolver::residualSlab(Level& l, int i)
{
    for (int j = 0; j < l.n.y; ++j) {
        const StencilRows<float> rows(l.n, l.x.data(), l.zeros.data(), i, j);
        const size_t base = l.index(i, j, 0);
        const float* b = l.b.data() + base;
        const uint8_t* cnt = l.count.data() + base;
        float* res = l.tmp.data() + base;
        const int nz = l.n.z;
        const auto edge = [&](int k) { res[k] = cnt[k] ? b[k] - (float(cnt[k]) * rows.c[k] - rows.neighbours(k)) : 0.0f; };
        edge(0);
        for (int k = 1; k < nz - 1; ++k) res[k] = keepOrZero(cnt[k] != 0, b[k] - (float(cnt[k]) * rows.c[k] - rows.inner(k)));
        if (nz > 1) edge(nz - 1);
    }
}

// x += the coarse correction (piecewise constant) on slab i's fluid cells.
void PressureSolver::prolongSlab(Level& l, const Level& c, int i)
{
    for (int j = 0; j < l.n.y; ++j) {
        const size_t base = l.index(i, j, 0);
        float* x = l.x.data() + base;
        const uint8_t* cnt = l.count.data() + base;
        const float* coarse = c.x.data() + c.index(i / 2, j / 2, 0);
#pragma GCC ivdep
        for (int k = 0; k < l.n.z; ++k) x[k] = selectBits(cnt[k] != 0, x[k] + coarse[k / 2], x[k]);   // x and coarse: two levels
    }
}


// x_l = V-cycle applied to b_l, a symmetric linear operator: kSmoothing red-black Gauss-Seidel pairs before the
// coarse correction and as many black-red after (the adjoint), restriction = prolongation^T / 2, and a
// palindromic sweep sequence on the coarsest level. In float: it only preconditions the CG, whose
// vectors and tolerance stay in double; half the bytes of a double V-cycle. The smoothing with the
// residual, and the prolongation with the smoothing after it, run as one pipelined pass each
// (pipelineSlabs): the sweeps read and write the finest level's x once per pass, not once per sweep.
void PressureSolver::vcycle(size_t li)
{
    Level& l = levels[li];
    if (li + 1 == levels.size()) {
        // Colours 0 1 0 1 ... (8 pairs), then 1 0 1 0 ... (8 pairs), the first from x = 0.
        constexpr int kCoarse = 32;
        pipelineSlabs(l.n.x, kCoarse, [&](int st, int i) {
            if (st == 0) firstSweepSlab(l, i);
            else sweepSlab(l, st < kCoarse / 2 ? st & 1 : (st + 1) & 1, i);
        });
        return;
    }
    // Colours 0 1 0 1 (the first from x = 0), then the residual.
    constexpr int kSweeps = 2 * kSmoothing;
    pipelineSlabs(l.n.x, kSweeps + 1, [&](int st, int i) {
        if (st == 0) firstSweepSlab(l, i);
        else if (st < kSweeps) sweepSlab(l, st & 1, i);
        else residualSlab(l, i);
    });
    Level& c = levels[li + 1];
    HostExec().forEachRow(size_t(c.n.x), size_t(c.n.y) * size_t(c.n.z), [&](size_t slab, size_t, size_t) {
        const int I = int(slab);
        for (int J = 0; J < c.n.y; ++J)
            for (int K = 0; K < c.n.z; ++K) {
                float sum = 0.0f;
                for (int di = 0; di < 2; ++di)
                    for (int dj = 0; dj < 2; ++dj)
                        for (int dk = 0; dk < 2; ++dk) {
                            const int i = 2 * I + di, j = 2 * J + dj, k = 2 * K + dk;
                            if (i < l.n.x && j < l.n.y && k < l.n.z) sum += l.tmp[l.index(i, j, k)];
                        }
                // The coarse stencil is (2h)^2 / h^2 = 4 times the fine one on averages: 4 / 8.
                c.b[c.index(I, J, K)] = c.count[c.index(I, J, K)] ? 0.5f * sum : 0.0f;
            }
    });
    vcycle(li + 1);
    // The prolongation, then colours 1 0 1 0.
    pipelineSlabs(l.n.x, kSweeps + 1, [&](int st, int i) {
        if (st == 0) prolongSlab(l, c, i);
        else sweepSlab(l, st & 1, i);
    });
}

double PressureSolver::dot(const std::vector<double>& a, const std::vector<double>& b)
{
    double out = 0.0;
    HostExec().sum<1>(a.size(), [&](size_t i, double* t) { t[0] = a[i] * b[i]; }, &out);
    return out;
}

// Solves A x = rhs (x holds the start), relative residual tol. Returns {iterations, residual}.
// The preconditioner reads r from the finest level's b (written as r is updated) and leaves
// z = M r in its x, read in place.
std::pair<int, double> PressureSolver::solve(const std::vector<double>& rhs, std::vector<double>& x, double tol, int maxIt)
{
    Level& l0 = levels[0];
    const size_t n = l0.cells();
    const uint8_t* cnt = l0.count.data();
    const double bnorm = std::sqrt(dot(rhs, rhs));
    if (bnorm == 0.0) {
        std::fill(x.begin(), x.end(), 0.0);
        return {0, 0.0};
    }
    HostExec().forEach(n, [&](size_t i) {
        if (!cnt[i]) x[i] = 0.0;   // the operator's neighbours are read unmasked
    });
    applyDot(x.data(), q.data());
    double rr = 0.0;
    HostExec().sum<1>(n, [&](size_t i, double* t) {
        r[i] = cnt[i] ? rhs[i] - q[i] : 0.0;
        l0.b[i] = float(r[i]);
        t[0] = r[i] * r[i];
    }, &rr);
    double rnorm = std::sqrt(rr);
    if (rnorm <= tol * bnorm) return {0, rnorm / bnorm};
    const float* z = l0.x.data();
    vcycle(0);
    double rho = 0.0;
    HostExec().sum<1>(n, [&](size_t i, double* t) {
        s[i] = double(z[i]);
        t[0] = r[i] * s[i];
    }, &rho);
    int it = 0;
    while (it < maxIt) {
        ++it;
        const double alpha = rho / applyDot(s.data(), q.data());
        // The update, the preconditioner's input and |r|^2 in one pass.
        HostExec().sum<1>(n, [&](size_t i, double* t) {
            x[i] += alpha * s[i];
            r[i] -= alpha * q[i];
            l0.b[i] = float(r[i]);
            t[0] = r[i] * r[i];
        }, &rr);
        rnorm = std::sqrt(rr);
        if (rnorm <= tol * bnorm) break;
        vcycle(0);
        double rhoNew = 0.0;
        HostExec().sum<1>(n, [&](size_t i, double* t) { t[0] = r[i] * double(z[i]); }, &rhoNew);
        const double beta = rhoNew / rho;
        rho = rhoNew;
        HostExec().forEach(n, [&](size_t i) { s[i] = double(z[i]) + beta * s[i]; });
    }
    return {it, rnorm / bnorm};
}

} // namespace sylva::volume
