// GPU benchmark: the LB solve at 128^3 RGB against the device's copy bandwidth, the default forest
// frame, and the studio viewport's CUDA-GL interop frame at 1280x720 (headless EGL), each side by side
// with the CPU path in the same run. Without a device it says so and exits 0.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

#include "core/lb/lb_solver.h"
#include "core/render/render_cpu.h"
#include "core/render/tonemap.h"
#include "cuda/device_query.h"
#include "pipeline/cache/grid_cache.h"
#include "pipeline/render/frame_build.h"
#include "pipeline/render/render_job.h"
#include "pipeline/render/view_frame.h"
#include "tests/bench/bench_timing.h"
#include "tests/gpu/egl_context.h"
#if SYLVA_HAVE_CUDA
#include "cuda/gl_interop.h"
#include "cuda/lb_cuda.h"
#include "cuda/render_cuda.h"
#endif

using namespace sylva;

namespace {

using bench::now;

template <class F>
double median(int reps, F&& f)
{
    return bench::timeReps(reps, f).median;
}

// A 128^3 crown-like grid: an ellipsoid of medium with random holes (as bench_lb's synthetic crown).
[[maybe_unused]] DensityGrid crown(int n)
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
    int grid = 128, reps = 3, frames = 200, vw = 1280, vh = 720;
    bool cpu = true, lb = true;
    for (int a = 1; a < argc; ++a) {
        if (!std::strcmp(argv[a], "--grid") && a + 1 < argc) grid = std::atoi(argv[++a]);
        else if (!std::strcmp(argv[a], "--reps") && a + 1 < argc) reps = std::atoi(argv[++a]);
        else if (!std::strcmp(argv[a], "--no-cpu")) cpu = false;
        else if (!std::strcmp(argv[a], "--no-lb")) lb = false;
        else if (!std::strcmp(argv[a], "--frames") && a + 1 < argc) frames = std::max(1, std::atoi(argv[++a]));
        else if (!std::strcmp(argv[a], "--viewport") && a + 2 < argc) {
            vw = std::atoi(argv[++a]);
            vh = std::atoi(argv[++a]);
        } else {
            std::printf("usage: bench_gpu [--grid N] [--reps N] [--frames N] [--viewport W H] [--no-cpu] [--no-lb]\n");
            return 2;
        }
    }
    const cuda::DeviceQuery q = cuda::queryDevices();
    if (q.devices.empty()) {
        std::printf("bench_gpu: no CUDA device (%s); nothing to measure\ndevice=none\n",
                    q.built ? q.message.c_str() : "this build has no CUDA backend");
        return 0;
    }
#if !SYLVA_HAVE_CUDA
    (void)grid, (void)reps, (void)frames, (void)vw, (void)vh, (void)cpu, (void)lb;
#endif
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
        if (!lb) break;
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
    if (cpu && lb) {
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

    // Viewport: what the studio does per frame on a GPU (Viewport::paintGpu): re-place the frame at the
    // camera (host: instances and instance BVH; device: their upload), trace and tone-map into the GL
    // pixel buffer, copy it into the texture, put it on the surface (a framebuffer blit), glFinish.
    double vpMoving = 0, vpStill = 0, vpPlace = 0, vpCpu = 0;
    test::EglContext gl(vw, vh);
    if (!gl.ok()) {
        std::printf("\nviewport: no OpenGL on the device (%s); not measured\n", gl.why().c_str());
    } else {
        const glm::vec3 sun = sunRadiance(scene.sun);
        ViewFrame f = buildViewFrame(scene, assets, sun);
        placeViewFrame(f, scene, sun, vw, vh, 1);
        cuda::DeviceScene dv(f.rs);
        GLuint pbo = 0, tex = 0, fbo = 0;
        glGenBuffers(1, &pbo);
        glBindBuffer(GL_PIXEL_UNPACK_BUFFER, pbo);
        glBufferData(GL_PIXEL_UNPACK_BUFFER, GLsizeiptr(vw) * vh * 4, nullptr, GL_STREAM_DRAW);
        glBindBuffer(GL_PIXEL_UNPACK_BUFFER, 0);
        glGenTextures(1, &tex);
        glBindTexture(GL_TEXTURE_2D, tex);
        glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA8, vw, vh, 0, GL_RGBA, GL_UNSIGNED_BYTE, nullptr);
        glGenFramebuffers(1, &fbo);
        glBindFramebuffer(GL_READ_FRAMEBUFFER, fbo);
        glFramebufferTexture2D(GL_READ_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, tex, 0);
        cuda::GlInterop interop;
        interop.setPixelBuffer(pbo, vw, vh);
        Scene moving = scene;
        const glm::dvec3 target = scene.camera.target, eye = scene.camera.position;
        std::vector<double> tMoving, tStill, tPlace;
        auto frame = [&](int i, bool move) {
            const double t0 = now();
            if (move) {
                // orbit the target by a quarter degree per frame
                const double a = 0.25 * i * 3.14159265358979 / 180.0, c = std::cos(a), s = std::sin(a);
                const glm::dvec3 off = eye - target;
                moving.camera.position = target + glm::dvec3(c * off.x + s * off.z, off.y, -s * off.x + c * off.z);
                placeViewFrame(f, moving, sun, vw, vh, 1);
                dv.place(f.rs);
                tPlace.push_back(now() - t0);
            }
            interop.render(dv, RenderMode::Full, scene.render.exposureKey);
            glBindBuffer(GL_PIXEL_UNPACK_BUFFER, pbo);
            glBindTexture(GL_TEXTURE_2D, tex);
            glTexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, vw, vh, GL_RGBA, GL_UNSIGNED_BYTE, nullptr);
            glBindBuffer(GL_PIXEL_UNPACK_BUFFER, 0);
            glBindFramebuffer(GL_DRAW_FRAMEBUFFER, 0);
            glBlitFramebuffer(0, 0, vw, vh, 0, 0, vw, vh, GL_COLOR_BUFFER_BIT, GL_NEAREST);
            glFinish();
            (move ? tMoving : tStill).push_back(now() - t0);
        };
        for (int i = 0; i < 10; ++i) frame(i, true);   // warm-up
        tMoving.clear();
        tPlace.clear();
        for (int i = 0; i < frames; ++i) frame(i, true);
        for (int i = 0; i < frames; ++i) frame(i, false);
        auto med = [](std::vector<double> v) {
            std::sort(v.begin(), v.end());
            return v[v.size() / 2];
        };
        vpMoving = med(tMoving);
        vpStill = med(tStill);
        vpPlace = med(tPlace);
        const GLenum err = glGetError();
        if (cpu) {
            // The CPU viewport's frame at the same size: trace, compose and tone-map on the host.
            placeViewFrame(f, scene, sun, vw, vh, 1);
            vpCpu = median(1, [&] {
                const Film film = renderFilm(f.rs.view());
                toneMapped(composeMode(film, RenderMode::Full, scene.sky), film.width, film.height, scene.render.exposureKey);
            });
        }
        std::printf("\nviewport %dx%d 1 spp, CUDA-GL interop (%s), median of %d frames:\n", vw, vh, gl.renderer().c_str(), frames);
        std::printf("  camera moving every frame: %.3f ms/frame = %.0f frames/s (host re-placement + upload %.3f ms)\n",
                    1e3 * vpMoving, 1.0 / vpMoving, 1e3 * vpPlace);
        std::printf("  camera still:              %.3f ms/frame = %.0f frames/s\n", 1e3 * vpStill, 1.0 / vpStill);
        if (cpu) std::printf("  CPU viewport frame, same size (host threads): %.3f s (GPU %.0fx faster)\n", vpCpu, vpCpu / vpMoving);
        std::printf("  GL errors: %s\n", err == GL_NO_ERROR ? "none" : "YES");
        interop.releasePixelBuffer();
        glDeleteFramebuffers(1, &fbo);
        glDeleteTextures(1, &tex);
        glDeleteBuffers(1, &pbo);
    }

    std::printf("\ndevice=%s\nlb_gpu_fp32_s=%.4f\nlb_gpu_fp16_s=%.4f\nlb_cpu_fp32_s=%.4f\ncopy_bandwidth_gbs=%.1f\n"
                "frame_gpu_s=%.5f\nframe_cpu_s=%.4f\nviewport_moving_ms=%.3f\nviewport_moving_fps=%.1f\n"
                "viewport_still_ms=%.3f\nviewport_place_ms=%.3f\nviewport_cpu_s=%.4f\n",
                q.devices[0].name.c_str(), gpu32, gpu16, cpu32, bw / 1e9, frameGpu, frameCpu, 1e3 * vpMoving,
                vpMoving > 0 ? 1.0 / vpMoving : 0.0, 1e3 * vpStill, 1e3 * vpPlace, vpCpu);
#endif
    return 0;
}
