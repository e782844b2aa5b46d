// CPU LB device (lb_device.h): rows along z vectorized 8 nodes wide, rows in parallel with oneTBB, fp32 or fp16 storage.
#include "core/lb/lb_solver.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <map>
#include <memory>
#include <tuple>

#include <sys/mman.h>

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#if defined(__F16C__) && defined(__AVX__)
#include <immintrin.h>
#define SYLVA_LB_F16C 1
#endif

#include "core/base/memory.h"
#include "core/base/error.h"
#include "core/base/half.h"
#include "core/base/parallel.h"
#include "core/lb/lb_device.h"
#include "core/lb/lb_kernels.h"
#include "core/lb/lb_node.h"
#include "core/lb/lb_slab.h"

namespace sylva::lb {

// fp16 storage on the CPU: F16C's conversions where present (round to nearest even, as floatToHalf).
template <>
struct StoredValue<uint16_t> {
    static SYLVA_INLINE float load(const uint16_t* p)
    {
#ifdef SYLVA_LB_F16C
        return _cvtsh_ss(*p);
#else
        return halfToFloat(*p);
#endif
    }
    static SYLVA_INLINE uint16_t make(float v) { return floatToHalf(v); }
};

namespace {

constexpr int kLanes = 8;
typedef float Vec8 __attribute__((vector_size(32)));   // 8 floats; GCC vector extension
typedef int Vec8i __attribute__((vector_size(32)));

// Unaligned 8-float access through a vector type that only promises 4-byte alignment, so the compiler
// emits one vector load/store (a memcpy into a local spilled halves through the stack).
typedef float Vec8u __attribute__((vector_size(32), aligned(4)));
inline Vec8 loadVec(const float* p) { return *reinterpret_cast<const Vec8u*>(p); }
inline void storeVec(float* p, Vec8 v) { *reinterpret_cast<Vec8u*>(p) = v; }

} // namespace

// vmaxps for the 8-wide vectors: same result as the generic x > 0 ? x : 0 (0 for NaN), one instruction.
template <>
struct Lanes<Vec8> {
    static Vec8 nonNegative(Vec8 x)
    {
#ifdef SYLVA_LB_F16C
        const __m256 r = _mm256_max_ps(reinterpret_cast<__m256>(x), _mm256_setzero_ps());
        return reinterpret_cast<Vec8>(r);
#else
        return x > Vec8{} ? x : Vec8{};
#endif
    }
};

namespace {

// SymmetricOmega with every coefficient broadcast to 8 lanes: the products use a vector operand from
// L1 instead of a broadcast per multiply-add.
struct SymmetricOmega8 {
    Vec8 ass, asg, bss, bsg, ags, agg, bgs, bgg, dd, oDD, oDV, oVD, oVV, oWW;
    float sigmaA;
    float sigmaT;
    explicit SymmetricOmega8(const SymmetricOmega& c) : sigmaA(c.sigmaA), sigmaT(c.sigmaT)
    {
        auto bc = [](float v) { return Vec8{v, v, v, v, v, v, v, v}; };
        ass = bc(c.ass);
        asg = bc(c.asg);
        bss = bc(c.bss);
        bsg = bc(c.bsg);
        ags = bc(c.ags);
        agg = bc(c.agg);
        bgs = bc(c.bgs);
        bgg = bc(c.bgg);
        dd = bc(c.dd);
        oDD = bc(c.oDD);
        oDV = bc(c.oDV);
        oVD = bc(c.oVD);
        oVV = bc(c.oVV);
        oWW = bc(c.oWW);
    }
};

// Storage conversion of n contiguous values.
inline void loadRow(const float* src, float* dst, int n) { std::memcpy(dst, src, size_t(n) * sizeof(float)); }
inline void storeRow(const float* src, float* dst, int n) { std::memcpy(dst, src, size_t(n) * sizeof(float)); }
// With n >= 8 a ragged end is one more vector ending at n, overlapping the last full one: the overlap
// rewrites the same values, so no element takes the (slow) scalar conversion.
inline void loadRow(const uint16_t* src, float* dst, int n)
{
    int k = 0;
#ifdef SYLVA_LB_F16C
    auto one = [&](int at) {
        _mm256_storeu_ps(dst + at, _mm256_cvtph_ps(_mm_loadu_si128(reinterpret_cast<const __m128i*>(src + at))));
    };
    for (; k + 8 <= n; k += 8) one(k);
    if (k < n && n >= 8) {
        one(n - 8);
        k = n;
    }
#endif
    for (; k < n; ++k) dst[k] = halfToFloat(src[k]);
}
inline void storeRow(const float* src, uint16_t* dst, int n)
{
    int k = 0;
#ifdef SYLVA_LB_F16C
    auto one = [&](int at) {
        _mm_storeu_si128(reinterpret_cast<__m128i*>(dst + at), _mm256_cvtps_ph(_mm256_loadu_ps(src + at), _MM_FROUND_TO_NEAREST_INT));
    };
    for (; k + 8 <= n; k += 8) one(k);
    if (k < n && n >= 8) {
        one(n - 8);
        k = n;
    }
#endif
    for (; k < n; ++k) dst[k] = floatToHalf(src[k]);
}
// 8 stored values as floats (the caller guarantees 8 readable values).
inline Vec8 loadVector(const float* p) { return loadVec(p); }
inline Vec8 loadVector(const uint16_t* p)
{
#ifdef SYLVA_LB_F16C
    const __m256 v = _mm256_cvtph_ps(_mm_loadu_si128(reinterpret_cast<const __m128i*>(p)));
    Vec8 out;
    std::memcpy(&out, &v, sizeof out);
    return out;
#else
    Vec8 out;
    for (int l = 0; l < kLanes; ++l) out[l] = halfToFloat(p[l]);
    return out;
#endif
}

// A large array on 2 MB pages where the kernel allows it (madvise): the streaming step touches ~30
// pages per row, so with 4 KB pages most of them miss the TLB.
template <typename S>
class PageArray {
public:
    PageArray() = default;
    PageArray(const PageArray&) = delete;
    PageArray& operator=(const PageArray&) = delete;
    ~PageArray() { std::free(m_data); }
    void assign(size_t n, S value)
    {
        allocate(n);
        std::fill(m_data, m_data + n, value);
    }
    // Room for n values, not initialized.
    void allocate(size_t n)
    {
        std::free(m_data);
        m_data = nullptr;
        m_size = n;
        constexpr size_t kHuge = size_t(2) << 20;
        const size_t bytes = (n * sizeof(S) + kHuge - 1) / kHuge * kHuge;
        void* p = nullptr;
        if (posix_memalign(&p, kHuge, std::max(bytes, kHuge)) != 0) throw std::bad_alloc();
#ifdef MADV_HUGEPAGE
        madvise(p, std::max(bytes, kHuge), MADV_HUGEPAGE);
#endif
        m_data = static_cast<S*>(p);
    }
    S* data() { return m_data; }
    const S* data() const { return m_data; }
    size_t size() const { return m_size; }
    S& operator[](size_t i) { return m_data[i]; }
    const S& operator[](size_t i) const { return m_data[i]; }

private:
    S* m_data = nullptr;
    size_t m_size = 0;
};

// One distinct channel solve: optics (green and brown) and two copies of f.
template <typename S>
struct ChannelField {
    ChannelField(const SymmetricOmega& greenOmega, const SymmetricOmega& brownOmega) : green(greenOmega), brown(brownOmega) {}
    SymmetricOmega8 green, brown;
    PageArray<S> a, b;
    bool flip = false;
};

struct Scratch {
    std::vector<float> buf;   // 19 rows of Zp floats
};

template <typename S>
class Solver final : public LbGrid {
public:
    Solver(const DensityGrid& density, const LbParams& params, const std::vector<ChannelParams>& solves)
        : m_params(params), m_dims(density.geometry.dims)
    {
        m_X = m_dims.x;
        m_Y = m_dims.y;
        m_Z = m_dims.z;
        m_Zp = (m_Z + kLanes - 1) / kLanes * kLanes;
        const size_t rows = size_t(m_X) * size_t(m_Y);
        m_rho.assign(rows * size_t(m_Zp), 0.0f);
        m_brown.assign(rows * size_t(m_Zp), 0);
        m_rowActive.assign(rows, 0);
        m_rowBrown.assign(rows, 0);
        for (size_t r = 0; r < rows; ++r)
            for (int k = 0; k < m_Z; ++k) {
                const size_t n = r * size_t(m_Z) + size_t(k);
                const float rho = density.density[n];
                const bool brown = !density.woodFraction.empty() && density.woodFraction[n] > params.brownThreshold;
                m_rho[r * size_t(m_Zp) + size_t(k)] = rho;
                m_brown[r * size_t(m_Zp) + size_t(k)] = brown ? -1 : 0;
                if (rho > 0.0f) {
                    m_rowActive[r] = 1;
                    if (brown) m_rowBrown[r] = 1;
                }
            }
        setSolves(solves, false);
        // Where each direction's row segment goes, relative to the source row (i, j, 0, 0): the
        // neighbour row's segment m, shifted by c_z; the source range skips the z boundary nodes.
        for (int m = 0; m < kDirections; ++m) {
            const int cz = kC[m][2];
            m_streamK0[m] = std::max(0, 1 - cz);
            m_streamLen[m] = std::min(m_Z - 1, m_Z - 2 - cz) - m_streamK0[m] + 1;
            m_streamOff[m] = (ptrdiff_t(kC[m][0]) * m_Y + kC[m][1]) * kDirections * ptrdiff_t(m_Z) + ptrdiff_t(m) * m_Z +
                             m_streamK0[m] + cz;
        }
    }

    // Makes the solver's channel solves `solves`, each starting from the boundary condition (everywhere
    // with a warm start) and zero inside. Memory of earlier solves is reused: a solver advances one
    // channel group after another without touching fresh pages again (on this VM the kernel's zeroing of
    // fresh pages cost ~15% of a 128^3 solve). With interiorFollows the caller writes the interior of
    // the current copy next (prolongateFrom), so only new memory is initialized; the other copy's
    // interior is overwritten by the first step and its boundary keeps the boundary condition.
    void setSolves(const std::vector<ChannelParams>& solves, bool interiorFollows) override
    {
        // Boundary condition for unit intensity; the solve is linear in intensity (scaled at the end).
        const std::vector<float> bc = boundaryOf(m_params);
        LbBoundary boundary;
        std::copy_n(bc.begin(), kDirections, boundary.f);
        const size_t count = shape().values();
        m_fields.resize(std::min(m_fields.size(), solves.size()));
        for (size_t c = 0; c < solves.size(); ++c) {
            const ChannelParams& cp = solves[c];
            const SymmetricOmega green = symmetricOmega(cp), brown = symmetricOmega({cp.sigmaA, cp.sigmaS, -1.0f});
            const bool fresh = c >= m_fields.size();
            if (fresh) {
                m_fields.push_back(std::make_unique<ChannelField<S>>(green, brown));
                m_fields[c]->a.allocate(count);
                m_fields[c]->b.allocate(count);
            } else {
                m_fields[c]->green = SymmetricOmega8(green);
                m_fields[c]->brown = SymmetricOmega8(brown);
            }
            ChannelField<S>& field = *m_fields[c];
            field.flip = false;
            if (!fresh && interiorFollows) continue;
            // Fresh memory: both copies in full, in parallel (each slab of rows by the thread that will
            // first touch it). Reused memory: the interior of the current copy; the rows on the x and y
            // faces already hold the boundary condition in both.
            startState(HostExec(), field.a.data(), shape(), boundary, m_params.warmStart, !fresh);
            if (fresh) startState(HostExec(), field.b.data(), shape(), boundary, m_params.warmStart);
        }
        m_skipF0 = m_params.zeroF0 && bc[0] == 0.0f;
    }

    size_t bytesPerStep() const { return m_fields.size() * size_t(m_X) * m_Y * m_Z * kDirections * sizeof(S) * 2; }

    // Advances every channel by `levels` steps as a wavefront over x-slabs (temporal blocking): level l
    // processes source slab w - l, one slab behind level l-1, so the slabs a block touches stay in cache.
    // Two full copies of f suffice: level l reads the copy level l-1 wrote, and the one-slab lag keeps every
    // read ahead of the next overwrite. Each node update is the same arithmetic as a plain step, so the
    // result is bit-identical for any block depth. With compareLevel >= 1, level compareLevel-1 stores the
    // node totals and level compareLevel returns the relative L2 change between the two (else 0).
    double advanceBlock(int levels, int compareLevel) override
    {
        const size_t totals = m_fields.size() * shape().nodes();
        if (compareLevel >= 1 && m_totals[0].size() != totals)
            for (std::vector<float>& t : m_totals) t.assign(totals, 0.0f);
        for (size_t c = 0; c < m_fields.size(); ++c) {
            ChannelField<S>& field = *m_fields[c];
            for (int w = 0; w < m_X + levels - 1; ++w) {
                if (m_progress) m_progress->throwIfCancelled();
                for (int l = 0; l < levels; ++l) {
                    const int x = w - l;
                    if (x < 0 || x >= m_X) continue;
                    const bool odd = (l & 1) != 0;
                    const S* src = (field.flip != odd) ? field.b.data() : field.a.data();
                    S* dst = (field.flip != odd) ? field.a.data() : field.b.data();
                    const int outMode = compareLevel < 1 ? 0 : (l == compareLevel - 1 ? 1 : (l == compareLevel ? 2 : 0));
                    stepPlane(c, x, src, dst, outMode);
                }
            }
            if (levels & 1) field.flip = !field.flip;
        }
        if (compareLevel < 1) return 0.0;
        double sums[2];
        totalsChange(HostExec(), m_totals[1].data(), m_totals[0].data(), totals, sums);
        return relativeChange(sums);
    }

    // One step of source plane x of channel solve c from src into dst (the collision of its rows and their
    // streaming into planes x-1, x, x+1; the grid's faces are never written): the one node update every
    // step runs, whole grids (advanceBlock) and slabs of a distributed grid (CpuSlab) alike.
    void stepPlane(size_t c, int x, const S* src, S* dst, int outMode)
    {
        const size_t grain = size_t(std::max(1, m_Y / 16));
        tbb::parallel_for(tbb::blocked_range<size_t>(0, size_t(m_Y), grain), [&](const tbb::blocked_range<size_t>& range) {
            Scratch& sc = m_scratch.local();
            if (sc.buf.size() != size_t(kDirections) * size_t(m_Zp)) sc.buf.assign(size_t(kDirections) * size_t(m_Zp), 0.0f);
            for (size_t j = range.begin(); j != range.end(); ++j) {
                const size_t r = size_t(x) * size_t(m_Y) + j;
                if (j + 2 < range.end()) prefetchRow(r + 2, src, dst);   // two rows ahead: measured better than one
                processRow(r, c, src, dst, sc, outMode);
            }
        });
    }

    // A step in parts (CpuSlab): source planes [x0, x1) of solve c from the current copy into the other,
    // which becomes current with flipState once every plane has been stepped.
    void stepPlanes(size_t c, int x0, int x1)
    {
        ChannelField<S>& field = *m_fields[c];
        const S* src = field.flip ? field.b.data() : field.a.data();
        S* dst = field.flip ? field.a.data() : field.b.data();
        for (int x = std::max(0, x0); x < std::min(m_X, x1); ++x) {
            if (m_progress) m_progress->throwIfCancelled();
            stepPlane(c, x, src, dst, 0);
        }
    }
    void flipState(size_t c) { m_fields[c]->flip = !m_fields[c]->flip; }
    // Plane x of the current copy of solve c: Y x 19 x Z stored values, contiguous.
    S* currentPlane(size_t c, int x)
    {
        ChannelField<S>& field = *m_fields[c];
        return (field.flip ? field.b.data() : field.a.data()) + dindex(x, 0, 0, 0);
    }
    size_t planeValues() const { return size_t(m_Y) * kDirections * size_t(m_Z); }
    int planes() const { return m_X; }

    // Slab depth of the wavefront: as many levels as keep (levels + 3) slabs of both copies in ~12 MB.
    int autoLevels() const override
    {
        const double slab = double(m_Y) * m_Z * kDirections * sizeof(S);
        return std::clamp(int(12.0e6 / (2.0 * slab)) - 3, 1, 16);
    }

    // Starts every channel solve from the current state of `coarse`, the same solves on coarsen() of this
    // grid (lb_kernels.h's prolongate); boundary nodes keep the boundary condition setSolves set. Only the
    // current copy's interior is written: the first step overwrites the other copy's interior and its
    // boundary already holds the boundary condition.
    void prolongateFrom(const LbGrid& coarseGrid) override
    {
        const Solver<S>& coarse = dynamic_cast<const Solver<S>&>(coarseGrid);
        for (size_t c = 0; c < m_fields.size(); ++c) {
            const ChannelField<S>& cf = *coarse.m_fields[c];
            ChannelField<S>& field = *m_fields[c];
            field.flip = false;
            prolongate(HostExec(), cf.flip ? cf.b.data() : cf.a.data(), coarse.shape(), field.a.data(), shape());
        }
    }

    // Raw access to the current state of channel solve c (storage order, fp32 values).
    void setState(size_t c, const std::vector<float>& f)
    {
        m_skipF0 = false;   // the given state may hold f_0
        ChannelField<S>& field = *m_fields[c];
        const size_t chunk = size_t(m_Z) * kDirections;   // one (i, j) row of all directions
        tbb::parallel_for(size_t(0), f.size() / chunk, [&](size_t r) {
            storeRow(f.data() + r * chunk, field.a.data() + r * chunk, int(chunk));
            std::copy_n(field.a.data() + r * chunk, chunk, field.b.data() + r * chunk);
        });
        field.flip = false;
    }
    void getState(size_t c, std::vector<float>& f) const
    {
        const ChannelField<S>& field = *m_fields[c];
        const S* cur = field.flip ? field.b.data() : field.a.data();
        f.resize(field.a.size());
        loadRow(cur, f.data(), int(f.size()));
    }

    // Node totals sum_m f_m of the current state, for channel solve c.
    void totals(size_t c, std::vector<float>& out) override
    {
        const ChannelField<S>& f = *m_fields[c];
        out.resize(shape().nodes());
        nodeTotals(HostExec(), f.flip ? f.b.data() : f.a.data(), out.data(), shape());
    }

private:
    LbShape shape() const { return {m_X, m_Y, m_Z, 1}; }

    size_t dindex(int i, int j, int k, int m) const
    {
        return ((size_t(i) * size_t(m_Y) + size_t(j)) * kDirections + size_t(m)) * size_t(m_Z) + size_t(k);
    }

    // Asks for the cache lines the next row will read (its 19 contiguous source rows) and write (one
    // row segment in each neighbour): the stores miss the private caches otherwise and stall the loop.
    void prefetchRow(size_t r, const S* src, S* dst) const
    {
        const int i = int(r / size_t(m_Y)), j = int(r % size_t(m_Y));
        const char* s = reinterpret_cast<const char*>(src + dindex(i, j, 0, 0));
        const size_t rowBytes = size_t(kDirections) * size_t(m_Z) * sizeof(S);
        for (size_t b = 0; b < rowBytes; b += 64) __builtin_prefetch(s + b, 0, 3);
        const size_t segBytes = size_t(m_Z) * sizeof(S);
        for (int m = m_skipF0 ? 1 : 0; m < kDirections; ++m) {
            const int ti = i + kC[m][0], tj = j + kC[m][1];
            if (ti < 1 || ti > m_X - 2 || tj < 1 || tj > m_Y - 2) continue;
            const char* d = reinterpret_cast<const char*>(dst + dindex(ti, tj, 0, m));
            for (size_t b = 0; b < segBytes; b += 64) __builtin_prefetch(d + b, 1, 3);
        }
    }

    void processRow(size_t r, size_t c, const S* src, S* dst, Scratch& s, int outMode)
    {
        const int i = int(r / size_t(m_Y)), j = int(r % size_t(m_Y));
        const size_t rowBase = dindex(i, j, 0, 0);
        const S* srcRow = src + rowBase;
        S* dstRow = dst + rowBase;
        // Rows next to the x/y faces have neighbours on the boundary, which keeps its values.
        const bool nearFace = i < 2 || i > m_X - 3 || j < 2 || j > m_Y - 3;
        auto targetIsBoundary = [&](int m) {
            const int ti = i + kC[m][0], tj = j + kC[m][1];
            return ti < 1 || ti > m_X - 2 || tj < 1 || tj > m_Y - 2;
        };
        const int firstM = m_skipF0 ? 1 : 0;
        if (outMode == 0 && !m_rowActive[r]) {
            // No medium in the row and no totals wanted: the values stream unchanged (f_0 zeroed), so
            // they are copied in storage form, which is exactly what converting and back would give.
            for (int m = firstM; m < kDirections; ++m) {
                if ((nearFace && targetIsBoundary(m)) || m_streamLen[m] <= 0) continue;
                S* d = dstRow + m_streamOff[m];
                if (m == 0 && m_params.zeroF0) std::fill(d, d + m_streamLen[m], StoredValue<S>::make(0.0f));
                else std::memcpy(d, srcRow + size_t(m) * size_t(m_Z) + size_t(m_streamK0[m]), size_t(m_streamLen[m]) * sizeof(S));
            }
            return;
        }
        float* buf = s.buf.data();
        const size_t Zp = size_t(m_Zp);
        // With m_skipF0 the f_0 row of buf is already zero (set at the end of the previous row).
        // 1-3. Load, (sum,) collide and park in buf one vector of 8 nodes at a time: the values stay in
        // registers between the load and the collision.
        collideRowFused(r, c, srcRow, buf, firstM, outMode);
        if (m_params.zeroF0) std::fill(buf, buf + Zp, 0.0f);   // absorbed: f_0 leaves the visible band
        // 4. Stream: post_m(r) goes to r + c_m when that node is interior.
        for (int m = firstM; m < kDirections; ++m) {
            if ((nearFace && targetIsBoundary(m)) || m_streamLen[m] <= 0) continue;
            storeRow(buf + size_t(m) * Zp + size_t(m_streamK0[m]), dstRow + m_streamOff[m], m_streamLen[m]);
        }
    }

    // The collision of one 8-node vector in place (f holds the 19 directions).
    void collideVector(Vec8 (&f)[kDirections], size_t r, size_t k, const ChannelField<S>& field) const
    {
        const size_t Zp = size_t(m_Zp);
        const float* rho = &m_rho[r * Zp];
        const int* brown = &m_brown[r * Zp];
        const Vec8 rv = loadVec(rho + k);
        bool anyBrown = false;
        if (m_rowBrown[r])
            for (int l = 0; l < kLanes; ++l) anyBrown |= brown[k + size_t(l)] != 0;
        if (!anyBrown) {
            collideNode(f, rv, field.green, m_params.zeroF0);
        } else {
            Vec8 fb[kDirections];
            for (int m = 0; m < kDirections; ++m) fb[m] = f[m];
            collideNode(f, rv, field.green, m_params.zeroF0);
            collideNode(fb, rv, field.brown, m_params.zeroF0);
            Vec8i mask;
            std::memcpy(&mask, brown + k, sizeof mask);
            for (int m = 0; m < kDirections; ++m) f[m] = mask ? fb[m] : f[m];
        }
    }

    bool vectorActive(size_t r, size_t k) const
    {
        const float* rho = &m_rho[r * size_t(m_Zp)];
        bool any = false;
        for (int l = 0; l < kLanes; ++l) any |= rho[k + size_t(l)] > 0.0f;
        return any;
    }

    // Loads each 8-node vector of an active row straight from storage, collides it when it holds
    // medium, and writes it to buf (the rows of 19 directions the streaming then reads).
    // With outMode 1 or 2 it stores the node totals sum_m f_m of the source state (nodeTotal, the
    // tolerance check) in m_totals[0] or [1].
    void collideRowFused(size_t r, size_t c, const S* srcRow, float* buf, int firstM, int outMode)
    {
        const ChannelField<S>& field = *m_fields[c];
        const size_t Zp = size_t(m_Zp), Z = size_t(m_Z);
        float* tot = outMode != 0 ? &m_totals[size_t(outMode - 1)][(c * size_t(m_X) * m_Y + r) * Z] : nullptr;
        Vec8 f[kDirections];
        if (firstM == 1) f[0] = Vec8{};
        for (size_t k = 0; k < Zp; k += kLanes) {
            if (k + kLanes <= Z) {
                for (int m = firstM; m < kDirections; ++m) f[m] = loadVector(srcRow + size_t(m) * Z + k);
            } else {   // the ragged end of a row whose length is no multiple of 8: zero padding
                float tmp[kLanes];
                for (int m = firstM; m < kDirections; ++m) {
                    std::fill(tmp, tmp + kLanes, 0.0f);
                    loadRow(srcRow + size_t(m) * Z + k, tmp, int(Z - k));
                    f[m] = loadVec(tmp);
                }
            }
            if (tot) {
                const Vec8 sum = nodeTotal(f);
                for (size_t l = 0; l < kLanes && k + l < Z; ++l) tot[k + l] = sum[l];
            }
            if (m_rowActive[r] && vectorActive(r, k)) collideVector(f, r, k, field);
            for (int m = firstM; m < kDirections; ++m) storeVec(buf + size_t(m) * Zp + k, f[m]);
        }
    }

public:
    Progress* m_progress = nullptr;   // checked for cancel once per wavefront slab

private:
    const LbParams& m_params;
    glm::ivec3 m_dims;
    int m_X = 0, m_Y = 0, m_Z = 0, m_Zp = 0;
    std::vector<float> m_rho;          // padded rows of density
    std::vector<int> m_brown;          // padded rows, -1 where brown
    std::vector<uint8_t> m_rowActive;  // any density in the row
    std::vector<uint8_t> m_rowBrown;   // any brown node in the row
    // f_0 is zero in both copies and stays so (zeroF0 from a start that has it zero: the boundary
    // condition, the coarse start): its rows are then neither read nor written, 1/19 of the traffic.
    bool m_skipF0 = false;
    int m_streamK0[kDirections] = {}, m_streamLen[kDirections] = {};
    ptrdiff_t m_streamOff[kDirections] = {};
    std::vector<std::unique_ptr<ChannelField<S>>> m_fields;
    std::vector<float> m_totals[2];   // the node totals of the tolerance check: before and after a step
    tbb::enumerable_thread_specific<Scratch> m_scratch;
};

// The CPU device: grids are Solvers of the storage type params.storage asks for, memory what the
// machine has available.
class CpuDevice final : public LbDevice {
public:
    double availableBytes() const override { return availableMemoryBytes(); }
    std::string memoryName() const override { return "memory"; }
    std::unique_ptr<LbGrid> makeGrid(const DensityGrid& density, const LbParams& params,
                                     const std::vector<ChannelParams>& solves, Progress* progress) override
    {
        std::unique_ptr<LbGrid> grid;
        if (params.storage == Storage::Fp16) {
            auto g = std::make_unique<Solver<uint16_t>>(density, params, solves);
            g->m_progress = progress;
            grid = std::move(g);
        } else {
            auto g = std::make_unique<Solver<float>>(density, params, solves);
            g->m_progress = progress;
            grid = std::move(g);
        }
        return grid;
    }
};

// A slab of a distributed grid (lb_slab.h): a Solver on the slab's local grid, one channel solve.
template <typename S>
class CpuSlab final : public LbSlab {
public:
    CpuSlab(const DensityGrid& local, const LbParams& params, Progress* progress)
        : m_params(params), m_solver(local, m_params, {params.channels[0]})
    {
        m_solver.m_progress = progress;
    }
    void setSolve(const ChannelParams& solve) override { m_solver.setSolves({solve}, false); }
    void stepPlanes(int x0, int x1) override { m_solver.stepPlanes(0, x0, x1); }
    void finishStep() override { m_solver.flipState(0); }
    void* plane(int x) override { return m_solver.currentPlane(0, x); }
    size_t planeBytes() const override { return m_solver.planeValues() * sizeof(S); }
    int planes() const override { return m_solver.planes(); }
    void totals(std::vector<float>& out) override { m_solver.totals(0, out); }

private:
    const LbParams m_params;   // the Solver keeps a reference
    Solver<S> m_solver;
};

} // namespace

void advance(const DensityGrid& density, const LbParams& params, std::vector<float>& f, int steps)
{
    validate(params);
    validateDensity(density);
    const size_t expected = density.geometry.nodeCount() * size_t(kDirections);
    if (f.size() != expected)
        throw Error("LB state holds " + std::to_string(f.size()) + " values, expected " + std::to_string(expected));
    auto run = [&](auto tag) {
        using S = decltype(tag);
        Solver<S> solver(density, params, {params.channels[0]});
        solver.setState(0, f);
        const int block = params.blockSteps > 0 ? params.blockSteps : solver.autoLevels();
        for (int t = 0; t < steps; t += block) solver.advanceBlock(std::min(block, steps - t), 0);
        solver.getState(0, f);
    };
    if (params.storage == Storage::Fp16) run(uint16_t{});
    else run(float{});
}

SlabRange slabOwned(int X, int index, int count)
{
    const int interior = X - 2;
    if (count < 1 || index < 0 || index >= count) throw Error("LB slabs: slab " + std::to_string(index) + " of " + std::to_string(count));
    if (interior < count)
        throw Error("the grid has " + std::to_string(interior) + " interior x-planes, fewer than the " + std::to_string(count) +
                    " slabs it is to be split into; use fewer ranks");
    const int base = interior / count, extra = interior % count;
    SlabRange r;
    r.begin = 1 + index * base + std::min(index, extra);
    r.end = r.begin + base + (index < extra ? 1 : 0);
    return r;
}

DensityGrid slabDensity(const DensityGrid& density, SlabRange owned)
{
    const glm::ivec3 d = density.geometry.dims;
    if (owned.begin < 1 || owned.end > d.x - 1 || owned.begin >= owned.end) throw Error("LB slabs: planes outside the grid");
    const int x0 = owned.begin - 1, x1 = owned.end + 1;
    DensityGrid s;
    s.geometry = density.geometry;
    s.geometry.dims.x = x1 - x0;
    s.geometry.origin.x += double(x0) * s.geometry.spacing;
    const size_t plane = size_t(d.y) * size_t(d.z);
    s.density.assign(density.density.begin() + long(size_t(x0) * plane), density.density.begin() + long(size_t(x1) * plane));
    if (!density.woodFraction.empty())
        s.woodFraction.assign(density.woodFraction.begin() + long(size_t(x0) * plane), density.woodFraction.begin() + long(size_t(x1) * plane));
    return s;
}

std::unique_ptr<LbSlab> makeCpuSlab(const DensityGrid& local, const LbParams& params, Progress* progress)
{
    validate(params);
    validateDensity(local);
    if (params.storage == Storage::Fp16) return std::make_unique<CpuSlab<uint16_t>>(local, params, progress);
    return std::make_unique<CpuSlab<float>>(local, params, progress);
}

std::vector<float> boundaryDistribution(const glm::vec3& sun)
{
    const glm::dvec3 d = -glm::normalize(glm::dvec3(sun));
    std::vector<float> bc(kDirections, 0.0f);
    for (int m = 1; m < kDirections; ++m) {
        const glm::dvec3 n = glm::normalize(glm::dvec3(kC[m][0], kC[m][1], kC[m][2]));
        bc[size_t(m)] = float(std::max(0.0, glm::dot(n, d)));
    }
    return bc;
}

std::vector<float> beamDistribution(const glm::vec3& sun)
{
    std::vector<float> bc(kDirections, 0.0f);
    if (!(glm::dot(sun, sun) > 0.0f)) return bc;
    const glm::dvec3 t = -glm::normalize(glm::dvec3(sun));
    glm::dvec3 u[kDirections];
    for (int m = 1; m < kDirections; ++m) u[m] = glm::normalize(glm::dvec3(kC[m][0], kC[m][1], kC[m][2]));
    // Every triple whose cone holds t (Cramer's rule, weights >= 0); the tightest: the least weighted angle.
    double best = 1e300;
    int pick[3] = {0, 0, 0};
    double weight[3] = {0.0, 0.0, 0.0};
    for (int a = 1; a < kDirections; ++a)
        for (int b = a + 1; b < kDirections; ++b)
            for (int c = b + 1; c < kDirections; ++c) {
                const glm::dmat3 M(u[a], u[b], u[c]);
                const double det = glm::determinant(M);
                if (std::fabs(det) < 1e-9) continue;
                const glm::dvec3 w = glm::inverse(M) * t;
                if (w.x < -1e-12 || w.y < -1e-12 || w.z < -1e-12) continue;
                const double spread = w.x * (1.0 - glm::dot(u[a], t)) + w.y * (1.0 - glm::dot(u[b], t)) + w.z * (1.0 - glm::dot(u[c], t));
                if (spread < best - 1e-12) best = spread, pick[0] = a, pick[1] = b, pick[2] = c, weight[0] = w.x, weight[1] = w.y, weight[2] = w.z;
            }
    const double sum = std::max(weight[0], 0.0) + std::max(weight[1], 0.0) + std::max(weight[2], 0.0);
    for (int k = 0; k < 3; ++k)
        if (pick[k] > 0 && sum > 0.0) bc[size_t(pick[k])] = float(std::max(weight[k], 0.0) / sum);
    return bc;
}

std::vector<float> boundaryOf(const LbParams& params)
{
    return params.boundary.empty() ? boundaryDistribution(params.sun) : params.boundary;
}

std::unique_ptr<LbDevice> makeCpuDevice() { return std::make_unique<CpuDevice>(); }

LightingGrid solveLighting(const DensityGrid& density, const LbParams& params, Progress* progress, SolveStats* stats)
{
    CpuDevice device;
    return solveOnDevice(device, density, params, progress, stats);
}

} // namespace sylva::lb
