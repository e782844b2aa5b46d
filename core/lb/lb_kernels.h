// The passes of an LB solve besides the step, written once over an executor (core/base/parallel.h): the
// start state (the boundary condition), the node totals, their change between two steps and the coarse
// start's interpolation. The CPU device (lb_solver.cpp) runs them with HostExec, the CUDA device
// (cuda/lb_cuda.cu) with CudaExec; only the step (collision and streaming) has a form for each.
//
// The distributions of a grid's solves lie one solve after another in docs/LB_MODEL.md's order, value
// (s, i, j, k, m) at (((s X + i) Y + j) 19 + m) Z + k: solve s is planes s X .. s X + X - 1 of one tall
// grid, so a pass over all the solves is a pass over rows of Z values. Values are stored as S (float, or
// a half type on either side); StoredValue<S> converts, specialized where S is known.
#pragma once

#include <cmath>
#include <cstddef>

#include "core/base/defines.h"
#include "core/lb/lattice.h"

namespace sylva::lb {

// load(p): the stored value at p as a float; make(v): v as stored (rounded to nearest even).
template <typename S>
struct StoredValue;

template <>
struct StoredValue<float> {
    static SYLVA_HD SYLVA_INLINE float load(const float* p) { return *p; }
    static SYLVA_HD SYLVA_INLINE float make(float v) { return v; }
};

// The node total sum_m f_m, added in direction order from 0: the step's fused totals (CPU, 8 nodes a
// vector) and the passes below give the same bits.
template <typename T>
SYLVA_HD SYLVA_INLINE T nodeTotal(const T (&f)[kDirections])
{
    T sum = T{};
    SYLVA_UNROLL
    for (int m = 0; m < kDirections; ++m) sum = sum + f[m];
    return sum;
}

// The shape of the solves a pass runs over: X x Y x Z nodes each.
struct LbShape {
    int X = 0, Y = 0, Z = 0;
    int solves = 1;
    SYLVA_HD size_t nodes() const { return size_t(X) * size_t(Y) * size_t(Z); }
    SYLVA_HD size_t values() const { return nodes() * size_t(kDirections); }   // one solve's distributions
    SYLVA_HD size_t rows() const { return size_t(solves) * size_t(X) * size_t(Y); }   // (s, i, j) rows of nodes
};

// The boundary condition for unit intensity, by value (it travels in a kernel's parameters).
struct LbBoundary {
    float f[kDirections] = {};
};

namespace kernels {

// Rows of the start state: boundary nodes hold the boundary condition, the others 0 (the boundary
// condition with warm). With interiorOnly, rows on an x or y face are left as they are.
template <typename S>
struct StartRows {
    S* f;
    LbShape shape;
    LbBoundary bc;
    bool warm, interiorOnly;
    SYLVA_HD void operator()(size_t row, size_t k0, size_t k1) const
    {
        const int m = int(row % size_t(kDirections));
        const size_t ij = row / size_t(kDirections);
        const int j = int(ij % size_t(shape.Y)), i = int((ij / size_t(shape.Y)) % size_t(shape.X));
        const bool face = i == 0 || j == 0 || i == shape.X - 1 || j == shape.Y - 1;
        if (face && interiorOnly) return;
        const S edge = StoredValue<S>::make(bc.f[m]), inside = StoredValue<S>::make(warm || face ? bc.f[m] : 0.0f);
        S* out = f + row * size_t(shape.Z);
        for (size_t k = k0; k < k1; ++k) out[k] = k == 0 || k == size_t(shape.Z) - 1 ? edge : inside;
    }
};

// The node totals of every solve into out (solve s's nodes from s * nodes, z fastest).
template <typename S>
struct TotalRows {
    const S* f;
    float* out;
    int Z;
    SYLVA_HD void operator()(size_t row, size_t k0, size_t k1) const
    {
        const S* in = f + row * size_t(kDirections) * size_t(Z);
        for (size_t k = k0; k < k1; ++k) {
            float v[kDirections];
            SYLVA_UNROLL
            for (int m = 0; m < kDirections; ++m) v[m] = StoredValue<S>::load(in + size_t(m) * size_t(Z) + k);
            out[row * size_t(Z) + k] = nodeTotal(v);
        }
    }
};

// The terms of the relative change: (now - before)^2 and now^2 per node, in double.
struct ChangeTerms {
    const float* now;
    const float* before;
    SYLVA_HD void operator()(size_t i, double* t) const
    {
        const double x = now[i], y = before[i];
        t[0] = (x - y) * (x - y);
        t[1] = x * x;
    }
};

// Coarse start: the interior of every solve of `fine` interpolated from `coarse` (the same solves on
// coarsen() of its grid): bilinear in x and y at (i/2, j/2) per coarse row, then linear in z at k/2.
// Boundary nodes are left as they are.
template <typename S>
struct ProlongRows {
    const S* coarse;
    S* fine;
    LbShape c, shape;
    SYLVA_HD float coarseXY(const size_t (&rowAt)[4], const float (&w)[4], int K) const
    {
        float v[4];
        SYLVA_UNROLL
        for (int q = 0; q < 4; ++q) v[q] = StoredValue<S>::load(coarse + rowAt[q] + size_t(K));
        return w[0] * v[0] + w[1] * v[1] + w[2] * v[2] + w[3] * v[3];
    }
    SYLVA_HD void operator()(size_t row, size_t k0, size_t k1) const
    {
        const int m = int(row % size_t(kDirections));
        const size_t ij = row / size_t(kDirections);
        const int j = int(ij % size_t(shape.Y)), i = int((ij / size_t(shape.Y)) % size_t(shape.X));
        const size_t s = ij / size_t(shape.Y) / size_t(shape.X);
        if (i < 1 || j < 1 || i > shape.X - 2 || j > shape.Y - 2) return;
        const int I0 = i / 2 < c.X - 2 ? i / 2 : c.X - 2, J0 = j / 2 < c.Y - 2 ? j / 2 : c.Y - 2;
        const float fx = float(i) / 2.0f - float(I0), fy = float(j) / 2.0f - float(J0);
        const float w[4] = {(1.0f - fx) * (1.0f - fy), (1.0f - fx) * fy, fx * (1.0f - fy), fx * fy};
        size_t rowAt[4];
        for (int q = 0; q < 4; ++q)
            rowAt[q] = (((s * size_t(c.X) + size_t(I0 + (q >> 1))) * size_t(c.Y) + size_t(J0 + (q & 1))) * kDirections + size_t(m)) *
                       size_t(c.Z);
        // xy at coarse K0 and K0 + 1; consecutive k share them (K0 moves every other k).
        int at = -2;
        float xy0 = 0.0f, xy1 = 0.0f;
        const size_t kEnd = k1 < size_t(shape.Z) - 1 ? k1 : size_t(shape.Z) - 1;
        for (size_t k = k0 > 1 ? k0 : 1; k < kEnd; ++k) {
            const int K0 = int(k) / 2 < c.Z - 2 ? int(k) / 2 : c.Z - 2;
            if (K0 != at) {
                xy0 = K0 == at + 1 ? xy1 : coarseXY(rowAt, w, K0);
                xy1 = coarseXY(rowAt, w, K0 + 1);
                at = K0;
            }
            const float fz = float(k) / 2.0f - float(K0);
            fine[row * size_t(shape.Z) + k] = StoredValue<S>::make((1.0f - fz) * xy0 + fz * xy1);
        }
    }
};

} // namespace kernels

// The start state of `shape.solves` solves in f: the boundary condition on boundary nodes (everywhere with
// warm), 0 inside; with interiorOnly the rows on the x and y faces are left as they are (memory that
// already holds the boundary condition there).
template <class Exec, typename S>
void startState(const Exec& exec, S* f, const LbShape& shape, const LbBoundary& bc, bool warm, bool interiorOnly = false)
{
    exec.forEachRow(shape.rows() * kDirections, size_t(shape.Z), kernels::StartRows<S>{f, shape, bc, warm, interiorOnly});
}

// The node totals sum_m f_m of every solve of f into out (shape.solves x nodes floats).
template <class Exec, typename S>
void nodeTotals(const Exec& exec, const S* f, float* out, const LbShape& shape)
{
    exec.forEachRow(shape.rows(), size_t(shape.Z), kernels::TotalRows<S>{f, out, shape.Z});
}

// sums[0] = sum (now - before)^2, sums[1] = sum now^2 over n totals; sums is the executor's memory.
template <class Exec>
void totalsChange(const Exec& exec, const float* now, const float* before, size_t n, double* sums)
{
    exec.template sum<2>(n, kernels::ChangeTerms{now, before}, sums);
}

// The relative L2 change sqrt(sum (T_now - T_before)^2 / sum T_now^2) from totalsChange's sums.
inline double relativeChange(const double (&sums)[2]) { return sums[1] > 0.0 ? std::sqrt(sums[0] / sums[1]) : 0.0; }

// Coarse start: the interior of every solve of `fine` (shape) interpolated from `coarse` (coarseShape,
// the same solves on coarsen() of the grid); the boundary nodes are left as they are.
template <class Exec, typename S>
void prolongate(const Exec& exec, const S* coarse, const LbShape& coarseShape, S* fine, const LbShape& shape)
{
    exec.forEachRow(shape.rows() * kDirections, size_t(shape.Z), kernels::ProlongRows<S>{coarse, fine, coarseShape, shape});
}

} // namespace sylva::lb
