// Benchmark: exporting a 256^3 lighting grid as .vdb (OpenVDB: the vec3 grid and the three channel
// grids, blosc-compressed by OpenVDB's defaults) against .npy (raw float32 + sidecar), side by side in
// one run: write time, file size, read-back time. Also the .vdb `sylva light -o` writes (lighting with
// the density and wood fraction). Usage: bench_vdb [N] [REPEATS] (default 256, 5).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <random>
#include <string>
#include <vector>

#include <tbb/info.h>
#include <unistd.h>

#include "pipeline/io/grid_file.h"

using namespace sylva;
namespace fs = std::filesystem;

namespace {

using Clock = std::chrono::steady_clock;

double median(std::vector<double> v)
{
    std::sort(v.begin(), v.end());
    return v.size() % 2 ? v[v.size() / 2] : 0.5 * (v[v.size() / 2 - 1] + v[v.size() / 2]);
}

template <class F>
double timed(F&& f)
{
    const Clock::time_point a = Clock::now();
    f();
    return std::chrono::duration<double>(Clock::now() - a).count();
}

// A crown-like medium: 60 random soft balls of leaves (density up to 1) in the middle of the grid,
// zero outside (about the share of empty space a voxelized tree has).
DensityGrid syntheticDensity(int n)
{
    DensityGrid d;
    d.geometry.dims = {n, n, n};
    d.geometry.origin = {-5.0, 0.0, -5.0};
    d.geometry.spacing = 10.0 / (n - 1);
    d.density.assign(d.geometry.nodeCount(), 0.0f);
    d.woodFraction.assign(d.geometry.nodeCount(), 0.0f);
    std::mt19937 rng(5);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    for (int b = 0; b < 60; ++b) {
        const glm::vec3 c(n * (0.25f + 0.5f * u(rng)), n * (0.3f + 0.5f * u(rng)), n * (0.25f + 0.5f * u(rng)));
        const float r = n * (0.05f + 0.08f * u(rng));
        const float peak = 0.3f + 0.7f * u(rng);
        const int lo[3] = {std::max(0, int(c.x - r)), std::max(0, int(c.y - r)), std::max(0, int(c.z - r))};
        const int hi[3] = {std::min(n - 1, int(c.x + r)), std::min(n - 1, int(c.y + r)), std::min(n - 1, int(c.z + r))};
        for (int i = lo[0]; i <= hi[0]; ++i)
            for (int j = lo[1]; j <= hi[1]; ++j)
                for (int k = lo[2]; k <= hi[2]; ++k) {
                    const float q = glm::length(glm::vec3(i, j, k) - c) / r;
                    if (q >= 1.0f) continue;
                    float& v = d.density[d.geometry.index(i, j, k)];
                    v = std::min(1.0f, v + peak * (1.0f - q * q));
                    if (q < 0.2f) d.woodFraction[d.geometry.index(i, j, k)] = 0.5f;
                }
    }
    return d;
}

// Light from a sun at +y attenuated through the medium (Beer-Lambert per channel) plus a sky term
// that falls off with the depth below the top: smooth everywhere, non-zero everywhere, like an LB grid.
LightingGrid syntheticLighting(const DensityGrid& d)
{
    LightingGrid l;
    l.geometry = d.geometry;
    const glm::ivec3 n = d.geometry.dims;
    l.rgb.assign(d.geometry.nodeCount() * 3, 0.0f);
    const float sigma[3] = {0.09f, 0.05f, 0.11f};
    for (int i = 0; i < n.x; ++i)
        for (int k = 0; k < n.z; ++k) {
            float tau[3] = {0, 0, 0};
            for (int j = n.y - 1; j >= 0; --j) {
                const size_t idx = d.geometry.index(i, j, k);
                for (int c = 0; c < 3; ++c) {
                    tau[c] += sigma[c] * d.density[idx];
                    l.rgb[idx * 3 + size_t(c)] = std::exp(-tau[c]) + 0.15f * std::exp(-0.3f * tau[c]) * float(j + 1) / float(n.y);
                }
            }
        }
    return l;
}

} // namespace

int main(int argc, char** argv)
{
    const int n = argc > 1 ? std::atoi(argv[1]) : 256;
    const int repeats = argc > 2 ? std::atoi(argv[2]) : 5;
    if (n < 3 || repeats < 1) {
        std::fprintf(stderr, "usage: bench_vdb [N >= 3] [REPEATS >= 1]\n");
        return 2;
    }
    const fs::path dir = fs::temp_directory_path() / ("sylva_bench_vdb_" + std::to_string(::getpid()));
    fs::create_directories(dir);
    const DensityGrid density = syntheticDensity(n);
    const LightingGrid lighting = syntheticLighting(density);
    size_t occupied = 0;
    for (float v : density.density) occupied += v > 0.0f;
    std::printf("lighting grid %d^3 (%.1f MiB of RGB float32), %.1f%% of nodes in the medium, %d threads, %d repeats\n", n,
                double(lighting.rgb.size() * sizeof(float)) / (1 << 20), 100.0 * double(occupied) / double(density.density.size()),
                tbb::info::default_concurrency(), repeats);

    struct Case {
        const char* name;
        std::string path;
        bool withDensity;
        std::vector<double> write, read;
        double bytes = 0;
    };
    Case cases[] = {{"npy", (dir / "light.npy").string(), false, {}, {}},
                    {"vdb", (dir / "light.vdb").string(), false, {}, {}},
                    {"vdb_with_density", (dir / "light_density.vdb").string(), true, {}, {}}};
    const std::string params = R"({"preset":"leaf","sun":[0,1,0],"steps":512})";
    bool exact = true;
    for (int r = 0; r < repeats; ++r)
        for (Case& c : cases) {   // interleaved, so drift in the machine's load hits every case alike
            c.write.push_back(timed([&] { writeLightingFile(c.path, lighting, params, c.withDensity ? &density : nullptr); }));
            LightingGrid back;
            c.read.push_back(timed([&] { back = readLightingFile(c.path); }));
            exact = exact && back.geometry == lighting.geometry &&
                    std::memcmp(back.rgb.data(), lighting.rgb.data(), lighting.rgb.size() * sizeof(float)) == 0;
            c.bytes = 0;
            for (const std::string& f : lightingFilesFor(c.path)) c.bytes += double(fs::file_size(f));
        }
    std::printf("\n%-18s %12s %12s %12s\n", "", "write s", "read s", "MiB");
    for (const Case& c : cases)
        std::printf("%-18s %12.3f %12.3f %12.1f\n", c.name, median(c.write), median(c.read), c.bytes / (1 << 20));
    std::printf("(medians; read back equal to the bit: %s)\n\n", exact ? "yes" : "NO");
    for (const Case& c : cases) {
        std::printf("%s_write_s=%.4f\n%s_read_s=%.4f\n%s_bytes=%.0f\n", c.name, median(c.write), c.name, median(c.read), c.name, c.bytes);
    }
    std::printf("vdb_over_npy_write=%.3f\nvdb_over_npy_bytes=%.3f\nexact=%d\n", median(cases[1].write) / median(cases[0].write),
                cases[1].bytes / cases[0].bytes, exact ? 1 : 0);
    fs::remove_all(dir);
    return exact ? 0 : 1;
}
