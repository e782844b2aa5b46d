// MemAvailable from /proc/meminfo, capped by SYLVA_MEMORY_LIMIT_MB.
#include "core/base/memory.h"

#include <algorithm>
#include <cstdio>
#include <cstdlib>

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
    double bytes = kb * 1024.0;
    if (const char* limit = std::getenv("SYLVA_MEMORY_LIMIT_MB")) {
        char* end = nullptr;
        const double mb = std::strtod(limit, &end);
        if (end != limit && mb > 0.0) bytes = bytes > 0.0 ? std::min(bytes, mb * 1e6) : mb * 1e6;
    }
    return bytes;
}

} // namespace sylva
