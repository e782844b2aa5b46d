// The pressure solve of the smoke simulation (smoke.h): A x = b for the MAC grid's Poisson operator on the
// fluid cells (the open top a pressure-0 ghost), by CG in double preconditioned by a geometric multigrid
// V-cycle in float (red-black Gauss-Seidel smoothing, temporally blocked by pipelineSlabs). The bits do
// not depend on the thread count.
#pragma once

#include <cstddef>
#include <cstdint>
#include <utility>
#include <vector>

#include <glm/glm.hpp>

namespace sylva::volume {

class PressureSolver {
public:
    // The operator of the grid of n cells whose fluid cells are 1 in `fluid` (z fastest); each fluid cell
    // must reach the open top through fluid cells (SmokeSim's flood fill sees to it).
    PressureSolver(const std::vector<uint8_t>& fluid, const glm::ivec3& n);

    // Solves A x = rhs (x holds the start), relative residual tol, at most maxIt CG iterations.
    // Returns {iterations, relative residual}.
    std::pair<int, double> solve(const std::vector<double>& rhs, std::vector<double>& x, double tol, int maxIt);

private:
    // One level of the V-cycle: the finest is the grid, each next one half its cells per axis.
    struct Level {
        glm::ivec3 n;
        std::vector<uint8_t> count;   // fluid neighbours (the open top's pressure-0 ghost counts); 0 off the fluid
        std::vector<float> x, b, tmp, zeros;
        size_t index(int i, int j, int k) const { return (size_t(i) * size_t(n.y) + size_t(j)) * size_t(n.z) + size_t(k); }
        size_t cells() const { return size_t(n.x) * size_t(n.y) * size_t(n.z); }
    };

    // Red-black sweep pairs before and after each coarse correction. Measured at 128^3 (bench_volume_sources,
    // iterations to 1e-6): 1 pair 17 CG iterations, 2 pairs 10.7, 3 pairs 9.7; 2 moves the fewest bytes.
    static constexpr int kSmoothing = 2;

    double applyDot(const double* x, double* out) const;
    static void sweepSlab(Level& l, int colour, int i);
    static void firstSweepSlab(Level& l, int i);
    static void residualSlab(Level& l, int i);
    static void prolongSlab(Level& l, const Level& c, int i);
    void vcycle(size_t li);
    static double dot(const std::vector<double>& a, const std::vector<double>& b);

    std::vector<Level> levels;
    std::vector<double> r, s, q, zeros;
};

} // namespace sylva::volume
