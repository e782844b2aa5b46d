// core/base/parallel.h: pipelineSlabs' temporally blocked stages against stage-by-stage passes, at every
// slab count and stage count around the chunking's edges and for several thread counts; HostExec's rows
// (forEachRow covers every item once, sumRows adds the rows in row order on any thread count).
#include <QTest>

#include <atomic>
#include <cstdint>
#include <cstring>
#include <random>
#include <vector>

#include <tbb/global_control.h>
#include <tbb/task_arena.h>

#include "core/base/parallel.h"

using namespace sylva;

namespace {

// A small grid of n slabs with the smoke V-cycle's kinds of stage: stage 0 writes every cell of its slab from
// b alone, then red-black Gauss-Seidel sweeps in place (stage s updates colour s % 2 from the other colour's
// six neighbours), and the last stage writes a residual into another array from x's neighbours.
struct Grid {
    int n, ny = 5, nz = 7;
    std::vector<float> x, b, res;
    explicit Grid(int slabs) : n(slabs)
    {
        const size_t cells = size_t(n) * size_t(ny) * size_t(nz);
        x.assign(cells, -1.0f);   // what stage 0 overwrites
        b.resize(cells);
        res.assign(cells, 0.0f);
        std::mt19937 rng(uint32_t(1000 + slabs));
        std::uniform_real_distribution<float> u(-1.0f, 1.0f);
        for (float& v : b) v = u(rng);
    }
    size_t at(int i, int j, int k) const { return (size_t(i) * size_t(ny) + size_t(j)) * size_t(nz) + size_t(k); }
    float xs(int i, int j, int k) const
    {
        return i < 0 || i >= n || j < 0 || j >= ny || k < 0 || k >= nz ? 0.0f : x[at(i, j, k)];
    }
    float neighbours(int i, int j, int k) const
    {
        return xs(i - 1, j, k) + xs(i + 1, j, k) + xs(i, j - 1, k) + xs(i, j + 1, k) + xs(i, j, k - 1) + xs(i, j, k + 1);
    }
    void stage(int s, int stages, int i)
    {
        for (int j = 0; j < ny; ++j)
            for (int k = 0; k < nz; ++k) {
                const size_t c = at(i, j, k);
                if (s == 0) x[c] = ((i + j + k) & 1) ? 0.0f : 0.5f * b[c];
                else if (s == stages - 1 && stages > 2) res[c] = b[c] - (6.0f * x[c] - neighbours(i, j, k));
                else if (((i + j + k) & 1) == (s & 1)) x[c] = (b[c] + neighbours(i, j, k)) / 6.5f;
            }
    }
};

bool sameBits(const std::vector<float>& a, const std::vector<float>& b)
{
    return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(float)) == 0;
}

} // namespace

class TestParallel : public QObject {
    Q_OBJECT
    // Arenas of more threads than this machine's cores really run that many (oversubscribed).
    tbb::global_control m_threads{tbb::global_control::max_allowed_parallelism, 8};
private Q_SLOTS:
    // The pipelined result has the bits of stage-by-stage passes, for any thread count.
    void pipelineMatchesStageByStage()
    {
        int cases = 0;
        for (int threads : {1, 2, 3, 8}) {
            tbb::task_arena arena(threads);
            for (int n : {1, 2, 3, 5, 8, 9, 15, 16, 17, 31, 40, 64, 100})
                for (int stages : {1, 2, 3, 5, 8, 13}) {
                    Grid ref(n), got(n);
                    for (int s = 0; s < stages; ++s)
                        for (int i = 0; i < n; ++i) ref.stage(s, stages, i);
                    arena.execute([&] { pipelineSlabs(n, stages, [&](int s, int i) { got.stage(s, stages, i); }); });
                    QVERIFY2(sameBits(ref.x, got.x) && sameBits(ref.res, got.res),
                             qPrintable(QString("%1 slabs, %2 stages, %3 threads").arg(n).arg(stages).arg(threads)));
                    ++cases;
                }
        }
        QCOMPARE(cases, 4 * 13 * 6);
    }

    // The schedule itself: every (stage, slab) runs once, and only after every earlier stage on the slabs
    // beside it (what the contract lets a stage read, and what may read what it overwrites).
    void everyStageAfterItsNeighbours()
    {
        for (int threads : {1, 2, 5}) {
            tbb::task_arena arena(threads);
            for (int n : {1, 4, 10, 11, 33, 128})
                for (int stages : {1, 2, 5, 9}) {
                    std::vector<std::atomic<int>> runs(size_t(n) * size_t(stages));
                    for (auto& r : runs) r = 0;
                    std::atomic<int> early{0};
                    arena.execute([&] {
                        pipelineSlabs(n, stages, [&](int s, int i) {
                            for (int before = 0; before < s; ++before)
                                for (int j = std::max(0, i - 1); j <= std::min(n - 1, i + 1); ++j)
                                    if (runs[size_t(before) * size_t(n) + size_t(j)].load() != 1) ++early;
                            ++runs[size_t(s) * size_t(n) + size_t(i)];
                        });
                    });
                    QVERIFY2(early.load() == 0, qPrintable(QString("%1 slabs, %2 stages, %3 threads: %4 stages ran before a neighbour's earlier one")
                                                               .arg(n).arg(stages).arg(threads).arg(early.load())));
                    for (size_t r = 0; r < runs.size(); ++r)
                        QVERIFY2(runs[r].load() == 1, qPrintable(QString("%1 slabs, %2 stages: stage %3 slab %4 ran %5 times")
                                                                     .arg(n).arg(stages).arg(r / size_t(n)).arg(r % size_t(n)).arg(runs[r].load())));
                }
        }
    }

    // forEachRow hands every item of every row exactly once, whole rows on the host, for rows shorter and
    // longer than a task's items; sumRows has the bits of the rows' sums added in order, on any thread count.
    void rowsCoverEveryItemAndSumInOrder()
    {
        for (int threads : {1, 2, 7}) {
            tbb::task_arena arena(threads);
            for (size_t len : {size_t(1), size_t(3), size_t(1000), HostExec::kChunk + 5})
                for (size_t rows : {size_t(0), size_t(1), size_t(17), size_t(300)}) {
                    std::vector<std::atomic<int>> seen(rows * len);
                    for (auto& v : seen) v = 0;
                    std::atomic<int> partial{0};
                    arena.execute([&] {
                        HostExec().forEachRow(rows, len, [&](size_t r, size_t k0, size_t k1) {
                            if (k0 != 0 || k1 != len) ++partial;
                            for (size_t k = k0; k < k1; ++k) ++seen[r * len + k];
                        });
                    });
                    QCOMPARE(partial.load(), 0);
                    for (const auto& v : seen) QCOMPARE(v.load(), 1);
                    auto term = [](size_t r, size_t k) { return 1.0 / double(3 + r * 7 + k) - 1e-3 * double(k % 5); };
                    double ref[2] = {0.0, 0.0};
                    for (size_t r = 0; r < rows; ++r) {
                        double row[2] = {0.0, 0.0};
                        for (size_t k = 0; k < len; ++k) row[0] += term(r, k), row[1] += term(r, k) * term(r, k);
                        ref[0] += row[0];
                        ref[1] += row[1];
                    }
                    double got[2] = {-1.0, -1.0};
                    arena.execute([&] {
                        HostExec().sumRows<2>(rows, len, [&](size_t r, size_t k0, size_t k1, double* t) {
                            for (size_t k = k0; k < k1; ++k) t[0] += term(r, k), t[1] += term(r, k) * term(r, k);
                        }, got);
                    });
                    QVERIFY2(std::memcmp(ref, got, sizeof ref) == 0,
                             qPrintable(QString("%1 rows of %2, %3 threads").arg(rows).arg(len).arg(threads)));
                }
        }
    }
};

QTEST_APPLESS_MAIN(TestParallel)
#include "tst_parallel.moc"
