// The program's operator new: malloc, then huge pages asked for on large blocks (huge_pages.h). Linked
// into every executable through sylva_core (core/CMakeLists.txt); operator delete stays free(), as the
// standard library's is. new[] and the nothrow forms call these.
#include "core/base/huge_pages.h"

#include <algorithm>
#include <cstdlib>
#include <new>

namespace {

void* allocate(std::size_t n)
{
    if (n == 0) n = 1;
    for (;;) {
        if (void* p = std::malloc(n)) {
            sylva::adviseHugePages(p, n);
            return p;
        }
        std::new_handler h = std::get_new_handler();
        if (!h) throw std::bad_alloc();
        h();
    }
}

void* allocateAligned(std::size_t n, std::align_val_t al)
{
    const std::size_t a = std::max(sizeof(void*), static_cast<std::size_t>(al));
    if (n == 0) n = 1;
    n = (n + a - 1) / a * a;   // aligned_alloc wants a multiple of the alignment
    for (;;) {
        if (void* p = std::aligned_alloc(a, n)) {
            sylva::adviseHugePages(p, n);
            return p;
        }
        std::new_handler h = std::get_new_handler();
        if (!h) throw std::bad_alloc();
        h();
    }
}

} // namespace

void* operator new(std::size_t n) { return allocate(n); }
void* operator new[](std::size_t n) { return allocate(n); }
void* operator new(std::size_t n, std::align_val_t al) { return allocateAligned(n, al); }
void* operator new[](std::size_t n, std::align_val_t al) { return allocateAligned(n, al); }

void operator delete(void* p) noexcept { std::free(p); }
void operator delete[](void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t) noexcept { std::free(p); }
void operator delete(void* p, std::align_val_t) noexcept { std::free(p); }
void operator delete[](void* p, std::align_val_t) noexcept { std::free(p); }
void operator delete(void* p, std::size_t, std::align_val_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t, std::align_val_t) noexcept { std::free(p); }
