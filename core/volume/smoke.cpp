// Stable fluids on a MAC grid (smoke.h): forces, semi-Lagrangian advection, MGPCG pressure projection.
#include "core/volume/smoke.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdio>
#include <string>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "core/base/error.h"
#include "core/base/memory.h"
#include "core/base/parallel.h"
#include "core/base/progress.h"
#include "core/volume/noise.h"

namespace sylva::volume {
namespace {

std::string num(double v)
{
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.6g", v);
    return buf;
}

bool finite3(const glm::vec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

// Runs body(i) for every x slab i in [0, n): disjoint writes, so the result is independent of threads.
template <class Body>
void forSlabs(int n, const Body& body)
{
    tbb::parallel_for(tbb::blocked_range<int>(0, n), [&](const tbb::blocked_range<int>& r) {
        for (int i = r.begin(); i != r.end(); ++i) body(i);
    });
}

// Sums body(i) (a double) over the x slabs i in [0, n), added in slab order: independent of the thread count.
template <class Body>
double sumSlabs(int n, const Body& body)
{
    std::vector<double> partial(size_t(n), 0.0);
    forSlabs(n, [&](int i) { partial[size_t(i)] = body(i); });
    double out = 0.0;
    for (double p : partial) out += p;
    return out;
}

// A staggered field: samples at (index + offset) in cell units.
struct FieldView {
    const float* data;
    glm::ivec3 n;
    glm::vec3 offset;
    float at(int i, int j, int k) const { return data[(size_t(i) * size_t(n.y) + size_t(j)) * size_t(n.z) + size_t(k)]; }
};

// ---- the semi-Lagrangian back-trace, a batch of points at a time ----
// Trilinear samples of the MAC grid's fields along rows of points: the axis samples (clamped index and
// fraction per axis) and the back-trace's arithmetic run 8 points at a time (loops over arrays, compiled
// with -fno-trapping-math so the clamps vectorize: core/CMakeLists.txt), and the corner loads of different
// points overlap. At 128^3, against one point at a time: the same bits, and a step of 0.50 s takes 0.39 s.
constexpr int kBatch = 64;

struct PointBatch {
    float x[kBatch], y[kBatch], z[kBatch];
    int count = 0;
};

struct AxisBatch {
    int i[kBatch];
    float t[kBatch];
};

[[gnu::always_inline]] inline void axisBatch(const float* pos, float offset, int n, int count, AxisBatch& out)
{
    const float hi = float(n - 1);
    for (int q = 0; q < count; ++q) {
        const float s = std::clamp(pos[q] - offset, 0.0f, hi);   // a field of n samples, the first at offset
        const int i = std::min(int(s), n - 2);
        out.i[q] = i;
        out.t[q] = s - float(i);
    }
}

// out[q] = the trilinear interpolation of the field of dims samples (z fastest) at the batch's axis samples.
[[gnu::always_inline]] inline void gatherBatch(const float* data, const glm::ivec3& dims, const AxisBatch& x, const AxisBatch& y,
                                               const AxisBatch& z, int count, float* out)
{
    int base[kBatch];
    for (int q = 0; q < count; ++q) base[q] = (x.i[q] * dims.y + y.i[q]) * dims.z + z.i[q];   // < 2^31: kSmokeCells.hi
    const int dy = dims.z, dx = dims.y * dims.z;
    for (int q = 0; q < count; ++q) {
        const float* p = data + base[q];
        const float zt = z.t[q];
        const float c00 = p[0] + zt * (p[1] - p[0]);
        const float c01 = p[dy] + zt * (p[dy + 1] - p[dy]);
        const float c10 = p[dx] + zt * (p[dx + 1] - p[dx]);
        const float c11 = p[dx + dy] + zt * (p[dx + dy + 1] - p[dx + dy]);
        const float c0 = c00 + y.t[q] * (c01 - c00), c1 = c10 + y.t[q] * (c11 - c10);
        out[q] = c0 + x.t[q] * (c1 - c0);
    }
}

// The face velocity (u, v, w on the MAC grid of n cells) at the batch's points: each axis sampled once for
// the field staggered along it and once for the two centred on it.
void velocityBatch(const float* u, const float* v, const float* w, const glm::ivec3& n, const PointBatch& p, float* vx, float* vy, float* vz)
{
    AxisBatch sx, sy, sz, cx, cy, cz;
    axisBatch(p.x, 0.0f, n.x + 1, p.count, sx);
    axisBatch(p.y, 0.0f, n.y + 1, p.count, sy);
    axisBatch(p.z, 0.0f, n.z + 1, p.count, sz);
    axisBatch(p.x, 0.5f, n.x, p.count, cx);
    axisBatch(p.y, 0.5f, n.y, p.count, cy);
    axisBatch(p.z, 0.5f, n.z, p.count, cz);
    gatherBatch(u, {n.x + 1, n.y, n.z}, sx, cy, cz, p.count, vx);
    gatherBatch(v, {n.x, n.y + 1, n.z}, cx, sy, cz, p.count, vy);
    gatherBatch(w, {n.x, n.y, n.z + 1}, cx, cy, sz, p.count, vz);
}

// RK2 back-trace of the batch's points (cell units) through the face velocity u, v, w, from the velocity
// v0 at each point: mid = x - dt/2 v0, back = x - dt v(mid), both clamped to [0, hi]; back replaces p.
void traceBatch(const float* u, const float* v, const float* w, const glm::ivec3& n, float scale, const float* v0x, const float* v0y,
                const float* v0z, PointBatch& p)
{
    const glm::vec3 hi = glm::vec3(n);
    PointBatch mid;
    mid.count = p.count;
    for (int q = 0; q < p.count; ++q) {
        mid.x[q] = std::clamp(p.x[q] - 0.5f * scale * v0x[q], 0.0f, hi.x);
        mid.y[q] = std::clamp(p.y[q] - 0.5f * scale * v0y[q], 0.0f, hi.y);
        mid.z[q] = std::clamp(p.z[q] - 0.5f * scale * v0z[q], 0.0f, hi.z);
    }
    float vx[kBatch], vy[kBatch], vz[kBatch];
    velocityBatch(u, v, w, n, mid, vx, vy, vz);
    for (int q = 0; q < p.count; ++q) {
        p.x[q] = std::clamp(p.x[q] - scale * vx[q], 0.0f, hi.x);
        p.y[q] = std::clamp(p.y[q] - scale * vy[q], 0.0f, hi.y);
        p.z[q] = std::clamp(p.z[q] - scale * vz[q], 0.0f, hi.z);
    }
}

// Monotonic cubic Hermite through f1 (t = 0) and f2 (t = 1), Fedkiw et al. 2001 eq. (8)-(9): the
// slopes are central differences, set to 0 where their sign differs from the secant's (or it is 0)
// and capped at 3 times the secant (Fritsch and Carlson 1980), so the curve never leaves [min(f1, f2), max(f1, f2)] between the samples.
float monotonicCubic(float f0, float f1, float f2, float f3, float t)
{
    const float delta = f2 - f1;
    float d1 = 0.5f * (f2 - f0), d2 = 0.5f * (f3 - f1);
    if (delta == 0.0f) {
        d1 = d2 = 0.0f;
    } else {
        if ((d1 > 0.0f) != (delta > 0.0f) || d1 == 0.0f) d1 = 0.0f;
        if ((d2 > 0.0f) != (delta > 0.0f) || d2 == 0.0f) d2 = 0.0f;
        // Fritsch-Carlson: slopes at most 3 times the secant keep the Hermite piece monotone.
        const float cap = 3.0f * std::fabs(delta);
        d1 = std::clamp(d1, -cap, cap);
        d2 = std::clamp(d2, -cap, cap);
    }
    const float a3 = d1 + d2 - 2.0f * delta, a2 = 3.0f * delta - 2.0f * d1 - d2;
    return ((a3 * t + a2) * t + d1) * t + f1;
}

float sampleCubic(const FieldView& f, const glm::vec3& pos)
{
    int i0[3];
    float t[3];
    for (int a = 0; a < 3; ++a) {
        const float s = std::clamp(pos[a] - f.offset[a], 0.0f, float(f.n[a] - 1));
        i0[a] = std::min(int(s), f.n[a] - 2);
        t[a] = s - float(i0[a]);
    }
    auto ci = [&](int a, int d) { return std::clamp(i0[a] + d, 0, f.n[a] - 1); };
    float plane[4];
    for (int di = 0; di < 4; ++di) {
        float row[4];
        for (int dj = 0; dj < 4; ++dj) {
            const int i = ci(0, di - 1), j = ci(1, dj - 1);
            row[dj] = monotonicCubic(f.at(i, j, ci(2, -1)), f.at(i, j, ci(2, 0)), f.at(i, j, ci(2, 1)), f.at(i, j, ci(2, 2)), t[2]);
        }
        plane[di] = monotonicCubic(row[0], row[1], row[2], row[3], t[1]);
    }
    return monotonicCubic(plane[0], plane[1], plane[2], plane[3], t[0]);
}

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
             num(need / 1048576.0) + " MiB but only " + num(have / 1048576.0) + " MiB are available");
    if (!(std::isfinite(s.cellSize) && s.cellSize > 0.0f)) fail("cell size " + num(s.cellSize) + " must be finite and > 0");
    checkParam(kSmokeDt, s.dt, "simulate", "time step");
    if (!finite3(s.origin)) fail("origin must be finite");
    if (!std::isfinite(s.buoyancyDensity) || !std::isfinite(s.buoyancyTemperature)) fail("buoyancy must be finite");
    checkParam(kSmokeVorticity, s.vorticity, "simulate");
    if (!(s.densityDecay >= 0.0f && s.densityDecay * s.dt <= 1.0f))
        fail("density decay " + num(s.densityDecay) + " must be >= 0 and at most 1 / dt");
    if (!(s.temperatureDecay >= 0.0f && s.temperatureDecay * s.dt <= 1.0f))
        fail("temperature decay " + num(s.temperatureDecay) + " must be >= 0 and at most 1 / dt");
    checkParam(kSmokeJitter, s.jitter, "simulate");
    checkParam(kSmokeTolerance, s.pressureTolerance, "simulate");
    checkParam(kSmokeSeed, s.seed, "simulate");
    if (s.pressureMaxIterations < 1) fail("pressure iterations must be >= 1");
    if (!(std::isfinite(s.cflLimit) && s.cflLimit > 0.0f)) fail("CFL limit must be finite and > 0");
    auto checkShape = [&](const SmokeShape& sh, const std::string& what) {
        if (!finite3(sh.centre)) fail(what + ": centre must be finite");
        if (sh.kind == SmokeShape::Kind::Sphere && !(std::isfinite(sh.radius) && sh.radius > 0.0f))
            fail(what + ": radius " + num(sh.radius) + " must be finite and > 0");
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
            fail(what + ": its velocity moves " + num(cfl) + " cells per step, over the CFL limit " + num(s.cflLimit) +
                 " (lower the time step or the speed)");
    }
    for (size_t i = 0; i < s.obstacles.size(); ++i) checkShape(s.obstacles[i], "obstacle " + std::to_string(i + 1));
}

// ---- the pressure solve: CG in double, preconditioned by a multigrid V-cycle in float ----

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

struct SmokeSim::Solver {
    struct Level {
        glm::ivec3 n;
        std::vector<uint8_t> count;   // fluid neighbours (the open top's pressure-0 ghost counts); 0 off the fluid
        std::vector<float> x, b, tmp, zeros;
        size_t index(int i, int j, int k) const { return (size_t(i) * size_t(n.y) + size_t(j)) * size_t(n.z) + size_t(k); }
        size_t cells() const { return size_t(n.x) * size_t(n.y) * size_t(n.z); }
    };
    std::vector<Level> levels;
    std::vector<double> r, s, q, zeros;

    explicit Solver(const std::vector<uint8_t>& fluid0, const glm::ivec3& n0)
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
    double applyDot(const double* x, double* out) const
    {
        const Level& l = levels[0];
        return sumSlabs(l.n.x, [&](int i) {
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
            return acc;
        });
    }

    // One Gauss-Seidel sweep over the cells of one colour ((i + j + k) % 2 == colour) of slab i, in place: the
    // cells of a colour depend only on the other colour, so slabs run in any order and the result does not
    // depend on the thread count.
    static void sweepSlab(Level& l, int colour, int i)
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
    static void firstSweepSlab(Level& l, int i)
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
    static void residualSlab(Level& l, int i)
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
    static void prolongSlab(Level& l, const Level& c, int i)
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

    // Red-black sweep pairs before and after each coarse correction. Measured at 128^3 (bench_volume_sources,
    // iterations to 1e-6): 1 pair 17 CG iterations, 2 pairs 10.7, 3 pairs 9.7; 2 moves the fewest bytes.
    static constexpr int kSmoothing = 2;

    // x_l = V-cycle applied to b_l, a symmetric linear operator: kSmoothing red-black Gauss-Seidel pairs before the
    // coarse correction and as many black-red after (the adjoint), restriction = prolongation^T / 2, and a
    // palindromic sweep sequence on the coarsest level. In float: it only preconditions the CG, whose
    // vectors and tolerance stay in double; half the bytes of a double V-cycle. The smoothing with the
    // residual, and the prolongation with the smoothing after it, run as one pipelined pass each
    // (pipelineSlabs): the sweeps read and write the finest level's x once per pass, not once per sweep.
    void vcycle(size_t li)
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
        forSlabs(c.n.x, [&](int I) {
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

    static double dot(const std::vector<double>& a, const std::vector<double>& b)
    {
        double out = 0.0;
        HostExec().sum<1>(a.size(), [&](size_t i, double* t) { t[0] = a[i] * b[i]; }, &out);
        return out;
    }

    // Solves A x = rhs (x holds the start), relative residual tol. Returns {iterations, residual}.
    // The preconditioner reads r from the finest level's b (written as r is updated) and leaves
    // z = M r in its x, read in place.
    std::pair<int, double> solve(const std::vector<double>& rhs, std::vector<double>& x, double tol, int maxIt)
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
};

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
    m_solver = new Solver(fluid, n);
}

SmokeSim::~SmokeSim() { delete m_solver; }

namespace {

struct Dims {
    glm::ivec3 n;
    size_t cell(int i, int j, int k) const { return (size_t(i) * size_t(n.y) + size_t(j)) * size_t(n.z) + size_t(k); }
    size_t uIdx(int i, int j, int k) const { return (size_t(i) * size_t(n.y) + size_t(j)) * size_t(n.z) + size_t(k); }
    size_t vIdx(int i, int j, int k) const { return (size_t(i) * size_t(n.y + 1) + size_t(j)) * size_t(n.z) + size_t(k); }
    size_t wIdx(int i, int j, int k) const { return (size_t(i) * size_t(n.y) + size_t(j)) * size_t(n.z + 1) + size_t(k); }
};

// Index ranges [lo, hi) along each axis, within [0, limit), that hold every cell or face whose point can
// lie in the shape (a margin of two cells): the loops over a source's cells and faces visit only these.
struct IndexBox {
    glm::ivec3 lo, hi;
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

double SmokeSim::divergenceNorm() const
{
    const Dims d{m_s.cells};
    const glm::ivec3 n = d.n;
    const double h = m_s.cellSize;
    // Slab by slab in parallel (HostExec's chunks of 16k items would put all the slabs in one).
    const double out = sumSlabs(n.x, [&](int i) {
        double acc = 0.0;
        for (int j = 0; j < n.y; ++j)
            for (int k = 0; k < n.z; ++k) {
                if (m_solid[d.cell(i, j, k)]) continue;
                const double div = (double(m_u[d.uIdx(i + 1, j, k)]) - double(m_u[d.uIdx(i, j, k)]) + double(m_v[d.vIdx(i, j + 1, k)]) -
                                    double(m_v[d.vIdx(i, j, k)]) + double(m_w[d.wIdx(i, j, k + 1)]) - double(m_w[d.wIdx(i, j, k)])) / h;
                acc += div * div;
            }
        return acc;
    });
    return std::sqrt(out);
}

void SmokeSim::project()
{
    const Dims d{m_s.cells};
    const glm::ivec3 n = d.n;
    // Faces next to a wall or an obstacle carry velocity 0 (the top faces stay free).
    forSlabs(n.x + 1, [&](int i) {
        for (int j = 0; j < n.y; ++j)
            for (int k = 0; k < n.z; ++k)
                if (i == 0 || i == n.x || m_solid[d.cell(i - 1, j, k)] || m_solid[d.cell(i, j, k)]) m_u[d.uIdx(i, j, k)] = 0.0f;
    });
    forSlabs(n.x, [&](int i) {
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
    forSlabs(n.x, [&](int i) {
        for (int j = 0; j < n.y; ++j)
            for (int k = 0; k < n.z; ++k) {
                const size_t c = d.cell(i, j, k);
                if (m_solid[c]) continue;
                rhs[c] = -(double(m_u[d.uIdx(i + 1, j, k)]) - double(m_u[d.uIdx(i, j, k)]) + double(m_v[d.vIdx(i, j + 1, k)]) -
                           double(m_v[d.vIdx(i, j, k)]) + double(m_w[d.wIdx(i, j, k + 1)]) - double(m_w[d.wIdx(i, j, k)]));
            }
    });
    const auto [it, res] = m_solver->solve(rhs, m_pressure, m_s.pressureTolerance, m_s.pressureMaxIterations);
    m_stats.pressureIterations = it;
    m_stats.pressureResidual = res;
    const std::vector<double>& p = m_pressure;
    forSlabs(n.x, [&](int i) {
        for (int j = 0; j < n.y; ++j)
            for (int k = 0; k < n.z; ++k) {
                const size_t c = d.cell(i, j, k);
                if (m_solid[c]) continue;
                if (i + 1 < n.x && !m_solid[d.cell(i + 1, j, k)])
                    m_u[d.uIdx(i + 1, j, k)] = float(double(m_u[d.uIdx(i + 1, j, k)]) - (p[d.cell(i + 1, j, k)] - p[c]));
                if (j + 1 < n.y && !m_solid[d.cell(i, j + 1, k)])
                    m_v[d.vIdx(i, j + 1, k)] = float(double(m_v[d.vIdx(i, j + 1, k)]) - (p[d.cell(i, j + 1, k)] - p[c]));
                if (j + 1 == n.y) m_v[d.vIdx(i, n.y, k)] = float(double(m_v[d.vIdx(i, n.y, k)]) + p[c]);   // ghost pressure 0
                if (k + 1 < n.z && !m_solid[d.cell(i, j, k + 1)])
                    m_w[d.wIdx(i, j, k + 1)] = float(double(m_w[d.wIdx(i, j, k + 1)]) - (p[d.cell(i, j, k + 1)] - p[c]));
            }
    });
    m_stats.divergenceAfter = divergenceNorm();
}

void SmokeSim::advectScalars(float dt)
{
    const Dims d{m_s.cells};
    const glm::ivec3 n = d.n;
    const float scale = dt / m_s.cellSize;
    m_oldDensity = m_density;   // copies into the kept buffers (no new pages)
    m_oldTemperature = m_temperature;
    const std::vector<float>& oldD = m_oldDensity;
    const std::vector<float>& oldT = m_oldTemperature;
    const FieldView fd{oldD.data(), n, glm::vec3(0.5f)}, ft{oldT.data(), n, glm::vec3(0.5f)};
    const SmokeInterp interp = m_s.interp;
    // Row by row, kBatch cells at a time (traceBatch); a solid cell's trace is made and dropped.
    forSlabs(n.x, [&](int i) {
        PointBatch p;
        AxisBatch ax, ay, az;
        float v0x[kBatch], v0y[kBatch], v0z[kBatch], dens[kBatch], temp[kBatch];
        for (int j = 0; j < n.y; ++j)
            for (int k0 = 0; k0 < n.z; k0 += kBatch) {
                const int count = std::min(kBatch, n.z - k0);
                p.count = count;
                const float *ua = &m_u[d.uIdx(i, j, k0)], *ub = &m_u[d.uIdx(i + 1, j, k0)];
                const float *va = &m_v[d.vIdx(i, j, k0)], *vb = &m_v[d.vIdx(i, j + 1, k0)];
                const float* wa = &m_w[d.wIdx(i, j, k0)];
                for (int q = 0; q < count; ++q) {
                    p.x[q] = float(i) + 0.5f;
                    p.y[q] = float(j) + 0.5f;
                    p.z[q] = float(k0 + q) + 0.5f;
                    v0x[q] = 0.5f * (ua[q] + ub[q]);
                    v0y[q] = 0.5f * (va[q] + vb[q]);
                    v0z[q] = 0.5f * (wa[q] + wa[q + 1]);
                }
                traceBatch(m_u.data(), m_v.data(), m_w.data(), n, scale, v0x, v0y, v0z, p);
                if (interp == SmokeInterp::Linear) {
                    // The same cells for both: one index computation.
                    axisBatch(p.x, 0.5f, n.x, count, ax);
                    axisBatch(p.y, 0.5f, n.y, count, ay);
                    axisBatch(p.z, 0.5f, n.z, count, az);
                    gatherBatch(fd.data, n, ax, ay, az, count, dens);
                    gatherBatch(ft.data, n, ax, ay, az, count, temp);
                } else {
                    for (int q = 0; q < count; ++q) {
                        const glm::vec3 back(p.x[q], p.y[q], p.z[q]);
                        dens[q] = sampleCubic(fd, back);
                        temp[q] = sampleCubic(ft, back);
                    }
                }
                const size_t c0 = d.cell(i, j, k0);
                for (int q = 0; q < count; ++q) {
                    const bool solid = m_solid[c0 + size_t(q)] != 0;
                    m_density[c0 + size_t(q)] = solid ? 0.0f : std::clamp(dens[q], 0.0f, 1.0f);
                    m_temperature[c0 + size_t(q)] = solid ? 0.0f : std::max(0.0f, temp[q]);
                }
            }
    });
}

void SmokeSim::step(Progress* progress)
{
    const Dims d{m_s.cells};
    const glm::ivec3 n = d.n;
    const float h = m_s.cellSize, dt = m_s.dt;
    if (progress) progress->throwIfCancelled();

    // 1. Forces on a copy of the velocity: buoyancy on the v faces, vorticity confinement on all.
    m_u1 = m_u;
    m_v1 = m_v;
    m_w1 = m_w;
    std::vector<float>& u1 = m_u1;
    std::vector<float>& v1 = m_v1;
    std::vector<float>& w1 = m_w1;
    forSlabs(n.x, [&](int i) {
        for (int j = 1; j <= n.y; ++j)
            for (int k = 0; k < n.z; ++k) {
                const size_t below = d.cell(i, j - 1, k);
                const size_t above = j < n.y ? d.cell(i, j, k) : below;
                const float rho = 0.5f * (m_density[below] + m_density[above]);
                const float temp = 0.5f * (m_temperature[below] + m_temperature[above]);
                v1[d.vIdx(i, j, k)] += dt * (-m_s.buoyancyDensity * rho + m_s.buoyancyTemperature * temp);
            }
    });
    if (m_s.vorticity > 0.0f) {
        const size_t cells = m_density.size();
        // Every cell of the three is written below before it is read.
        m_centre.resize(cells);
        m_omega.resize(cells);
        m_vorticityMag.resize(cells);
        std::vector<glm::vec3>& centre = m_centre;
        std::vector<glm::vec3>& omega = m_omega;
        std::vector<float>& mag = m_vorticityMag;
        forSlabs(n.x, [&](int i) {
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
        forSlabs(n.x, [&](int i) {
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
        forSlabs(n.x, [&](int i) {
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
        forSlabs(n.x + 1, [&](int i) {
            for (int j = 0; j < n.y; ++j)
                for (int k = 0; k < n.z; ++k)
                    if (i > 0 && i < n.x) u1[d.uIdx(i, j, k)] += dt * 0.5f * (force[d.cell(i - 1, j, k)].x + force[d.cell(i, j, k)].x);
            if (i == n.x) return;
            for (int j = 1; j < n.y; ++j)
                for (int k = 0; k < n.z; ++k) v1[d.vIdx(i, j, k)] += dt * 0.5f * (force[d.cell(i, j - 1, k)].y + force[d.cell(i, j, k)].y);
            for (int j = 0; j < n.y; ++j)
                for (int k = 1; k < n.z; ++k) w1[d.wIdx(i, j, k)] += dt * 0.5f * (force[d.cell(i, j, k - 1)].z + force[d.cell(i, j, k)].z);
        });
    }
    // Source velocities on the faces inside each source.
    for (const SmokeSource& src : m_s.sources) {
        if (src.velocity == glm::vec3(0.0f)) continue;
        const IndexBox box = shapeBox(src.shape, m_s, n + 1);
        forSlabs(box.hi.x - box.lo.x, [&](int slab) {
            const int i = box.lo.x + slab;
            for (int j = box.lo.y; j < box.hi.y; ++j)
                for (int k = box.lo.z; k < box.hi.z; ++k) {
                    if (j < n.y && k < n.z && src.shape.contains(m_s.origin + h * glm::vec3(float(i), j + 0.5f, k + 0.5f)))
                        u1[d.uIdx(i, j, k)] = src.velocity.x;
                    if (i < n.x && k < n.z && src.shape.contains(m_s.origin + h * glm::vec3(i + 0.5f, float(j), k + 0.5f)))
                        v1[d.vIdx(i, j, k)] = src.velocity.y;
                    if (i < n.x && j < n.y && src.shape.contains(m_s.origin + h * glm::vec3(i + 0.5f, j + 0.5f, float(k))))
                        w1[d.wIdx(i, j, k)] = src.velocity.z;
                }
        });
    }
    // 2. The CFL check on the velocity that will advect: refuse before anything changes.
    const double maxSq = maxSquare(u1, v1, w1);
    if (std::isnan(maxSq)) throw Error("simulate: the velocity is no longer finite at step " + std::to_string(m_steps + 1));
    const double cfl = std::sqrt(3.0 * maxSq) * dt / h;   // a bound: each component at most its maximum
    if (cfl > m_s.cflLimit)
        throw Error("simulate: step " + std::to_string(m_steps + 1) + " would move the smoke " + num(cfl) +
                    " cells (CFL number), over the limit " + num(m_s.cflLimit) + "; lower the time step (--dt) or the forces");
    m_stats.cfl = cfl;
    if (progress) progress->throwIfCancelled();

    // 3. Self-advection (RK2 back-trace through the forced velocity).
    {
        const float scale = dt / h;
        const FieldView fu{u1.data(), {n.x + 1, n.y, n.z}, {0.0f, 0.5f, 0.5f}};
        const FieldView fv{v1.data(), {n.x, n.y + 1, n.z}, {0.5f, 0.0f, 0.5f}};
        const FieldView fw{w1.data(), {n.x, n.y, n.z + 1}, {0.5f, 0.5f, 0.0f}};
        const SmokeInterp interp = m_s.interp;
        const auto& U = u1;
        const auto& V = v1;
        const auto& W = w1;
        // RK2 from the velocity at the face itself (its own component and the 4-face averages of the
        // others: what trilinear sampling gives there, without the gathers), kBatch faces of a row at a
        // time (traceBatch); then the face's own component at the foot of the trace into out.
        struct Rows {
            PointBatch p;
            AxisBatch ax, ay, az;
            float v0x[kBatch], v0y[kBatch], v0z[kBatch], value[kBatch];
        };
        auto advect = [&](Rows& r, const FieldView& f, float* out) {
            traceBatch(U.data(), V.data(), W.data(), n, scale, r.v0x, r.v0y, r.v0z, r.p);
            const int count = r.p.count;
            if (interp == SmokeInterp::Linear) {
                axisBatch(r.p.x, f.offset.x, f.n.x, count, r.ax);
                axisBatch(r.p.y, f.offset.y, f.n.y, count, r.ay);
                axisBatch(r.p.z, f.offset.z, f.n.z, count, r.az);
                gatherBatch(f.data, f.n, r.ax, r.ay, r.az, count, r.value);
            } else {
                for (int q = 0; q < count; ++q) r.value[q] = sampleCubic(f, glm::vec3(r.p.x[q], r.p.y[q], r.p.z[q]));
            }
            for (int q = 0; q < count; ++q) out[q] = r.value[q];
        };
        forSlabs(n.x + 1, [&](int i) {
            Rows r;
            const int ia = std::max(i - 1, 0), ib = std::min(i, n.x - 1);
            for (int j = 0; j < n.y; ++j)
                for (int k0 = 0; k0 < n.z; k0 += kBatch) {
                    const int count = r.p.count = std::min(kBatch, n.z - k0);
                    const float* uc = &U[d.uIdx(i, j, k0)];
                    const float *v00 = &V[d.vIdx(ia, j, k0)], *v10 = &V[d.vIdx(ib, j, k0)], *v01 = &V[d.vIdx(ia, j + 1, k0)],
                                *v11 = &V[d.vIdx(ib, j + 1, k0)];
                    const float *wa = &W[d.wIdx(ia, j, k0)], *wb = &W[d.wIdx(ib, j, k0)];
                    for (int q = 0; q < count; ++q) {
                        r.p.x[q] = float(i);
                        r.p.y[q] = float(j) + 0.5f;
                        r.p.z[q] = float(k0 + q) + 0.5f;
                        r.v0x[q] = uc[q];
                        r.v0y[q] = 0.25f * (v00[q] + v10[q] + v01[q] + v11[q]);
                        r.v0z[q] = 0.25f * (wa[q] + wb[q] + wa[q + 1] + wb[q + 1]);
                    }
                    advect(r, fu, &m_u[d.uIdx(i, j, k0)]);
                }
            if (i == n.x) return;
            for (int j = 0; j <= n.y; ++j) {
                const int ja = std::max(j - 1, 0), jb = std::min(j, n.y - 1);
                for (int k0 = 0; k0 < n.z; k0 += kBatch) {
                    const int count = r.p.count = std::min(kBatch, n.z - k0);
                    const float *u00 = &U[d.uIdx(i, ja, k0)], *u10 = &U[d.uIdx(i + 1, ja, k0)], *u01 = &U[d.uIdx(i, jb, k0)],
                                *u11 = &U[d.uIdx(i + 1, jb, k0)];
                    const float* vc = &V[d.vIdx(i, j, k0)];
                    const float *wa = &W[d.wIdx(i, ja, k0)], *wb = &W[d.wIdx(i, jb, k0)];
                    for (int q = 0; q < count; ++q) {
                        r.p.x[q] = float(i) + 0.5f;
                        r.p.y[q] = float(j);
                        r.p.z[q] = float(k0 + q) + 0.5f;
                        r.v0x[q] = 0.25f * (u00[q] + u10[q] + u01[q] + u11[q]);
                        r.v0y[q] = vc[q];
                        r.v0z[q] = 0.25f * (wa[q] + wa[q + 1] + wb[q] + wb[q + 1]);
                    }
                    advect(r, fv, &m_v[d.vIdx(i, j, k0)]);
                }
            }
            for (int j = 0; j < n.y; ++j)
                for (int k0 = 0; k0 <= n.z; k0 += kBatch) {
                    const int count = r.p.count = std::min(kBatch, n.z + 1 - k0);
                    const float *ua = &U[d.uIdx(i, j, 0)], *ub = &U[d.uIdx(i + 1, j, 0)];
                    const float *va = &V[d.vIdx(i, j, 0)], *vb = &V[d.vIdx(i, j + 1, 0)];
                    const float* wc = &W[d.wIdx(i, j, k0)];
                    for (int q = 0; q < count; ++q) {
                        const int k = k0 + q, ka = std::max(k - 1, 0), kb = std::min(k, n.z - 1);
                        r.p.x[q] = float(i) + 0.5f;
                        r.p.y[q] = float(j) + 0.5f;
                        r.p.z[q] = float(k);
                        r.v0x[q] = 0.25f * (ua[ka] + ub[ka] + ua[kb] + ub[kb]);
                        r.v0y[q] = 0.25f * (va[ka] + vb[ka] + va[kb] + vb[kb]);
                        r.v0z[q] = wc[q];
                    }
                    advect(r, fw, &m_w[d.wIdx(i, j, k0)]);
                }
        });
    }
    if (progress) progress->throwIfCancelled();
    // 4. Projection, 5. scalars, decay and emission.
    project();
    if (progress) progress->throwIfCancelled();
    advectScalars(dt);
    const float keepD = 1.0f - m_s.densityDecay * dt, keepT = 1.0f - m_s.temperatureDecay * dt;
    const uint64_t stepSeed = m_s.seed * 0x9E3779B97F4A7C15ull + uint64_t(m_steps);
    forSlabs(n.x, [&](int i) {
        for (int j = 0; j < n.y; ++j)
            for (int k = 0; k < n.z; ++k) {
                const size_t c = d.cell(i, j, k);
                if (m_solid[c]) continue;
                m_density[c] *= keepD;
                m_temperature[c] *= keepT;
            }
    });
    // Emission: the maximum of what is there and each source (in any order: max commutes).
    for (const SmokeSource& src : m_s.sources) {
        const IndexBox box = shapeBox(src.shape, m_s, n);
        forSlabs(box.hi.x - box.lo.x, [&](int slab) {
            const int i = box.lo.x + slab;
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
    const double speedSq = maxSquare(m_u, m_v, m_w);
    if (std::isnan(speedSq)) throw Error("simulate: the velocity is no longer finite at step " + std::to_string(m_steps + 1));
    m_stats.maxSpeed = std::sqrt(3.0 * speedSq);
    ++m_steps;
}

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
