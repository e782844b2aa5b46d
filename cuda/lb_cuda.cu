// The CUDA LB device (core/lb/lb_device.h): one thread per node and channel solve, values in registers,
// Omega in constant memory, ping-pong buffers, fp32 or fp16 storage, the convergence check and the
// coarse-start interpolation on the device. The control flow is lb::solveOnDevice, shared with the CPU.
#include "cuda/lb_cuda.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include <cuda_fp16.h>

#include "core/lb/lb_device.h"
#include "core/lb/lb_node.h"
#include "core/lb/omega.h"
#include "cuda/cuda_check.h"

namespace sylva::cuda {
namespace {

using lb::SymmetricOmega;
using lb::kDirections;

constexpr int kMaxSolves = 3;
__constant__ SymmetricOmega c_omega[kMaxSolves][2];   // [solve][green, brown] of the grid being stepped
__constant__ int c_dir[kDirections][3];
__constant__ float c_bc[kDirections];                 // boundary condition for unit intensity

SYLVA_DEVICE SYLVA_INLINE float loadF(const float* p) { return *p; }
SYLVA_DEVICE SYLVA_INLINE float loadF(const __half* p) { return __half2float(*p); }
SYLVA_DEVICE SYLVA_INLINE void storeF(float* p, float v) { *p = v; }
SYLVA_DEVICE SYLVA_INLINE void storeF(__half* p, float v) { *p = __float2half_rn(v); }

// One step for every node of every solve (blockIdx.y): collide at the node, push post_m to the
// neighbour r + c_m when that neighbour is interior (docs/LB_MODEL.md "Update").
template <typename S>
__global__ void stepKernel(const S* __restrict__ src, S* __restrict__ dst, const float* __restrict__ rho,
                           const unsigned char* __restrict__ brown, int X, int Y, int Z, size_t solveStride, int zeroF0)
{
    const size_t node = size_t(blockIdx.x) * blockDim.x + threadIdx.x;
    const size_t nodes = size_t(X) * size_t(Y) * size_t(Z);
    if (node >= nodes) return;
    const int solve = blockIdx.y;
    const int k = int(node % size_t(Z));
    const size_t row = node / size_t(Z);
    const int j = int(row % size_t(Y)), i = int(row / size_t(Y));
    const S* s = src + size_t(solve) * solveStride;
    S* d = dst + size_t(solve) * solveStride;
    float f[kDirections];
    const size_t base = row * kDirections * size_t(Z) + size_t(k);
#pragma unroll
    for (int m = 0; m < kDirections; ++m) f[m] = loadF(s + base + size_t(m) * size_t(Z));
    const float r = rho[node];
    if (r > 0.0f) lb::collideNode(f, r, c_omega[solve][brown[node] ? 1 : 0], zeroF0 != 0);
    if (zeroF0) f[0] = 0.0f;
#pragma unroll
    for (int m = 0; m < kDirections; ++m) {
        const int ti = i + c_dir[m][0], tj = j + c_dir[m][1], tk = k + c_dir[m][2];
        if (ti < 1 || ti > X - 2 || tj < 1 || tj > Y - 2 || tk < 1 || tk > Z - 2) continue;
        storeF(d + ((size_t(ti) * size_t(Y) + size_t(tj)) * kDirections + size_t(m)) * size_t(Z) + size_t(tk), f[m]);
    }
}

// Node totals sum_m f_m of every solve (blockIdx.y) into out[solve * nodes + node].
template <typename S>
__global__ void totalsKernel(const S* __restrict__ fAll, float* __restrict__ out, int Z, size_t nodes, size_t solveStride)
{
    const size_t node = size_t(blockIdx.x) * blockDim.x + threadIdx.x;
    if (node >= nodes) return;
    const S* f = fAll + size_t(blockIdx.y) * solveStride;
    const size_t row = node / size_t(Z);
    const int k = int(node % size_t(Z));
    const size_t base = row * kDirections * size_t(Z) + size_t(k);
    float sum = 0.0f;
#pragma unroll
    for (int m = 0; m < kDirections; ++m) sum += loadF(f + base + size_t(m) * size_t(Z));
    out[size_t(blockIdx.y) * nodes + node] = sum;
}

// acc[0] += sum (a - b)^2, acc[1] += sum a^2 (block reduction, then one atomic per block).
__global__ void changeKernel(const float* __restrict__ a, const float* __restrict__ b, size_t n, double* acc)
{
    __shared__ double sd[256], sn[256];
    const size_t idx = size_t(blockIdx.x) * blockDim.x + threadIdx.x;
    double d = 0.0, nn = 0.0;
    if (idx < n) {
        const double x = a[idx], y = b[idx];
        d = (x - y) * (x - y);
        nn = x * x;
    }
    sd[threadIdx.x] = d;
    sn[threadIdx.x] = nn;
    __syncthreads();
    for (unsigned s = blockDim.x / 2; s > 0; s >>= 1) {
        if (threadIdx.x < s) {
            sd[threadIdx.x] += sd[threadIdx.x + s];
            sn[threadIdx.x] += sn[threadIdx.x + s];
        }
        __syncthreads();
    }
    if (threadIdx.x == 0) {
        atomicAdd(&acc[0], sd[0]);
        atomicAdd(&acc[1], sn[0]);
    }
}

// Every value of the distributions `f` (solves one after another, solveStride apart): the boundary
// condition c_bc on boundary nodes (everywhere with warm), 0 inside.
template <typename S>
__global__ void initKernel(S* __restrict__ f, size_t count, int X, int Y, int Z, int warm)
{
    const size_t e = size_t(blockIdx.x) * blockDim.x + threadIdx.x;
    if (e >= count) return;
    const int k = int(e % size_t(Z));
    const size_t row = e / size_t(Z);
    const int m = int(row % size_t(kDirections));
    const size_t ij = row / size_t(kDirections);
    const int j = int(ij % size_t(Y)), i = int((ij / size_t(Y)) % size_t(X));
    const bool boundary = i == 0 || j == 0 || k == 0 || i == X - 1 || j == Y - 1 || k == Z - 1;
    storeF(f + e, warm || boundary ? c_bc[m] : 0.0f);
}

// Coarse start: the interior of every solve (blockIdx.y) of `fine` interpolated from `coarse` on
// coarsen() of its grid, as the CPU does: bilinear in x and y at (i/2, j/2), then linear in z at k/2.
template <typename S>
__global__ void prolongKernel(const S* __restrict__ coarse, S* __restrict__ fine, int cX, int cY, int cZ, int X, int Y,
                              int Z, size_t coarseStride, size_t fineStride)
{
    const size_t e = size_t(blockIdx.x) * blockDim.x + threadIdx.x;
    if (e >= fineStride) return;
    const int k = int(e % size_t(Z));
    const size_t row = e / size_t(Z);
    const int m = int(row % size_t(kDirections));
    const size_t ij = row / size_t(kDirections);
    const int j = int(ij % size_t(Y)), i = int(ij / size_t(Y));
    if (i < 1 || j < 1 || k < 1 || i > X - 2 || j > Y - 2 || k > Z - 2) return;
    const S* cs = coarse + size_t(blockIdx.y) * coarseStride;
    const int I0 = min(i / 2, cX - 2), J0 = min(j / 2, cY - 2), K0 = min(k / 2, cZ - 2);
    const float fx = float(i) / 2.0f - float(I0), fy = float(j) / 2.0f - float(J0), fz = float(k) / 2.0f - float(K0);
    const float w[4] = {(1.0f - fx) * (1.0f - fy), (1.0f - fx) * fy, fx * (1.0f - fy), fx * fy};
    float xy[2];
#pragma unroll
    for (int t = 0; t < 2; ++t) {
        float v[4];
#pragma unroll
        for (int q = 0; q < 4; ++q) {
            const size_t I = size_t(I0 + (q >> 1)), J = size_t(J0 + (q & 1));
            v[q] = loadF(cs + ((I * size_t(cY) + J) * kDirections + size_t(m)) * size_t(cZ) + size_t(K0 + t));
        }
        xy[t] = w[0] * v[0] + w[1] * v[1] + w[2] * v[2] + w[3] * v[3];
    }
    storeF(fine + size_t(blockIdx.y) * fineStride + e, (1.0f - fz) * xy[0] + fz * xy[1]);
}

inline unsigned blocksFor(size_t n, int threads)
{
    return unsigned((n + size_t(threads) - 1) / size_t(threads));
}

// The channel solves of one grid on the device (lb::LbGrid): density, brown mask, two copies of f for
// every solve (a holds the current state), totals for the convergence check. The control flow of the
// solve is lb::solveOnDevice's, the same as on the CPU.
template <typename S>
class CudaGrid final : public lb::LbGrid {
public:
    CudaGrid(const DensityGrid& density, const lb::LbParams& params, const std::vector<lb::ChannelParams>& solves,
             Progress* progress)
        : m_params(params), m_progress(progress), m_X(density.geometry.dims.x), m_Y(density.geometry.dims.y),
          m_Z(density.geometry.dims.z), m_nodes(density.geometry.nodeCount())
    {
        std::vector<unsigned char> brownHost(m_nodes, 0);
        if (!density.woodFraction.empty())
            for (size_t n = 0; n < m_nodes; ++n) brownHost[n] = density.woodFraction[n] > params.brownThreshold ? 1 : 0;
        m_rho.upload(density.density.data(), m_nodes, "density");
        m_brown.upload(brownHost.data(), m_nodes, "brown mask");
        m_acc.allocate(2, "reduction");
        check(cudaMemcpyToSymbol(c_dir, lb::kC, sizeof(lb::kC)), "lattice to constant memory");
        setSolves(solves, false);
    }

    void setSolves(const std::vector<lb::ChannelParams>& solves, bool interiorFollows) override
    {
        (void)interiorFollows;   // both copies are written in full: a kernel, cheap next to the steps
        if (solves.empty() || solves.size() > size_t(kMaxSolves))
            throw Error("the CUDA LB grid holds 1 to " + std::to_string(kMaxSolves) + " channel solves, not " +
                        std::to_string(solves.size()));
        m_solves = int(solves.size());
        for (int s = 0; s < m_solves; ++s) {
            m_omega[s][0] = lb::symmetricOmega(solves[size_t(s)]);
            m_omega[s][1] = lb::symmetricOmega({solves[size_t(s)].sigmaA, solves[size_t(s)].sigmaS, -1.0f});
        }
        const size_t count = stride() * size_t(m_solves);
        if (m_a.size() < count) {
            m_a.allocate(0);
            m_b.allocate(0);
            m_a.allocate(count, "distributions");
            m_b.allocate(count, "distributions");
            m_totA.allocate(m_nodes * size_t(m_solves), "totals");
            m_totB.allocate(m_nodes * size_t(m_solves), "totals");
        }
        // Boundary condition for unit intensity; the solve is linear in intensity (scaled at the end).
        const std::vector<float> bc = lb::boundaryOf(m_params);
        check(cudaMemcpyToSymbol(c_bc, bc.data(), sizeof(float) * kDirections), "boundary condition to constant memory");
        for (DeviceBuffer<S>* copy : {&m_a, &m_b})
            initKernel<S><<<blocksFor(count, kThreads), kThreads>>>(copy->get(), count, m_X, m_Y, m_Z,
                                                                         m_params.warmStart ? 1 : 0);
        check(cudaGetLastError(), "LB initial state");
    }

    double advanceBlock(int levels, int compareLevel) override
    {
        // Constant memory is shared by every grid: this grid's Omega goes in before its steps.
        check(cudaMemcpyToSymbol(c_omega, m_omega, sizeof(m_omega)), "Omega to constant memory");
        const dim3 grid(blocksFor(m_nodes, kThreads), unsigned(m_solves));
        const bool compare = compareLevel >= 1 && compareLevel < levels;
        for (int l = 0; l < levels; ++l) {
            if (m_progress) m_progress->throwIfCancelled();
            if (compare && l == compareLevel - 1)
                totalsKernel<S><<<grid, kThreads>>>(m_a.get(), m_totA.get(), m_Z, m_nodes, stride());
            if (compare && l == compareLevel) {
                // The change of every solve's node totals over one step (sum over the solves).
                totalsKernel<S><<<grid, kThreads>>>(m_a.get(), m_totB.get(), m_Z, m_nodes, stride());
                check(cudaMemsetAsync(m_acc.get(), 0, 2 * sizeof(double)), "reduction reset");
                const size_t all = m_nodes * size_t(m_solves);
                changeKernel<<<blocksFor(all, 256), 256>>>(m_totB.get(), m_totA.get(), all, m_acc.get());
            }
            stepKernel<S><<<grid, kThreads>>>(m_a.get(), m_b.get(), m_rho.get(), m_brown.get(), m_X, m_Y, m_Z, stride(),
                                              m_params.zeroF0 ? 1 : 0);
            check(cudaGetLastError(), "LB step kernel");
            std::swap(m_a, m_b);
        }
        if (!compare) {
            check(cudaDeviceSynchronize(), "LB steps");
            return 0.0;
        }
        double h[2];
        m_acc.download(h, 2, "convergence check");
        return h[1] > 0.0 ? std::sqrt(h[0] / h[1]) : 0.0;
    }

    // Steps between the host's progress and cancel checks (each block ends in a synchronization); the
    // CPU's wavefront depth on grids up to ~300 nodes a side, so both check convergence at the same steps.
    int autoLevels() const override { return 16; }

    void prolongateFrom(const lb::LbGrid& coarseGrid) override
    {
        const CudaGrid<S>& coarse = dynamic_cast<const CudaGrid<S>&>(coarseGrid);
        if (coarse.m_solves != m_solves) throw Error("coarse start: the coarse grid holds other channel solves");
        const dim3 grid(blocksFor(stride(), kThreads), unsigned(m_solves));
        prolongKernel<S><<<grid, kThreads>>>(coarse.m_a.get(), m_a.get(), coarse.m_X, coarse.m_Y, coarse.m_Z, m_X, m_Y,
                                             m_Z, coarse.stride(), stride());
        check(cudaGetLastError(), "coarse start interpolation");
    }

    void totals(size_t s, std::vector<float>& out) override
    {
        totalsKernel<S><<<dim3(blocksFor(m_nodes, kThreads), 1), kThreads>>>(m_a.get() + s * stride(), m_totA.get(), m_Z,
                                                                                 m_nodes, stride());
        check(cudaGetLastError(), "totals kernel");
        out.resize(m_nodes);
        m_totA.download(out.data(), m_nodes, "lighting grid");
    }

private:
    static constexpr int kThreads = 128;
    size_t stride() const { return m_nodes * kDirections; }

    const lb::LbParams& m_params;
    Progress* m_progress;
    int m_X, m_Y, m_Z;
    size_t m_nodes;
    int m_solves = 0;
    SymmetricOmega m_omega[kMaxSolves][2];   // [solve][green, brown]
    DeviceBuffer<float> m_rho;
    DeviceBuffer<unsigned char> m_brown;
    DeviceBuffer<S> m_a, m_b;
    DeviceBuffer<float> m_totA, m_totB;
    DeviceBuffer<double> m_acc;
};

// The CUDA device of the shared control flow: grids in device memory, refused (BackendError, so the
// job reruns on the CPU) when one channel's distributions do not fit.
class CudaDevice final : public lb::LbDevice {
public:
    double availableBytes() const override
    {
        size_t freeBytes = 0, totalBytes = 0;
        check(cudaMemGetInfo(&freeBytes, &totalBytes), "device memory query");
        return double(freeBytes);
    }
    std::string memoryName() const override { return "device memory"; }
    [[noreturn]] void refuseMemory(const std::string& message) const override { throw BackendError("CUDA: " + message); }
    std::unique_ptr<lb::LbGrid> makeGrid(const DensityGrid& density, const lb::LbParams& params,
                                         const std::vector<lb::ChannelParams>& solves, Progress* progress) override
    {
        if (params.storage == lb::Storage::Fp16) return std::make_unique<CudaGrid<__half>>(density, params, solves, progress);
        return std::make_unique<CudaGrid<float>>(density, params, solves, progress);
    }
};

} // namespace

double deviceCopyBandwidth(size_t bytes, int reps)
{
    DeviceBuffer<char> a(bytes, "bandwidth buffer"), b(bytes, "bandwidth buffer");
    check(cudaMemset(a.get(), 1, bytes), "bandwidth buffer");
    cudaEvent_t e0, e1;
    check(cudaEventCreate(&e0), "event");
    check(cudaEventCreate(&e1), "event");
    std::vector<float> ms;
    for (int r = 0; r < reps + 1; ++r) {
        cudaEventRecord(e0);
        cudaMemcpy(b.get(), a.get(), bytes, cudaMemcpyDeviceToDevice);
        cudaEventRecord(e1);
        cudaEventSynchronize(e1);
        float t = 0.0f;
        cudaEventElapsedTime(&t, e0, e1);
        if (r > 0) ms.push_back(t);   // the first copy warms up
    }
    cudaEventDestroy(e0);
    cudaEventDestroy(e1);
    check(cudaGetLastError(), "bandwidth copies");
    std::sort(ms.begin(), ms.end());
    return 2.0 * double(bytes) / (double(ms[ms.size() / 2]) * 1e-3);
}

LightingGrid solveLightingCuda(const DensityGrid& density, const lb::LbParams& params, Progress* progress,
                               lb::SolveStats* stats)
{
    CudaDevice device;
    return lb::solveOnDevice(device, density, params, progress, stats);
}

} // namespace sylva::cuda
