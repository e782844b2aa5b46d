// gpu_replay: the GPU checks on a machine that has a CUDA device but none of the pipeline's libraries (Qt,
// OpenImageIO, Assimp...: the lent device machines). tst_gpu writes each bundled scene's prepared frame and its
// CPU film to a folder (SYLVA_GPU_REPLAY_DIR=DIR, bundledScenesMatchCpu; core/render/scene_bytes.h); this
// program links only the core and the CUDA backend, traces each frame on the device and compares it with the
// CPU film in every mode in linear radiance with tst_gpu's tolerance (kGpuAgainstCpu, tests/common/linear_compare.h).
// tests/gpu/device_replay.sh prepares the folder and the command.
//   gpu_replay DIR [--cpu]     --cpu: trace on the CPU instead (checks the replay itself: the same bits)
// Prints a line per frame and mode, then name=value lines; exits 1 when a frame is off or unreadable, 2 on usage.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

#include "core/base/error.h"
#include "core/render/render_cpu.h"
#include "core/render/scene_bytes.h"
#include "core/scene/scene.h"
#include "cuda/device_query.h"
#include "cuda/render_cuda.h"
#include "tests/common/linear_compare.h"

using namespace sylva;

int main(int argc, char** argv)
{
    if (argc < 2 || std::strcmp(argv[1], "--help") == 0) {
        std::printf("usage: gpu_replay DIR [--cpu]\n  traces each DIR/*.frame (written by tst_gpu with SYLVA_GPU_REPLAY_DIR=DIR) on the CUDA device\n"
                    "  and compares it with the CPU film stored beside it; --cpu traces on the CPU instead\n");
        return argc < 2 ? 2 : 0;
    }
    const bool onCpu = argc > 2 && std::strcmp(argv[2], "--cpu") == 0;
    if (!onCpu) {
        const cuda::DeviceQuery q = cuda::queryDevices();
        if (!q.built || q.devices.empty()) {
            std::fprintf(stderr, "gpu_replay: no CUDA device: %s\n", q.built ? q.message.c_str() : "this build has no CUDA backend");
            return 1;
        }
        std::printf("device: %s (sm_%d%d)\n", q.devices[0].name.c_str(), q.devices[0].computeMajor, q.devices[0].computeMinor);
    }
    std::vector<std::filesystem::path> frames;
    std::error_code ec;
    for (const auto& e : std::filesystem::directory_iterator(argv[1], ec))
        if (e.path().extension() == ".frame") frames.push_back(e.path());
    std::sort(frames.begin(), frames.end());
    if (ec || frames.empty()) {
        std::fprintf(stderr, "gpu_replay: no .frame files in %s\n", argv[1]);
        return 1;
    }
    int failed = 0;
    for (const auto& path : frames) {
        try {
            RenderScene rs;
            Film cpu;
            glm::vec3 sky(0.0f);
            readRenderSceneFile(path.string(), rs, cpu, sky);
            const auto t0 = std::chrono::steady_clock::now();
            const Film other = onCpu ? renderFilm(rs.view()) : cuda::renderCuda(cuda::DeviceScene(rs));
            const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
            if (other.width != cpu.width || other.height != cpu.height) throw Error("the film's size differs");
            const bool sameBits = std::memcmp(other.pixels.data(), cpu.pixels.data(), cpu.pixels.size() * sizeof(SampleParts)) == 0;
            const std::string name = path.stem().string();
            bool ok = !onCpu || sameBits;
            for (RenderMode m : {RenderMode::Full, RenderMode::Local, RenderMode::Ambient, RenderMode::Lb}) {
                const test::LinearComparison c = test::compareLinear(composeMode(other, m, sky), composeMode(cpu, m, sky), test::kGpuAgainstCpu);
                ok = ok && c.pass;
                std::printf("%s %s: %s (%.3f s, %s)\n", name.c_str(), renderModeName(m), c.summary.c_str(), seconds,
                            sameBits ? "the same bits" : "bits differ");
                std::printf("%s_%s_values_off=%zu\n%s_%s_mean_error=%.3g\n", name.c_str(), renderModeName(m), c.off, name.c_str(),
                            renderModeName(m), c.meanError);
            }
            if (!ok) ++failed;
            std::printf("%s_ok=%d\n", name.c_str(), ok ? 1 : 0);
        } catch (const std::exception& e) {
            std::fprintf(stderr, "gpu_replay: %s: %s\n", path.string().c_str(), e.what());
            ++failed;
        }
    }
    std::printf("frames=%zu\nframes_failed=%d\n", frames.size(), failed);
    return failed ? 1 : 0;
}
