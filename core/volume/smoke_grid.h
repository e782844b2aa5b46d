// What the files of the smoke simulation share. SmokeSim (smoke.h) is split by job: smoke.cpp the settings
// and the set-up, smoke_step.cpp the step's phases, smoke_advect.cpp the semi-Lagrangian advection,
// smoke_interp.cpp the monotonic cubic interpolation, smoke_pressure.cpp the projection and
// smoke_multigrid.cpp its pressure solver. Loops over x slabs run with HostExec::forEachRow (a slab of
// cells a row), sums with HostExec::sumRows (the slabs' sums added in slab order), so the bits do not
// depend on the thread count.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "core/base/number_text.h"
#include "core/base/parallel.h"

namespace sylva::volume::smoke_detail {

// The MAC grid of n cells: the index of a cell and of a u, v, w face, z fastest.
struct Dims {
    glm::ivec3 n;
    size_t cell(int i, int j, int k) const { return (size_t(i) * size_t(n.y) + size_t(j)) * size_t(n.z) + size_t(k); }
    size_t uIdx(int i, int j, int k) const { return (size_t(i) * size_t(n.y) + size_t(j)) * size_t(n.z) + size_t(k); }
    size_t vIdx(int i, int j, int k) const { return (size_t(i) * size_t(n.y + 1) + size_t(j)) * size_t(n.z) + size_t(k); }
    size_t wIdx(int i, int j, int k) const { return (size_t(i) * size_t(n.y) + size_t(j)) * size_t(n.z + 1) + size_t(k); }
    size_t slabCells() const { return size_t(n.y) * size_t(n.z); }   // cells of an x slab (its forEachRow length)
};

// body(i, j, k, c) for every fluid cell c = d.cell(i, j, k) (solid[c] == 0), the x slabs in parallel; the
// bodies write disjoint cells.
template <class Body>
void forFluidCells(const Dims& d, const std::vector<uint8_t>& solid, const Body& body)
{
    HostExec().forEachRow(size_t(d.n.x), d.slabCells(), [&](size_t slab, size_t, size_t) {
        const int i = int(slab);
        for (int j = 0; j < d.n.y; ++j)
            for (int k = 0; k < d.n.z; ++k) {
                const size_t c = d.cell(i, j, k);
                if (!solid[c]) body(i, j, k, c);
            }
    });
}

} // namespace sylva::volume::smoke_detail
