// The CUDA LB device (core/lb/lb_device.h): one thread per node and channel solve, values in registers,
// Omega in constant memory, ping-pong buffers, fp32 or fp16 storage. The control flow is
// lb::solveOnDevice and the passes besides the step (start state, totals, convergence check, coarse-start
// interpolation) are core/lb/lb_kernels.h's, run with CudaExec: the CPU's code on either.
#include "cuda/lb_cuda.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include <cuda_fp16.h>

#include "core/lb/lb_device.h"
#include "core/lb/lb_kernels.h"
#include "core/lb/lb_node.h"
#include "core/lb/omega.h"
#include "cuda/cuda_check.h"
#include "cuda/device_exec.cuh"

namespace sylva::lb {

template <>
struct StoredValue<__half> {
    static SYLVA_HD SYLVA_INLINE float load(const __half* p) { return __half2float(*p); }
    static SYLVA_HD SYLVA_INLINE __half make(float v) { return __float2half_rn(v); }
};

} // namespace sylva::lb

namespace sylva::cuda {
namespace {

using lb::SymmetricOmega;
using lb::kDirections;

constexpr int kMaxSolves = 3;
__constant__ SymmetricOmega c_omega[kMaxSolves][2];   // [solve][green, brown] of the grid being stepped
__constant__ int c_dir[kDirections][3];

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
    for (int m = 0; m < kDirections; ++m) f[m] = lb::StoredValue<S>::load(s + base + size_t(m) * size_t(Z));
    const float r = rho[node];
    if (r > 0.0f) lb::collideNode(f, r, c_omega[solve][brown[node] ? 1 : 0], zeroF0 != 0);
    if (zeroF0) f[0] = 0.0f;
#pragma unroll
    for (int m = 0; m < kDirections; ++m) {
        const int ti = i + c_dir[m][0], tj = j + c_dir[m][1], tk = k + c_dir[m][2];
        if (ti < 1 || ti > X - 2 || tj < 1 || tj > Y - 2 || tk < 1 || tk > Z - 2) continue;
        d[((size_t(ti) * size_t(Y) + size_t(tj)) * kDirections + size_t(m)) * size_t(Z) + size_t(tk)] = lb::StoredValue<S>::make(f[m]);
    }
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
        lb::LbBoundary boundary;
        std::copy_n(bc.begin(), kDirections, boundary.f);
        for (DeviceBuffer<S>* copy : {&m_a, &m_b}) lb::startState(CudaExec(), copy->get(), shape(), boundary, m_params.warmStart);
    }

    double advanceBlock(int levels, int compareLevel) override
    {
        // Constant memory is shared by every grid: this grid's Omega goes in before its steps.
        check(cudaMemcpyToSymbol(c_omega, m_omega, sizeof(m_omega)), "Omega to constant memory");
        const dim3 grid(blocksFor(m_nodes, kThreads), unsigned(m_solves));
        const bool compare = compareLevel >= 1 && compareLevel < levels;
        for (int l = 0; l < levels; ++l) {
            if (m_progress) m_progress->throwIfCancelled();
            if (compare && l == compareLevel - 1) lb::nodeTotals(CudaExec(), m_a.get(), m_totA.get(), shape());
            if (compare && l == compareLevel) {
                // The change of every solve's node totals over one step (sum over the solves).
                lb::nodeTotals(CudaExec(), m_a.get(), m_totB.get(), shape());
                lb::totalsChange(CudaExec(), m_totB.get(), m_totA.get(), m_nodes * size_t(m_solves), m_acc.get());
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
        double sums[2];
        m_acc.download(sums, 2, "convergence check");
        return lb::relativeChange(sums);
    }

    // Steps between the host's progress and cancel checks (each block ends in a synchronization); the
    // CPU's wavefront depth on grids up to ~300 nodes a side, so both check convergence at the same steps.
    int autoLevels() const override { return 16; }

    void prolongateFrom(const lb::LbGrid& coarseGrid) override
    {
        const CudaGrid<S>& coarse = dynamic_cast<const CudaGrid<S>&>(coarseGrid);
        if (coarse.m_solves != m_solves) throw Error("coarse start: the coarse grid holds other channel solves");
        lb::prolongate(CudaExec(), coarse.m_a.get(), coarse.shape(), m_a.get(), shape());
    }

    void totals(size_t s, std::vector<float>& out) override
    {
        lb::nodeTotals(CudaExec(), m_a.get() + s * stride(), m_totA.get(), {m_X, m_Y, m_Z, 1});
        out.resize(m_nodes);
        m_totA.download(out.data(), m_nodes, "lighting grid");
    }

private:
    static constexpr int kThreads = 128;   // the step kernel's blocks
    size_t stride() const { return m_nodes * kDirections; }
    lb::LbShape shape() const { return {m_X, m_Y, m_Z, m_solves}; }

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
