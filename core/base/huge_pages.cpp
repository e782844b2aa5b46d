// madvise(MADV_HUGEPAGE) on the 2 MB-aligned inside of large allocations; see huge_pages.h.
#include "core/base/huge_pages.h"

#include <atomic>
#include <cstdint>
#include <cstdlib>
#include <cstring>

#if defined(__linux__)
#include <sys/mman.h>
#endif

namespace sylva {

namespace {

constexpr uintptr_t kHugePage = uintptr_t(2) << 20;

// -1 unknown, 0 off, 1 on. Read without a lock: every thread computes the same value.
std::atomic<int> g_advise{-1};

} // namespace

bool hugePagesAdvised() noexcept
{
    int mode = g_advise.load(std::memory_order_relaxed);
    if (mode < 0) {
        const char* v = std::getenv("SYLVA_HUGE_PAGES");
        mode = v && std::strcmp(v, "0") == 0 ? 0 : 1;
        g_advise.store(mode, std::memory_order_relaxed);
    }
    return mode == 1;
}

void adviseHugePages(void* p, size_t bytes) noexcept
{
#if defined(__linux__) && defined(MADV_HUGEPAGE)
    if (!p || bytes < kHugePageMinBytes || !hugePagesAdvised()) return;
    const uintptr_t begin = (reinterpret_cast<uintptr_t>(p) + kHugePage - 1) & ~(kHugePage - 1);
    const uintptr_t end = (reinterpret_cast<uintptr_t>(p) + bytes) & ~(kHugePage - 1);
    if (end > begin) madvise(reinterpret_cast<void*>(begin), size_t(end - begin), MADV_HUGEPAGE);
#else
    (void)p;
    (void)bytes;
#endif
}

} // namespace sylva
