// GPU benchmark: the LB solve at 128^3 RGB against the device's copy bandwidth, and the default forest
// frame, each side by side with the CPU path in the same run. Without a device it says so and exits 0.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

#include "core/lb/lb_solver.h"
#include "core/render/render_cpu.h"
#include "cuda/device_query.h"
#include "pipeline/cache/grid_cache.h"
#include "pipeline/render/render_job.h"
#if SYLVA_HAVE_CUDA
#include "cuda/lb_cuda.h"
#include "cuda/render_cuda.h"
#endif

using namespace sylva;

namespace {

double now() { return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count(); }

template <class F>
double median(int reps, F&& f)
{
    std::vector<double> t;
    for (int r = 0; r < reps; ++r) {
        const double t0 = now();
        f();
        t.push_back(now() - t0);
    }
    std::sort(t.begin(), t.end());
    return t[t.size() / 2];
}

// A 128^3 crown-like grid: an ellipsoid of medium with random holes (as bench_lb's synthetic crown).
DensityGrid crown(int n)
{
    DensityGrid d;
    d.geometry.dims = glm::ivec3(n);
    d.geometry.spacing = 0.1;
    d.density.assign(d.geometry.nodeCount(), 0.0f);
    uint32_t h = 12345;
    for (int i = 1; i < n - 1; ++i)
        for (int j = 1; j < n - 1; ++j)
            for (int k = 1; k < n - 1; ++k) {
                const glm::vec3 p = (glm::vec3(i, j, k) - glm::vec3(n / 2.0f)) / (n * 0.4f);
                h = h * 1664525u + 1013904223u;
                if (glm::dot(p, p) < 1.0f && (h >> 24) < 80) d.density[d.geometry.index(i, j, k)] = float(h >> 28) / 15.0f;
            }
    return d;
}

} // namespace

int main(int argc, char** argv)
{
    int grid = 128, reps = 3;
    bool cpu = true;
    for (int a = 1; a < argc; ++a) {
        if (!std::strcmp(argv[a], "--grid") && a + 1 < argc) grid = std::atoi(argv[++a]);
        else if (!std::strcmp(argv[a], "--reps") && a + 1 < argc) reps = std::atoi(argv[++a]);
        else if (!std::strcmp(argv[a], "--no-cpu")) cpu = false;
        else {
            std::printf("usage: bench_gpu [--grid N] [--reps N] [--no-cpu]\n");
            return 2;
        }
    }
    const cuda::DeviceQuery q = cuda::queryDevices();
    if (q.devices.empty()) {
        std::printf("bench_gpu: no CUDA device (%s); nothing to measure\ndevice=none\n",
                    q.built ? q.message.c_str() : "this build has no CUDA backend");
        return 0;
    }
#if SYLVA_HAVE_CUDA
    std::printf("device: %s, %d SMs, %.1f GiB\n", q.devices[0].name.c_str(), q.devices[0].multiprocessors,
                double(q.devices[0].totalMemoryBytes) / (1 << 30));
    // LB: leaf preset (three distinct channels), default steps.
    const DensityGrid d = crown(grid);
    lb::LbParams p = lb::paramsFromPreset(*lb::findPreset("leaf"));
    p.sun = {0.3f, 1.0f, 0.2f};
    const double nodes = double(d.geometry.nodeCount());
    const double bw = cuda::deviceCopyBandwidth(size_t(512) << 20, 10);
    std::printf("\nLB %d^3 RGB, leaf preset, %d steps (median of %d)\n", grid, lb::defaultSteps(d.geometry.dims), reps);
    std::printf("%-28s %10s %12s %14s %12s\n", "", "seconds", "ms/step", "Gcell-upd/s", "GB/s");
    double gpu32 = 0, gpu16 = 0, cpu32 = 0;
    for (bool half : {false, true}) {
        p.storage = half ? lb::Storage::Fp16 : lb::Storage::Fp32;
        lb::SolveStats st;
        cuda::solveLightingCuda(d, p, nullptr, &st);   // warm-up
        const double t = median(reps, [&] { cuda::solveLightingCuda(d, p, nullptr, &st); });
        const double updates = nodes * 3.0 * st.steps / t;
        std::printf("%-28s %10.4f %12.3f %14.2f %12.1f\n", half ? "GPU fp16" : "GPU fp32", t, 1e3 * t / st.steps, updates / 1e9,
                    st.bytesPerStep * st.steps / t / 1e9);
        (half ? gpu16 : gpu32) = t;
    }
    std::printf("%-28s %10s %12s %14s %12.1f\n", "device copy (read+write)", "", "", "", bw / 1e9);
    if (cpu) {
        p.storage = lb::Storage::Fp32;
        lb::SolveStats st;
        cpu32 = median(1, [&] { lb::solveLighting(d, p, nullptr, &st); });
        std::printf("%-28s %10.4f %12.3f\n", "CPU fp32", cpu32, 1e3 * cpu32 / st.steps);
    }

    // Frame: the default forest, 896x448, 1 spp, shadows.
    Scene scene = defaultScene();
    GridCache cache;
    const std::vector<SpeciesAssets> assets = loadSpeciesAssets(scene, &cache, true);
    const RenderScene rs = buildRenderScene(scene, assets, sunRadiance(scene.sun));
    const cuda::DeviceScene ds(rs);
    cuda::renderCuda(ds);   // warm-up
    const double frameGpu = median(std::max(reps, 5), [&] { cuda::renderCuda(ds); });
    double frameCpu = 0;
    if (cpu) frameCpu = median(1, [&] { renderFilm(rs.view()); });
    std::printf("\ndefault forest 896x448 1 spp: GPU %.4f s, CPU %.4f s (ratio %.1fx); scene on device %.1f MB\n", frameGpu,
                frameCpu, frameCpu > 0 ? frameCpu / frameGpu : 0.0, double(ds.deviceBytes()) / 1e6);
    std::printf("\ndevice=%s\nlb_gpu_fp32_s=%.4f\nlb_gpu_fp16_s=%.4f\nlb_cpu_fp32_s=%.4f\ncopy_bandwidth_gbs=%.1f\n"
                "frame_gpu_s=%.5f\nframe_cpu_s=%.4f\n",
                q.devices[0].name.c_str(), gpu32, gpu16, cpu32, bw / 1e9, frameGpu, frameCpu);
#endif
    return 0;
}
