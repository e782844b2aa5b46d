// What the machine can still give: the memory checks of the LB solver and the render job use it.
#pragma once

namespace sylva {

// MemAvailable from /proc/meminfo in bytes; 0 when unknown (the callers then skip their check). The
// environment variable SYLVA_MEMORY_LIMIT_MB caps it (a machine shared with other work; the tests).
double availableMemoryBytes();

} // namespace sylva
