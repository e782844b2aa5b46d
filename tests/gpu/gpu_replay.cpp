// gpu_replay: the GPU checks on a machine that has a CUDA device but none of the pipeline's libraries (Qt,
// OpenImageIO, Assimp...: the lent device machines). tst_gpu writes each bundled scene's prepared frame and its
// CPU film to a folder (SYLVA_GPU_REPLAY_DIR=DIR, bundledScenesMatchCpu; core/render/scene_bytes.h); this
// program links only the core and the CUDA backend, traces each frame on the device and compares it with the
// CPU film in every mode with tst_gpu's tolerance (values of the tone-mapped pictures off by more than 0.1:
// at most 1 in 200). tests/gpu/device_replay.sh prepares the folder and the command.
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
#include "core/render/tonemap.h"
#include "core/scene/scene.h"
#include "cuda/device_query.h"
#include "cuda/render_cuda.h"

using namespace sylva;

namespace {

std::vector<float> toneMappedMode(const Film& f, RenderMode m, const glm::vec3& sky)
{
    std::vector<glm::vec3> lin = composeMode(f, m, sky);
    std::vector<float> out(lin.size() * 3);
    ToneMapParams p;
    p.key = 0.18f;
    toneMapToSrgb(&lin[0].x, lin.size(), out.data(), p);
    return out;
}

} // namespace

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
                const std::vector<float> a = toneMappedMode(cpu, m, sky), b = toneMappedMode(other, m, sky);
                int bad = 0;
                for (size_t i = 0; i < a.size(); ++i) bad += std::fabs(a[i] - b[i]) > 0.1f;
                const int n = int(a.size());
                ok = ok && bad <= n / 200;
                std::printf("%s %s: %d of %d values differ by more than 0.1 (%.3f s, %s)\n", name.c_str(), renderModeName(m), bad, n, seconds,
                            sameBits ? "the same bits" : "bits differ");
                std::printf("%s_%s_values_off=%d\n", name.c_str(), renderModeName(m), bad);
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
