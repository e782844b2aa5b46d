// LB kernels: one thread per node and channel, values in registers, Omega in constant memory,
// ping-pong buffers, fp32 or fp16 storage; the convergence check runs on the device.
#include "cuda/lb_cuda.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <vector>

#include <cuda_fp16.h>

#include "core/lb/lb_node.h"
#include "core/lb/omega.h"
#include "cuda/cuda_check.h"

namespace sylva::cuda {
namespace {

using lb::SymmetricOmega;
using lb::kDirections;

constexpr int kMaxSolves = 3;
__constant__ SymmetricOmega c_omega[kMaxSolves][2];   // [solve][green, brown]
__constant__ int c_dir[kDirections][3];

SYLVA_DEVICE SYLVA_INLINE float loadF(const float* p) { return *p; }
SYLVA_DEVICE SYLVA_INLINE float loadF(const __half* p) { return __half2float(*p); }
SYLVA_DEVICE SYLVA_INLINE void storeF(float* p, float v) { *p = v; }
SYLVA_DEVICE SYLVA_INLINE void storeF(__half* p, float v) { *p = __float2half_rn(v); }

// One step for every node of every solve (blockIdx.y): collide at the node, push post_m to the
// neighbour r + c_m when that neighbour is interior (LB_MODEL.md "Update").
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

template <typename S>
S toStorage(float v);
template <>
float toStorage<float>(float v)
{
    return v;
}
template <>
__half toStorage<__half>(float v)
{
    return __float2half_rn(v);
}

template <typename S>
LightingGrid solveTyped(const DensityGrid& density, const lb::LbParams& params, Progress* progress, lb::SolveStats* stats)
{
    const auto t0 = std::chrono::steady_clock::now();
    const glm::ivec3 dims = density.geometry.dims;
    const int X = dims.x, Y = dims.y, Z = dims.z;
    const size_t nodes = density.geometry.nodeCount();

    // Distinct channel solves.
    std::vector<lb::ChannelParams> solves;
    int solveOf[3];
    for (int c = 0; c < 3; ++c) {
        const lb::ChannelParams& cp = params.channels[size_t(c)];
        solveOf[c] = -1;
        for (size_t s = 0; s < solves.size(); ++s)
            if (solves[s].sigmaA == cp.sigmaA && solves[s].sigmaS == cp.sigmaS && solves[s].g == cp.g) solveOf[c] = int(s);
        if (solveOf[c] < 0) {
            solveOf[c] = int(solves.size());
            solves.push_back(cp);
        }
    }
    const int ns = int(solves.size());
    SymmetricOmega om[kMaxSolves][2];
    for (int s = 0; s < ns; ++s) {
        om[s][0] = lb::symmetricOmega(solves[size_t(s)]);
        om[s][1] = lb::symmetricOmega({solves[size_t(s)].sigmaA, solves[size_t(s)].sigmaS, -1.0f});
    }
    check(cudaMemcpyToSymbol(c_omega, om, sizeof(om)), "Omega to constant memory");
    check(cudaMemcpyToSymbol(c_dir, lb::kC, sizeof(lb::kC)), "lattice to constant memory");

    // Density and the brown mask.
    std::vector<unsigned char> brownHost(nodes, 0);
    if (!density.woodFraction.empty())
        for (size_t n = 0; n < nodes; ++n) brownHost[n] = density.woodFraction[n] > params.brownThreshold ? 1 : 0;
    DeviceBuffer<float> rho;
    rho.upload(density.density.data(), nodes, "density");
    DeviceBuffer<unsigned char> brown;
    brown.upload(brownHost.data(), nodes, "brown mask");

    // Initial state (unit intensity; scaled at the end): boundary nodes hold the sun, interior 0
    // (or the unobstructed field with warmStart). Both buffers start equal.
    const std::vector<float> bc = lb::boundaryDistribution(params.sun);
    const size_t solveStride = nodes * kDirections;
    std::vector<S> init(solveStride * size_t(ns), toStorage<S>(0.0f));
    for (int s = 0; s < ns; ++s)
        for (int i = 0; i < X; ++i)
            for (int j = 0; j < Y; ++j)
                for (int m = 0; m < kDirections; ++m) {
                    S* row = &init[size_t(s) * solveStride + ((size_t(i) * size_t(Y) + size_t(j)) * kDirections + size_t(m)) * size_t(Z)];
                    const bool wholeRow = params.warmStart || i == 0 || j == 0 || i == X - 1 || j == Y - 1;
                    for (int k = 0; k < Z; ++k)
                        if (wholeRow || k == 0 || k == Z - 1) row[k] = toStorage<S>(bc[size_t(m)]);
                }
    DeviceBuffer<S> a, b;
    a.upload(init.data(), init.size(), "distributions");
    b.upload(init.data(), init.size(), "distributions");
    init.clear();
    init.shrink_to_fit();

    const int threads = 128;
    const dim3 grid(unsigned((nodes + threads - 1) / threads), unsigned(ns));
    const int steps = params.tolerance > 0.0 ? (params.maxSteps > 0 ? params.maxSteps : 4 * density.geometry.longestEdge())
                                             : lb::fixedSteps(params, dims);
    const int checkEvery = params.checkEvery > 0 ? params.checkEvery : 16;
    DeviceBuffer<float> totA(nodes * size_t(ns), "totals"), totB(nodes * size_t(ns), "totals");
    DeviceBuffer<double> acc(2, "reduction");
    lb::SolveStats st;
    st.channelSolves = ns;
    int taken = 0;
    for (int step = 0; step < steps; ++step) {
        const bool checkNow = params.tolerance > 0.0 && (step + 1) % checkEvery == 0;
        // The check measures the change of every solve's output over one step.
        if (checkNow) totalsKernel<S><<<grid, threads>>>(a.get(), totA.get(), Z, nodes, solveStride);
        stepKernel<S><<<grid, threads>>>(a.get(), b.get(), rho.get(), brown.get(), X, Y, Z, solveStride,
                                         params.zeroF0 ? 1 : 0);
        check(cudaGetLastError(), "LB step kernel");
        std::swap(a, b);
        ++taken;
        if (checkNow) {
            totalsKernel<S><<<grid, threads>>>(a.get(), totB.get(), Z, nodes, solveStride);
            check(cudaMemset(acc.get(), 0, 2 * sizeof(double)), "reduction reset");
            const size_t all = nodes * size_t(ns);
            changeKernel<<<unsigned((all + 255) / 256), 256>>>(totB.get(), totA.get(), all, acc.get());
            double h[2];
            acc.download(h, 2, "convergence check");
            const double change = h[1] > 0.0 ? std::sqrt(h[0] / h[1]) : 0.0;
            st.lastChange = change;
            st.changeHistory.emplace_back(taken, change);
            if (change < params.tolerance) {
                st.converged = true;
                break;
            }
        }
        if (progress && (step % 8 == 7 || step + 1 == steps)) {
            check(cudaDeviceSynchronize(), "LB step");
            progress->report(double(step + 1) / double(steps), "LB step " + std::to_string(step + 1) + "/" + std::to_string(steps));
        }
    }
    check(cudaDeviceSynchronize(), "LB solve");

    // Output: total density per node and channel, times the channel's intensity.
    LightingGrid out;
    out.geometry = density.geometry;
    out.rgb.assign(nodes * 3, 0.0f);
    std::vector<float> tot(nodes * size_t(ns));
    totalsKernel<S><<<grid, threads>>>(a.get(), totA.get(), Z, nodes, solveStride);
    check(cudaGetLastError(), "totals kernel");
    totA.download(tot.data(), tot.size(), "lighting grid");
    for (int c = 0; c < 3; ++c)
        for (size_t n = 0; n < nodes; ++n) out.rgb[n * 3 + size_t(c)] = tot[size_t(solveOf[c]) * nodes + n] * params.intensity[c];
    st.steps = taken;
    st.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    st.bytesPerStep = double(solveStride) * double(ns) * sizeof(S) * 2.0;
    if (stats) *stats = st;
    return out;
}

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
    lb::validate(params);
    lb::validateDensity(density);
    if (params.storage == lb::Storage::Fp16) return solveTyped<__half>(density, params, progress, stats);
    return solveTyped<float>(density, params, progress, stats);
}

} // namespace sylva::cuda
