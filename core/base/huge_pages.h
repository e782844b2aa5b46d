// Transparent huge pages for large arrays. The acceleration structures, LB grids and frame buffers are
// hundreds of MB written once and then read at random: in 4 KB pages they cost one page fault per 4 KB
// when first touched (10-12 us each on a paravirtualized VM, 1 GB in 2.7 s) and a TLB miss on most
// random reads; in 2 MB pages one fault per 2 MB and a TLB that covers the whole frame. The kernel
// gives huge pages only to ranges asked for by madvise when its mode is "madvise" (Debian's default),
// so every large allocation asks (core/base/global_new.cpp: the program's operator new).
#pragma once

#include <cstddef>

namespace sylva {

// Allocations of at least this many bytes ask for huge pages (the 2 MB-aligned part of them).
constexpr size_t kHugePageMinBytes = size_t(4) << 20;

// Asks the kernel to back the 2 MB-aligned pages inside [p, p + bytes) with transparent huge pages,
// before they are touched. Does nothing for smaller ranges, off Linux, or with SYLVA_HUGE_PAGES=0 in
// the environment (read once). Never fails: a kernel without THP keeps 4 KB pages.
void adviseHugePages(void* p, size_t bytes) noexcept;

// False when SYLVA_HUGE_PAGES=0 turned the advice off (the benchmarks' comparison).
bool hugePagesAdvised() noexcept;

} // namespace sylva
