// SPDX-License-Identifier: Apache-2.0
// Global operator new/delete for the fuzz targets: plain malloc/free, so
// that a failed allocation throws std::bad_alloc as it does in vdbpack
// itself. ASan's own operator new aborts the process instead ("allocator is
// out of memory"), which would turn OpenVDB's reaction to a corrupt size
// field (a huge new[] that throws, caught and reported by vdbpack) into a
// false crash. Huge requests fail through ASAN_OPTIONS max_allocation_size_mb
// and allocator_may_return_null (scripts/fuzz.sh).
#include <cstdlib>
#include <new>

static void *alloc_or_throw(std::size_t n) {
    if (void *p = std::malloc(n ? n : 1)) return p;
    throw std::bad_alloc();
}

static void *aligned_or_null(std::size_t n, std::align_val_t a) {
    void *p = nullptr;
    std::size_t al = static_cast<std::size_t>(a);
    if (al < sizeof(void *)) al = sizeof(void *);
    if (posix_memalign(&p, al, n ? n : 1) != 0) return nullptr;
    return p;
}

void *operator new(std::size_t n) { return alloc_or_throw(n); }
void *operator new[](std::size_t n) { return alloc_or_throw(n); }
void *operator new(std::size_t n, const std::nothrow_t &) noexcept {
    return std::malloc(n ? n : 1);
}
void *operator new[](std::size_t n, const std::nothrow_t &) noexcept {
    return std::malloc(n ? n : 1);
}
void *operator new(std::size_t n, std::align_val_t a) {
    if (void *p = aligned_or_null(n, a)) return p;
    throw std::bad_alloc();
}
void *operator new[](std::size_t n, std::align_val_t a) { return operator new(n, a); }
void *operator new(std::size_t n, std::align_val_t a, const std::nothrow_t &) noexcept {
    return aligned_or_null(n, a);
}
void *operator new[](std::size_t n, std::align_val_t a, const std::nothrow_t &) noexcept {
    return aligned_or_null(n, a);
}
void operator delete(void *p) noexcept { std::free(p); }
void operator delete[](void *p) noexcept { std::free(p); }
void operator delete(void *p, std::size_t) noexcept { std::free(p); }
void operator delete[](void *p, std::size_t) noexcept { std::free(p); }
void operator delete(void *p, const std::nothrow_t &) noexcept { std::free(p); }
void operator delete[](void *p, const std::nothrow_t &) noexcept { std::free(p); }
void operator delete(void *p, std::align_val_t) noexcept { std::free(p); }
void operator delete[](void *p, std::align_val_t) noexcept { std::free(p); }
void operator delete(void *p, std::size_t, std::align_val_t) noexcept { std::free(p); }
void operator delete[](void *p, std::size_t, std::align_val_t) noexcept { std::free(p); }
void operator delete(void *p, std::align_val_t, const std::nothrow_t &) noexcept { std::free(p); }
void operator delete[](void *p, std::align_val_t, const std::nothrow_t &) noexcept { std::free(p); }
