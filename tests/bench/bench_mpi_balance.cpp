// Load balance of `sylva render --mpi` from measured tile costs: the frame's 8x8 blocks are timed one by
// one on one thread (the same renderFilmRect the ranks call), then the speedup at N ranks is simulated for
// the dynamic queue of 32x32 tiles (each rank takes the next tile when it is free; a tile traced by a rank
// other than 0 pays the per-tile message cost) and for the seed's static split (N equal parts of the
// image, Geist & Steele, "A Lighting Model for Fast Rendering of Forest Ecosystems", section 4.3: rows and, for
// comparison, columns).
//   bench_mpi_balance [SCENE.sylva.json] [--spp N] [--message-us U]   (default: the default forest)
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <functional>
#include <queue>
#include <string>
#include <vector>

#include <tbb/global_control.h>

#include "core/render/render_cpu.h"
#include "pipeline/cache/grid_cache.h"
#include "pipeline/mpi/mpi_tiles.h"
#include "pipeline/render/render_job.h"
#include "pipeline/scene/scene_file.h"
#include "tests/bench/bench_timing.h"

using namespace sylva;

namespace {

// Dynamic queue: tiles in queue order (mpi::frameTiles for `ranks`, each the sum of its 8x8 blocks), each to the rank that is free first; rank 0 pays no message.
double dynamicMakespan(const std::vector<double>& tiles, int ranks, double message)
{
    using Slot = std::pair<double, int>;   // free at, rank
    std::priority_queue<Slot, std::vector<Slot>, std::greater<Slot>> free;
    for (int r = 0; r < ranks; ++r) free.push({0.0, r});
    double end = 0.0;
    for (double c : tiles) {
        auto [t, r] = free.top();
        free.pop();
        t += c + (r == 0 ? 0.0 : message);
        end = std::max(end, t);
        free.push({t, r});
    }
    return end;
}

// Static split of a cost profile (per row or per column, summed over the other axis) into `ranks` equal
// parts; a line shared by two parts is split in proportion. Returns the largest part's cost.
double staticMakespan(const std::vector<double>& profile, int ranks)
{
    const double n = double(profile.size());
    double worst = 0.0;
    for (int r = 0; r < ranks; ++r) {
        const double a = n * r / ranks, b = n * (r + 1) / ranks;
        double sum = 0.0;
        for (size_t i = size_t(a); i < profile.size() && double(i) < b; ++i) {
            const double lo = std::max(a, double(i)), hi = std::min(b, double(i + 1));
            sum += profile[i] * std::max(0.0, hi - lo);
        }
        worst = std::max(worst, sum);
    }
    return worst;
}

} // namespace

int main(int argc, char** argv)
{
    std::string scenePath;
    int spp = 0;
    double messageUs = 250.0;   // docs/PERFORMANCE.md: a tile round trip over shared memory measured 135-226 us, plus polling
    for (int i = 1; i < argc; ++i) {
        if (!std::strcmp(argv[i], "--spp") && i + 1 < argc) spp = std::atoi(argv[++i]);
        else if (!std::strcmp(argv[i], "--message-us") && i + 1 < argc) messageUs = std::atof(argv[++i]);
        else scenePath = argv[i];
    }
    Scene scene = scenePath.empty() ? defaultScene() : readSceneFile(scenePath);
    if (spp > 0) scene.render.spp = spp;
    GridCache cache;
    RenderTimings timings;
    const RenderScene rs = prepareRenderScene(scene, &cache, nullptr, nullptr, nullptr, timings);
    const RenderView v = rs.view();
    tbb::global_control one(tbb::global_control::max_allowed_parallelism, 1);

    constexpr int kBlock = 8, kTile = 32;
    const int bx = (v.width + kBlock - 1) / kBlock, by = (v.height + kBlock - 1) / kBlock;
    std::vector<double> block(size_t(bx) * size_t(by));
    std::vector<SampleParts> buf(kBlock * kBlock);
    for (int j = 0; j < by; ++j)
        for (int i = 0; i < bx; ++i) {
            // Once each, as the frame traces it (a repeat would find the block's data in the caches and
            // time a third of the real cost); a preempted block poses as a dear one on a loaded machine.
            const double s = bench::now();
            renderFilmRect(v, i * kBlock, j * kBlock, std::min(v.width, (i + 1) * kBlock), std::min(v.height, (j + 1) * kBlock), buf.data());
            block[size_t(j) * size_t(bx) + size_t(i)] = bench::now() - s;
        }

    // 32x32 tiles in the queue's order (rows of tiles, left to right), rows and columns of the image.
    const int per = kTile / kBlock, tx = (bx + per - 1) / per, ty = (by + per - 1) / per;
    std::vector<double> tiles(size_t(tx) * size_t(ty), 0.0), rows(size_t(by), 0.0), cols(size_t(bx), 0.0);
    double sum = 0.0, maxTile = 0.0;
    for (int j = 0; j < by; ++j)
        for (int i = 0; i < bx; ++i) {
            const double c = block[size_t(j) * size_t(bx) + size_t(i)];
            tiles[size_t(j / per) * size_t(tx) + size_t(i / per)] += c;
            rows[size_t(j)] += c;
            cols[size_t(i)] += c;
            sum += c;
        }
    for (double c : tiles) maxTile = std::max(maxTile, c);
    std::printf("scene: %s, %dx%d, %d spp; %zu tiles of 32x32; the blocks sum to %.3f s on one thread (tiles: mean %.2f ms, max %.2f ms)\n",
                scenePath.empty() ? "default forest" : scenePath.c_str(), v.width, v.height, scene.render.spp, tiles.size(), sum,
                1e3 * sum / double(tiles.size()), 1e3 * maxTile);
    std::printf("per-tile message cost %.0f us\n\n", messageUs);
    std::printf("%6s %14s %14s %14s %16s\n", "ranks", "dynamic", "static rows", "static cols", "dynamic / N");
    const double message = messageUs * 1e-6;
    std::string lines;
    for (int n : {2, 4, 16, 64}) {
        std::vector<double> queue;
        for (const mpi::TileRect& t : mpi::frameTiles(v.width, 0, v.height, n, kTile)) {
            double c = 0.0;
            for (int j = t.y0 / kBlock; j * kBlock < t.y1; ++j)
                for (int i = t.x0 / kBlock; i * kBlock < t.x1; ++i) c += block[size_t(j) * size_t(bx) + size_t(i)];
            queue.push_back(c);
        }
        const double dyn = sum / dynamicMakespan(queue, n, message);
        const double rowsS = sum / staticMakespan(rows, n), colsS = sum / staticMakespan(cols, n);
        std::printf("%6d %13.2fx %13.2fx %13.2fx %16.3f\n", n, dyn, rowsS, colsS, dyn / n);
        char l[200];
        std::snprintf(l, sizeof l, "dynamic_%d=%.3f\nstatic_rows_%d=%.3f\nstatic_cols_%d=%.3f\n", n, dyn, n, rowsS, n, colsS);
        lines += l;
    }
    std::printf("\n%sframe_seconds_one_thread=%.3f\ntiles=%zu\n", lines.c_str(), sum, tiles.size());
    return 0;
}
