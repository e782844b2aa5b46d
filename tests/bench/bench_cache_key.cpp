// Cache key of a 256^3 density grid (density + wood fraction, 128 MiB): the key the cache uses now
// (densityHash: XXH3-128 over the arrays, pipeline/lighting_job) beside the one it used before
// (SHA-256 through QCryptographicHash over the same bytes), in one run, medians of several runs.
// Target: <= 50 ms. Ends with name=value lines.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <vector>

#include <QCryptographicHash>

#include "pipeline/cache/grid_cache.h"
#include "pipeline/lighting_job.h"

using namespace sylva;
using Clock = std::chrono::steady_clock;

namespace {

double median(std::vector<double> v)
{
    std::sort(v.begin(), v.end());
    return v[v.size() / 2];
}

template <typename F>
std::vector<double> timeRuns(int runs, F&& f)
{
    std::vector<double> ms;
    for (int r = 0; r < runs; ++r) {
        const auto t0 = Clock::now();
        f();
        ms.push_back(std::chrono::duration<double, std::milli>(Clock::now() - t0).count());
    }
    return ms;
}

// The version 1 key of the same grid: SHA-256 of each array, then SHA-256 of the fields (as CacheKey did).
QByteArray sha256Key(const DensityGrid& g)
{
    QCryptographicHash fields(QCryptographicHash::Sha256);
    for (const std::vector<float>* a : {&g.density, &g.woodFraction})
        fields.addData(QCryptographicHash::hash(QByteArrayView(reinterpret_cast<const char*>(a->data()), qsizetype(a->size() * 4)),
                                                QCryptographicHash::Sha256));
    return fields.result();
}

} // namespace

int main(int argc, char** argv)
{
    const int edge = argc > 1 ? std::atoi(argv[1]) : 256;
    DensityGrid g;
    g.geometry.dims = glm::ivec3(edge);
    g.geometry.spacing = 0.05;
    const size_t n = g.geometry.nodeCount();
    g.density.resize(n);
    g.woodFraction.resize(n);
    uint32_t s = 1;
    for (size_t i = 0; i < n; ++i) {
        s = s * 1664525u + 1013904223u;
        g.density[i] = float(s >> 8) * (1.0f / 16777216.0f);
        g.woodFraction[i] = (s & 0xff) < 20 ? 1.0f : 0.0f;
    }
    const double mib = double(n) * 2 * 4 / (1024.0 * 1024.0);

    std::string key;
    densityHash(g);   // warm: pages touched, code loaded
    const std::vector<double> xxh = timeRuns(7, [&] { key = densityHash(g); });
    QByteArray old;
    const std::vector<double> sha = timeRuns(3, [&] { old = sha256Key(g); });
    // The checksum of a 256^3 lighting entry's payload (3 floats a node), XXH3-64.
    const std::vector<float> rgb(n * 3, 0.5f);
    uint64_t sum = 0;
    const std::vector<double> check = timeRuns(5, [&] { sum ^= xxh3(rgb.data(), rgb.size() * 4); });

    const double tX = median(xxh), tS = median(sha), tC = median(check);
    std::printf("density grid %d^3: %.0f MiB (density + wood fraction)\n", edge, mib);
    std::printf("%-40s %10s %10s %10s\n", "", "median ms", "min ms", "MiB/s");
    std::printf("%-40s %10.1f %10.1f %10.0f\n", "key, XXH3-128 (densityHash, now)", tX, *std::min_element(xxh.begin(), xxh.end()), mib / tX * 1e3);
    std::printf("%-40s %10.1f %10.1f %10.0f\n", "key, SHA-256 via Qt (format 1)", tS, *std::min_element(sha.begin(), sha.end()), mib / tS * 1e3);
    std::printf("%-40s %10.1f %10.1f %10.0f\n", "checksum, XXH3-64 of a lighting payload", tC, *std::min_element(check.begin(), check.end()),
                double(n) * 12 / (1024.0 * 1024.0) / tC * 1e3);
    std::printf("key %s (sha-256 %s), checksum %016llx\n\n", key.c_str(), old.toHex().left(16).constData(), (unsigned long long)sum);

    std::printf("grid=%d\n", edge);
    std::printf("key_xxh3_ms=%.2f\n", tX);
    std::printf("key_sha256_ms=%.2f\n", tS);
    std::printf("speedup=%.1f\n", tS / tX);
    std::printf("checksum_lighting_xxh3_ms=%.2f\n", tC);
    std::printf("target_ms=50\n");
    std::printf("within_target=%d\n", tX <= 50.0 ? 1 : 0);
    return 0;
}
