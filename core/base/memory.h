// What the machine can still give: the memory checks of the LB solver and the render job use it.
#pragma once

namespace sylva {

// MemAvailable from /proc/meminfo in bytes; 0 when unknown (the callers then skip their check).
double availableMemoryBytes();

} // namespace sylva
