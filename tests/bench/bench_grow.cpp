// Benchmark of the tree grower and OBJ writer: median grow time per species and budget, OBJ write time.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include "core/base/error.h"
#include "pipeline/grow/obj_writer.h"
#include "pipeline/grow/tree_grower.h"

using namespace sylva;
namespace fs = std::filesystem;

namespace {

double seconds(std::chrono::steady_clock::time_point a, std::chrono::steady_clock::time_point b)
{
    return std::chrono::duration<double>(b - a).count();
}

double median(std::vector<double> v)
{
    std::sort(v.begin(), v.end());
    const size_t n = v.size();
    return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

} // namespace

int main(int argc, char** argv)
{
    // usage: bench_grow [OUTPUT_FOLDER] [REPEATS]
    const fs::path out = argc > 1 ? fs::path(argv[1]) : fs::temp_directory_path() / "sylva_bench_grow";
    const int repeats = argc > 2 ? std::max(1, std::atoi(argv[2])) : 5;
    std::vector<std::pair<std::string, double>> results;
    try {
        fs::create_directories(out);
        std::printf("tree grower: median of %d runs per row; output in %s\n", repeats, out.string().c_str());
        std::printf("%-10s %9s %10s %12s %10s\n", "species", "target", "triangles", "median_s", "s_per_100k");
        for (const std::string& name : speciesNames()) {
            for (size_t target : {size_t(100000), size_t(500000)}) {
                GrowOptions o;
                o.species = speciesFromName(name);
                o.targetTriangles = target;
                o.seed = 1;
                std::vector<double> times;
                size_t triangles = 0;
                for (int r = 0; r < repeats; ++r) {
                    const auto t0 = std::chrono::steady_clock::now();
                    const GrownTree tree = growTree(o);
                    const auto t1 = std::chrono::steady_clock::now();
                    times.push_back(seconds(t0, t1));
                    triangles = tree.mesh.triangleCount();
                }
                const double med = median(times);
                const double per100k = med / (double(triangles) / 100000.0);
                std::printf("%-10s %9zu %10zu %12.4f %10.4f\n", name.c_str(), target, triangles, med, per100k);
                const std::string key = "grow_" + name + "_" + std::to_string(target / 1000) + "k";
                results.push_back({key + "_s", med});
                results.push_back({key + "_per100k_s", per100k});
            }
        }

        std::printf("\nOBJ write (mesh + MTL + 2 PNG), median of %d runs\n", repeats);
        std::printf("%-10s %10s %12s %10s\n", "species", "triangles", "median_s", "MB");
        for (const std::pair<TreeSpecies, size_t>& job :
             {std::pair{TreeSpecies::Broadleaf, size_t(100000)}, std::pair{TreeSpecies::Broadleaf, size_t(1000000)},
              std::pair{TreeSpecies::Conifer, size_t(1000000)}}) {
            GrowOptions o;
            o.species = job.first;
            o.targetTriangles = job.second;
            const GrownTree tree = growTree(o);
            const fs::path objPath = out / (speciesName(job.first) + "_" + std::to_string(job.second / 1000) + "k.obj");
            std::vector<double> times;
            for (int r = 0; r < repeats; ++r) {
                const auto t0 = std::chrono::steady_clock::now();
                writeObj(objPath.string(), tree);
                const auto t1 = std::chrono::steady_clock::now();
                times.push_back(seconds(t0, t1));
            }
            const double med = median(times);
            const double mb = double(fs::file_size(objPath)) / 1e6;
            std::printf("%-10s %10zu %12.4f %10.1f\n", speciesName(job.first).c_str(), tree.mesh.triangleCount(), med, mb);
            const std::string key = "write_obj_" + speciesName(job.first) + "_" + std::to_string(job.second / 1000) + "k";
            results.push_back({key + "_s", med});
            results.push_back({key + "_mb", mb});
            fs::remove(objPath);
        }
    } catch (const Error& e) {
        std::fprintf(stderr, "bench_grow: %s\n", e.what());
        return 1;
    }
    std::printf("\n");
    for (const auto& [key, value] : results) std::printf("%s=%.4f\n", key.c_str(), value);
    return 0;
}
