// MemAvailable from /proc/meminfo.
#include "core/base/memory.h"

#include <cstdio>

namespace sylva {

double availableMemoryBytes()
{
    std::FILE* f = std::fopen("/proc/meminfo", "r");
    if (!f) return 0.0;
    char line[256];
    double kb = 0.0;
    while (std::fgets(line, sizeof line, f))
        if (std::sscanf(line, "MemAvailable: %lf kB", &kb) == 1) break;
    std::fclose(f);
    return kb * 1024.0;
}

} // namespace sylva
